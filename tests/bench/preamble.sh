# SPDX-License-Identifier: GPL-3.0-or-later
# The start of a bench script that writes one result file (sourced:
# `. "$(dirname "$0")/preamble.sh"`, the script's own arguments seen):
# strict mode, the repository's root as the working directory, BUILD
# (default build), out = $1 (default tests/bench/results, made), repeat
# = REPEAT (default 3), cli = the built convsim, and a scratch directory
# $work that is removed at exit.
set -eu
cd "$(dirname "${BASH_SOURCE[0]}")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
repeat=${REPEAT:-3}
mkdir -p "$out"
cli="$BUILD/convsim"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
