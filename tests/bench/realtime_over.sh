#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Issue 37's 1.5 times capacity: `node tests/bench/realtime.mjs N` (N from
# OVER_N, default 1500) RUNS times (default 3), each with the previous
# build first in the same minutes (BASELINE), the load average before and
# after each run: are the admitted sessions in real time while the refused
# creations' flood arrives? The previous build is PREV_CONVSIMD, or commit
# PREV (default: LAST_RELEASE, a9a256a now), built by tests/bench/prev_build.sh. Not part of
# `make bench` (about a minute a run). Writes $1/realtime_1500.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
. tests/bench/prev_build.sh
PREV=${PREV:-$LAST_RELEASE}
N=${OVER_N:-1500}
RUNS=${RUNS:-3}
prev=${PREV_CONVSIMD:-}
if [ -z "$prev" ]; then
	prev_build realtime_over convsimd
fi
. tests/bench/provenance.sh
{
	echo "# $N default sessions asked of one daemon: the admitted in real time while the rest are refused?"
	echo
	provenance
	echo
	echo "Command: \`bash tests/bench/realtime_over.sh\`: \`node tests/bench/realtime.mjs $N\` $RUNS times, the previous"
	echo "build ($PREV) first in each run (BASELINE). \"no: the admitted in real time, the rest 503\" is what 1.5"
	echo "times capacity should show (issue 37 item 2)."
	echo
	echo "| run | build | sessions | admitted (refused: 503 cpu) | at >= 0.95 of real time | slowest rtf | median rtf | stream lag p50 / p99, ms | daemon CPU, cores | daemon CPU per session-second, ms | holds (all admitted, in real time, p99 < 50 ms) | streams refused (503 cpu) | load average before / after the run |"
	echo "|---|---|---|---|---|---|---|---|---|---|---|---|---|"
	for r in $(seq 1 "$RUNS"); do
		before=$(cut -d' ' -f1 /proc/loadavg)
		rows=$(CONVSIMD="$BUILD/convsimd" BASELINE="$prev" node tests/bench/realtime.mjs "$N" | grep -E '^\| (baseline|this build) ')
		after=$(cut -d' ' -f1 /proc/loadavg)
		echo "$rows" | sed "s/^| baseline |/| run $r | previous |/; s/^| this build |/| run $r | this build |/; s/\$/ $before \/ $after |/"
	done
	echo
	echo "Load average (1 min) read before and after each run (both builds). Lag: each sample's delay"
	echo "against its stream's fastest delivery since its session's creation (realtime.mjs)."
} > "$out/realtime_1500.md"
cat "$out/realtime_1500.md"
