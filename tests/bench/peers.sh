#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The peers at the 1 % gate (part of `make bench`; `make bench-peers` runs
# it alone): builds tests/bench/peers against the core library, GSL and
# SUNDIALS, runs its sanity check (every peer against the core's rk4 on
# the machine-alone orbit; a failure stops here), then each peer's
# tolerance ladder over the gate's points (loosest first, until one meets
# 1 % at every point or a run exhausts its CPU budget) in two
# single-threaded processes, the core's dem over the same points, and
# writes $1/peers.tsv, peers.md and gate.tsv (the plot's panel (4), drawn
# by `workprec report`). BENCH_QUICK=1: one point, a shorter ladder.
set -eu
cd "$(dirname "$0")/../.."
. tests/bench/provenance.sh
prov=$(provenance)
BUILD=${BUILD:-build}
CC=${CC:-cc}
out=${1:-tests/bench/results}
cmd=${2:-make bench}
mkdir -p "$out" "$BUILD/bench"
bin="$BUILD/bench/peers"
$CC -O2 -g -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -Icore -o "$bin" \
	tests/bench/peers.c tests/bench/peers_points.c tests/bench/peers_check.c \
	tests/bench/peers_report.c tests/bench/peer.c tests/bench/peer_gsl.c \
	tests/bench/peer_sundials.c "$BUILD/libcore.a" \
	-lgsl -lgslcblas -lsundials_cvode -lsundials_arkode -lsundials_nvecserial -lm
# The gate's points: the defaults' two worst (155 deg cw, 0.69 %; 70 deg cw,
# 0.63 %, where |v| < 0.3 peak) and the peak (30 deg cw). The ccw points
# are their mirrors (v_ccw(beta) = -v_cw(180 - beta)). All 74 would take
# hours: a peer at the gate costs 10-400 times the defaults.
# Ladders: decades from 1e-2 (1e-1 for the BDF peers, which do not finish
# a point at 1e-2 within the budget).
if [ "${BENCH_QUICK:-0}" = 1 ]; then
	points="155:cw"; ladder="1e-2 1e-3"; bdf_ladder="1e-1"; budget=10
else
	points="30:cw,70:cw,155:cw"; ladder="1e-2 1e-3 1e-4"; bdf_ladder="1e-1 1e-2 1e-3"
	budget=60
fi
pin() { # core, command...: one core per process where taskset exists
	local c=$1; shift
	if command -v taskset >/dev/null; then taskset -c "$c" "$@"; else "$@"; fi
}
echo "peers: sanity check against the core's rk4 (machine alone)"
"$bin" check
echo "peers: the 1 % gate at $points, rtol $ladder (BDF: $bdf_ladder), $budget CPU s a run at most"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
{
	for p in gsl-rk8pd gsl-msadams cvode-adams arkode-erk; do
		# shellcheck disable=SC2086
		pin 0 "$bin" gate "$p" $ladder --points "$points" --budget "$budget"
	done > "$tmp/a.tsv"
} &
a=$!
{
	pin 1 "$bin" ours --points "$points"
	# shellcheck disable=SC2086
	pin 1 "$bin" gate gsl-rkf45 $ladder --points "$points" --budget "$budget"
	for p in gsl-msbdf cvode-bdf; do
		# shellcheck disable=SC2086
		pin 1 "$bin" gate "$p" $bdf_ladder --points "$points" --budget "$budget"
	done
} > "$tmp/b.tsv" &
b=$!
wait "$a"
wait "$b"
cat "$tmp/b.tsv" "$tmp/a.tsv" > "$out/peers.tsv"
"$bin" report "$out" "$cmd" --points "$points"
stamp "$out/peers.md" "$prov"
cat "$out/peers.md"
