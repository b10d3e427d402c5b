#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Work-precision benchmark (`make bench`): builds tests/bench/workprec
# against the core library, runs the scenes in two single-threaded
# processes (the full scene alone in one, the others in turn in the other),
# then the GSL and SUNDIALS peers at the 1 % gate (peers.sh), then writes
# the table and the plot. BENCH_QUICK=1: shorter horizons and
# ladders, results into $BUILD/bench-quick instead of tests/bench/results.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
CC=${CC:-cc}
if [ "${BENCH_QUICK:-0}" = 1 ]; then
	out="$BUILD/bench-quick"; q=quick; cmd="BENCH_QUICK=1 make bench"
else
	out=tests/bench/results; q=; cmd="make bench"
fi
mkdir -p "$out" "$BUILD/bench"
bin="$BUILD/bench/workprec"
$CC -O2 -g -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -Icore \
	-o "$bin" tests/bench/workprec.c tests/bench/workprec_run.c \
	tests/bench/workprec_scenes.c tests/bench/workprec_report.c tests/bench/workprec_svg.c \
	"$BUILD/libcore.a" -lm
pin() { # core, command...: one core per process where taskset exists
	local c=$1; shift
	if command -v taskset >/dev/null; then taskset -c "$c" "$@"; else "$@"; fi
}
. tests/bench/provenance.sh
prov=$(provenance)
start=$(date +%s)
echo "bench: full scene on core 0; machine alone, reduced scene, reductions on core 1"
pin 0 "$bin" scene full $q > "$out/full.tsv" &
full_pid=$!
{
	pin 1 "$bin" scene nofeed $q > "$out/nofeed.tsv"
	pin 1 "$bin" scene reduced $q > "$out/reduced.tsv"
	pin 1 "$bin" scene reductions $q > "$out/reductions.tsv"
} &
rest_pid=$!
wait "$full_pid"
wait "$rest_pid"
echo "bench: the GSL and SUNDIALS peers at the 1 % gate (two cores)"
bash tests/bench/peers.sh "$out" "$cmd"
"$bin" report "$out" "$cmd"
stamp "$out/workprec.md" "$prov"
echo "bench: the 74-point v(beta) curve against the converged reference (one core per sweep)"
bash tests/bench/accuracy.sh "$out"
echo "bench: the machine zoo against its converged references (one core per curve)"
bash tests/bench/zoo.sh "$out"
echo "bench: the chaotic feed's bars against its long-window reference (one core)"
bash tests/bench/chaos.sh "$out"
echo "bench: the speed targets (one core)"
bash tests/bench/targets.sh "$out"
echo "bench: start-up and the curve, whole processes, against the previous build (one core)"
bash tests/bench/startup.sh "$out"
echo "bench: cost against the feed's size (one core)"
bash tests/bench/scaling.sh "$out"
echo "bench: a 2-parameter fit on 20 points (two threads)"
bash tests/bench/fit.sh "$out"
echo "bench: the paper's peaks fitted: e alone, e with each second parameter, the preset's curve (two threads, a few minutes)"
bash tests/bench/calibration.sh "$out" > /dev/null
echo "bench: a 20 x 37 study (two threads; two ranks under mpirun)"
bash tests/bench/study.sh "$out"
echo "bench: paced default sessions held in real time, against the previous build (loopback, both cores)"
bash tests/bench/realtime.sh "$out"
echo "bench: what a stream costs the daemon per record (the charge of its streams in the paced budget)"
bash tests/bench/stream_cost.sh "$out" > /dev/null
echo "bench: what a paced session's sample costs its worker (the sample term of the CPU estimate; ~1 min)"
bash tests/bench/sample_cost.sh "$out" > /dev/null
echo "bench: what a creation refused for CPU costs the daemon (the paced budget full)"
bash tests/bench/refuse_cost.sh "$out" > /dev/null
echo "bench: a burst of large creations beside running sessions (how many settle at once; ~1 min)"
bash tests/bench/settle_flood.sh "$out" > /dev/null
echo "bench: PATCH throughput with the durable control log (loopback, a temporary data directory)"
{ echo "Command: \`node tests/bench/controls.mjs\` (part of \`make bench\`). $(provenance)"; echo
	CONVSIMD="$BUILD/convsimd" OLD="${OLD_CONVSIMD:-}" node tests/bench/controls.mjs; } | tee "$out/controls.md"
echo "bench: the request body check: CPU per 1 MiB body of many names (one daemon)"
{ echo "Command: \`node tests/bench/body_parse.mjs\` (part of \`make bench\`). $(provenance)"; echo
	CONVSIMD="$PWD/$BUILD/convsimd" node tests/bench/body_parse.mjs; } >"$out/body_parse.md"
echo "bench: the PI loop closed from a client at pace 1, with 0, 100 and 200 ms added, and open loop (one daemon, ~2 min)"
python3 tests/bench/remote_loop.py "$BUILD/convsimd" >"$out/remote_loop.md"
echo "bench: the conveyor as a control system: identification, setpoint steps, disturbances (loopback, pace max)"
{ echo "Command: \`node tests/bench/control_loop.mjs\` (part of \`make bench\`). $(provenance)"; echo
	CONVSIMD="$BUILD/convsimd" node tests/bench/control_loop.mjs; } | tee "$out/control_loop.md"
echo "bench: shaping the beta command (overdrive, ZV-shaped ramp) against a plain step, on the core"
${CC:-cc} -O2 -g -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -D_DEFAULT_SOURCE -Icore \
	-o "$BUILD/control_shaping" tests/bench/control_shaping.c "$BUILD/libcore.a" -lm -lpthread
{ echo "Command: \`$BUILD/control_shaping\` (tests/bench/control_shaping.c, part of \`make bench\`). $(provenance)"; echo
	"$BUILD/control_shaping"; } | tee "$out/control_shaping.md"
echo "bench: $(( $(date +%s) - start )) s; wrote $out/workprec.md and $out/workprec.svg"
