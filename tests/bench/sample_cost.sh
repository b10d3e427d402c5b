#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# What a paced session's sample costs its worker (part of `make bench`,
# about two minutes of both cores): the figures behind the sample term of the
# CPU estimate (server/admit/budget_cost.c SAMPLE_CPU_S, docs/budgets.md
# "CPU"). A daemon runs a fleet of N default sessions at pace 1 and a
# sample rate r (50, 250, 1000 a simulated s; no streams); once they have
# run 6 s, the workers' own measure (convsim_paced_cpu_cores over N, CPU s
# per simulated s) and the daemon's CPU over the next 6 s; then fleets of 1,
# 10 and N at 250. Beside them the same scene flat out in one process
# (`convsim run --duration 20`, the least of 5). Writes $1/sample_cost.md.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-tests/bench/results}
BUILD=${BUILD:-build}
N=${SAMPLE_COST_N:-150}
PORT=${SAMPLE_COST_PORT:-18437}
. tests/bench/provenance.sh
line=$(provenance)
tick=$(getconf CLK_TCK)
flat() { # CPU s per simulated s of the scene flat out, the least of 5
	local best
	best=$(for _ in 1 2 3 4 5; do
		"$BUILD/convsim" run -q --duration 20 --sample-rate "$1" --set beta=30 |
			sed -n 's/.*"cpu_seconds": *\([0-9.e-]*\).*/\1/p' | head -1
	done | sort -g | head -1)
	python3 -c "print($best / 20)"
}
fleet() { # r [n] -> "measured daemon" in CPU s per simulated s a session, n sessions (N)
	local n=${2:-$N}
	"$BUILD/convsimd" --port "$PORT" --max-sessions $((n + 10)) --max-paced-cores 2 >/dev/null 2>&1 &
	local pid=$! i
	for i in $(seq 50); do curl -s -o /dev/null "http://127.0.0.1:$PORT/api/v1/health" && break; sleep 0.1; done
	for i in $(seq "$n"); do
		curl -s -o /dev/null -X POST -H 'Content-Type: application/json' \
			"http://127.0.0.1:$PORT/api/v1/sessions" -d "{\"pace\":1,\"sample_rate\":$1}"
	done
	sleep 6
	local t0 t1 held
	t0=$(awk '{print $14 + $15}' "/proc/$pid/stat")
	sleep 6
	t1=$(awk '{print $14 + $15}' "/proc/$pid/stat")
	held=$(curl -s "http://127.0.0.1:$PORT/metrics" | awk '$1 == "convsim_paced_cpu_cores" {print $2}')
	kill "$pid"
	wait "$pid" 2>/dev/null || true
	python3 -c "print($held / $n, ($t1 - $t0) / $tick / 6 / $n)"
}
{
	echo "# What a paced session's sample costs its worker"
	echo
	echo "Command: \`bash tests/bench/sample_cost.sh\` (part of \`make bench\`). $line"
	echo "A daemon with $N default sessions at pace 1 (no streams) at each sample rate; \"workers\": their"
	echo "own measure (convsim_paced_cpu_cores over the sessions, after 6 s); \"daemon\": its CPU over the"
	echo "next 6 s over the sessions; \"flat out\": the scene in one process (\`convsim run --duration 20"
	echo "--sample-rate r\`, the least of 5). All in ms of CPU per simulated s a session."
	echo
	echo "| samples a simulated s | workers | daemon | flat out | workers less flat out, us a sample |"
	echo "|---|---|---|---|---|"
	for r in 50 250 1000; do
		read -r w d <<<"$(fleet "$r")"
		f=$(flat "$r")
		python3 -c "print('| $r | %.3f | %.3f | %.3f | %.2f |' % (1e3 * $w, 1e3 * $d, 1e3 * $f, 1e6 * ($w - $f) / $r))"
	done
	echo
	echo "The same at 250 samples a simulated s with fewer sessions: what a paced worker costs when"
	echo "the cores go idle between its batches (the daemon's figure counts whole clock ticks, coarse"
	echo "for one session)."
	echo
	echo "| sessions | workers | daemon |"
	echo "|---|---|---|"
	for n in 1 10 $N; do
		read -r w d <<<"$(fleet 250 "$n")"
		python3 -c "print('| $n | %.3f | %.3f |' % (1e3 * $w, 1e3 * $d))"
	done
	echo
	echo "Load average $(cut -d' ' -f1-3 /proc/loadavg) after. The slope between two rows is what a"
	echo "sample adds; the last column charges a row's whole paced overhead to its samples, as the"
	echo "estimate's one term does."
} > "$out/sample_cost.md"
cat "$out/sample_cost.md"
