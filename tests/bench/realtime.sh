#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Paced default sessions held in real time by one daemon, the previous
# build beside this one in the same minutes (part of `make bench`; a few
# minutes): tests/bench/realtime.mjs for each N of REALTIME_N (default
# "200 600 1000": within the default --max-paced-cores, beyond it, where the
# admitted must keep real time and the rest get 503, and issue 37's target). The previous build
# is commit PREV (default: LAST_RELEASE of tests/bench/prev_build.sh, a9a256a now; the rounds before
# compared with 03e01ae, main before its streams were charged in the cores
# for paced sessions, dbe9ffc, 7e56a85, 1b75a01, 4eff261, 357b026, 685132b, b09537b, ac6018f, 21c112d, 4611a1d, 4163b0a, f809dea, 30ec102, 629d0db, f27d350, 902f3ae, 322ab1b, 2c46d6e and c0da41f), exported with git archive and built once
# into $BUILD/prev-PREV (`make build/convsimd`); PREV_CONVSIMD names a
# built one instead. Writes $1/realtime.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
. tests/bench/prev_build.sh
PREV=${PREV:-$LAST_RELEASE}
prev=${PREV_CONVSIMD:-}
if [ -z "$prev" ]; then
	prev_build realtime convsimd
fi
rev=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
N=${REALTIME_N:-200 600 1000}
{
	echo "# Paced default sessions in real time: the previous build beside this one"
	echo
	echo "Command: \`bash tests/bench/realtime.sh\` (part of \`make bench\`; \`node tests/bench/realtime.mjs $N\`"
	echo "with BASELINE), $(date -u '+%Y-%m-%d %H:%M UTC'), $(nproc) cores"
	echo "($(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')), load average $(cut -d' ' -f1-3 /proc/loadavg) before."
	echo "Previous build: $PREV; this build: $rev."
	echo
	CONVSIMD="$BUILD/convsimd" BASELINE="$prev" node tests/bench/realtime.mjs $N | sed -n '/^|/p'
	echo
	echo "Load average $(cut -d' ' -f1-3 /proc/loadavg) after. Daemon CPU per session-second: its user +"
	echo "sys time from before the first creation to after the last deletion over the simulated seconds"
	echo "of all its sessions; the figure the machine's other load distorts least."
} | tee "$out/realtime.md"
