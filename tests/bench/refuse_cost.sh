#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# What a creation refused for CPU costs the daemon, the previous build
# beside this one in the same minutes (tests/bench/refuse_cost.mjs, a few
# seconds): the figures behind docs/budgets.md "What a refusal costs". The
# previous build is commit PREV (default 20f6f5e: main before a refusal
# was decided ahead of the instance's settling), exported with git
# archive and built once into $BUILD/prev-PREV (`make build/convsimd`);
# PREV_CONVSIMD names a built one instead. Writes $1/refuse_cost.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
PREV=${PREV:-20f6f5e}
. tests/bench/prev_build.sh
daemon_beside_previous refuse_cost
{
	echo
	echo "Previous build: $PREV. Load average $(cut -d' ' -f1-3 /proc/loadavg) after. A refusal's CPU: the daemon's CPU"
	echo "(user + sys, /proc, 10-ms ticks) over the refused creations less what its running sessions spent in"
	echo "as long a quiet window just before, over the creations; the latency is the client's, over"
	echo "keep-alive connections."
} >> "$out/refuse_cost.md"
cat "$out/refuse_cost.md"
