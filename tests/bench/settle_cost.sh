#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The settling of a steady start beside its estimate, scenes 1 x 2 to 64 x
# 64, and the estimate of the previous build (tests/bench/settle_cost.mjs,
# a minute or two): the figures behind docs/load.md "What settling
# costs". The previous build is commit PREV (default 09f3a0d: the estimate
# that counted a light column's work), built once into $BUILD/prev-PREV;
# PREV_CONVSIMD names a built one instead. Writes $1/settle_cost.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
PREV=${PREV:-09f3a0d}
prev=${PREV_CONVSIMD:-}
if [ -z "$prev" ]; then
	. tests/bench/prev_build.sh
	prev_build settle_cost convsimd
fi
. tests/bench/provenance.sh
line=$(provenance)
CONVSIMD="$BUILD/convsimd" OLD="$prev" node tests/bench/settle_cost.mjs > "$out/settle_cost.md"
stamp "$out/settle_cost.md" "$line"
{
	echo
	echo "Previous build: $PREV. Load average $(cut -d' ' -f1-3 /proc/loadavg) after. The estimate's"
	echo "constants are calibrated to a quiet machine (server/admit/budget_cost.c); under load every scene"
	echo "measures more than its estimate, the default one too."
} >> "$out/settle_cost.md"
cat "$out/settle_cost.md"
