#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# A burst of large creations beside running sessions, the previous build
# beside this one in the same minutes (tests/bench/settle_flood.mjs, about
# a minute): the figures behind docs/load.md "Creations that settle".
# The previous build is commit PREV (default 3fec5b4: main before
# --max-settling), exported with git archive and built once into
# $BUILD/prev-PREV (`make build/convsimd`); PREV_CONVSIMD names a built one
# instead. Writes $1/settle_flood.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
PREV=${PREV:-3fec5b4}
. tests/bench/prev_build.sh
daemon_beside_previous settle_flood
{
	echo
	echo "Previous build: $PREV. Load average $(cut -d' ' -f1-3 /proc/loadavg) after. This build runs with its"
	echo "defaults: --max-settling is half the cores, rounded up ($(( ($(nproc) + 1) / 2 )) here). Pace kept: simulated s per wall s"
	echo "over the session's pace, over the burst and over 5 s before it; daemon CPU: user + sys from /proc"
	echo "(10-ms ticks) over the burst; settling at once: request threads that used 20 ms of CPU or more in"
	echo "a 0.5-s window."
} >> "$out/settle_flood.md"
cat "$out/settle_flood.md"
