#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The simulation of a default session in the daemon's pattern against one
# long run, in one process (`make bench-advance-cost`; about a minute):
# tests/bench/advance_cost.c in ROUNDS turns (5) of long, chunks, sampled
# and sessions (N instances, 200), the median CPU of each; then each of
# the first three under callgrind (instructions per simulated second,
# which the machine's other load does not change; skipped without
# valgrind). Writes $1/advance_cost.md (default tests/bench/results).
set -eu
cd "$(dirname "$0")/../.."
out=${1:-tests/bench/results}
ROUNDS=${ROUNDS:-5}
N=${N:-200}
bin=build/advance_cost
rev=$(git rev-parse --short HEAD 2>/dev/null || echo unknown)
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
load0=$(cut -d' ' -f1-3 /proc/loadavg)
for r in $(seq "$ROUNDS"); do
	"$bin" long 20 >> "$tmp/long"
	"$bin" chunks 20 >> "$tmp/chunks"
	"$bin" sampled 20 >> "$tmp/sampled"
	"$bin" sessions 0.5 "$N" >> "$tmp/sessions"
done
load1=$(cut -d' ' -f1-3 /proc/loadavg)
med() { cut -d' ' -f3 "$tmp/$1" | sort -g | awk '{a[NR]=$1} END {printf "%.3f", a[int((NR+1)/2)]}'; }
span() { cut -d' ' -f3 "$tmp/$1" | sort -g | awk 'NR==1 {lo=$1} {hi=$1} END {printf "%.3f-%.3f", lo, hi}'; }
ir() {
	if ! command -v valgrind >/dev/null; then echo "-"; return; fi
	valgrind --tool=callgrind --collect-atstart=no --toggle-collect=measured \
		--callgrind-out-file=/dev/null "$bin" "$1" 2 2>&1 |
		sed -n 's/.*Collected : \([0-9]*\).*/\1/p' | awk '{printf "%.2f", $1 / 2 / 1e6}'
}
ir_long=$(ir long); ir_chunks=$(ir chunks); ir_sampled=$(ir sampled)
{
	echo "# The simulation of a default session: the daemon's pattern against one long run"
	echo
	echo "Command: \`bash tests/bench/advance_cost.sh\` (\`make bench-advance-cost\`; tests/bench/advance_cost.c),"
	echo "czubak2016 with the defaults from t = 2 s (its shadow over), $(date -u '+%Y-%m-%d %H:%M UTC'),"
	echo "build $rev, $(nproc) cores ($(grep -m1 'model name' /proc/cpuinfo | sed 's/.*: //')),"
	echo "load average $load0 before, $load1 after. CPU: the median (and range) of $ROUNDS turns; instructions:"
	echo "callgrind over 2 simulated s (the same on any load)."
	echo
	echo "| pattern | CPU per simulated s, ms (median) | range of the turns | instructions per simulated s, millions |"
	echo "|---|---|---|---|"
	echo "| long: one sim_advance over 20 s | $(med long) | $(span long) | $ir_long |"
	echo "| chunks: sim_advance to each of 250 samples a second | $(med chunks) | $(span chunks) | $ir_chunks |"
	echo "| sampled: the same, each sample's status and feed arrays read out | $(med sampled) | $(span sampled) | $ir_sampled |"
	echo "| sessions: $N sampled instances in turn, 0.1 s batches | $(med sessions) | $(span sessions) | as sampled |"
	echo
	if [ "$ir_long" != "-" ]; then
		echo "Instructions over the long run's: chunks $(awk -v a="$ir_chunks" -v b="$ir_long" 'BEGIN {printf "%+.1f", 100 * (a / b - 1)}') %,"
		echo "sampled $(awk -v a="$ir_sampled" -v b="$ir_long" 'BEGIN {printf "%+.1f", 100 * (a / b - 1)}') %."
		echo
	fi
	echo "The figures of one turn are in the same minutes; the machine's other load raises all of them"
	echo "alike (the quiet machine's figure is targets.md's)."
} | tee "$out/advance_cost.md"
