#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Where a daemon of paced default sessions spends its CPU, the previous
# build beside this one in the same minutes (`make profile-daemon`; about
# a minute, two builds the first time): both built with frame pointers
# (-fno-omit-frame-pointer, so that perf's call chains reach the worker's
# loop) into build-prof/ (this one) and build-prof/prev-PREV (commit PREV,
# default dbe9ffc, main before the second pass of issue 37 item 1; the
# round before compared with 7e56a85; exported with git archive), then tests/bench/profile.mjs
# with PROFILE_N sessions (200) for PROFILE_SECONDS (8). Writes
# $1/profile.md (default tests/bench/results).
set -eu
cd "$(dirname "$0")/../.."
out=${1:-tests/bench/results}
PREV=${PREV:-dbe9ffc}
N=${PROFILE_N:-200}
S=${PROFILE_SECONDS:-8}
FP="-O2 -g -fno-omit-frame-pointer"
make --no-print-directory -s -j2 BUILD=build-prof CFLAGS="$FP" build-prof/convsimd
prev_dir="build-prof/prev-$PREV"
if [ ! -x "$prev_dir/src/build-prof/convsimd" ]; then
	echo "profile: building the previous build ($PREV) in $prev_dir"
	mkdir -p "$prev_dir/src"
	[ -f "$prev_dir/src/Makefile" ] || git archive "$PREV" | tar -x -C "$prev_dir/src"
	make -C "$prev_dir/src" --no-print-directory -j2 BUILD=build-prof CFLAGS="$FP" build-prof/convsimd \
		> "$prev_dir/make.log" 2>&1 || { tail -20 "$prev_dir/make.log"; exit 1; }
fi
rev=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
{
	echo "# Where a daemon of paced default sessions spends its CPU"
	echo
	echo "Command: \`make profile-daemon\` (\`bash tests/bench/profile.sh\`: \`node tests/bench/profile.mjs $N $S\`"
	echo "with BASELINE; \`perf record -e cpu-clock -F 499 -g -p PID -- sleep $S\` on the daemon), $N default"
	echo "sessions at pace 1 with an NDJSON stream each (trough, 10 samples a simulated second),"
	echo "$(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')),"
	echo "load average $(cut -d' ' -f1-3 /proc/loadavg) before. Previous build: $PREV; this build: $rev; both"
	echo "with frame pointers."
	echo
	CONVSIMD="build-prof/convsimd" BASELINE="$prev_dir/src/build-prof/convsimd" PERF_DATA=build-prof/perf.data \
		node tests/bench/profile.mjs "$N" "$S"
	echo
	echo "Load average $(cut -d' ' -f1-3 /proc/loadavg) after. Each perf sample goes to the first part"
	echo "its thread and call chain show, in the table's order; \`session\` threads are the workers,"
	echo "\`MHD-connection\` threads the streams. The daemon's CPU per session-second here is over the"
	echo "$S s sampled, once all sessions run (no creations): lower than realtime.md's."
} | tee "$out/profile.md"
