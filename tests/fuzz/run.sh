#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs each libFuzzer harness of tests/fuzz/ for FUZZ_SECONDS (make fuzz;
# docs/fuzzing.md "Fuzzing") on its committed seeds (tests/fuzz/corpus/NAME, read
# only) and its working corpus ($FUZZ_BUILD/corpus/NAME, where new inputs
# go), with its dictionary, at nice 10, and prints a table: executions,
# exec/s, coverage (cov: edges, ft: features), CPU seconds (user+sys; the
# machine may be shared, so wall time says little), crashes. A crash, a
# leak, a sanitizer report, an oracle failure or an input slower than
# FUZZ_TIMEOUT seconds stops that harness, keeps the input in
# $FUZZ_BUILD/crashes/ and makes this script exit 1.
# FUZZ_JOBS harnesses run at a time (make fuzz: JOBS, every core).
set -u
cd "$(dirname "$0")/../.."
B=${FUZZ_BUILD:-build-fuzz}
S=${FUZZ_SECONDS:-60}
T=${FUZZ_TIMEOUT:-60}
# FUZZ_RUNS=N: N inputs per harness from the fixed seed 1 instead of a time
# (CI: the same amount of fuzzing every run; the inputs kept follow coverage,
# which can differ between machines)
R=${FUZZ_RUNS:-}
NAMES=${FUZZ_NAMES:-body_session body_control body_controlline body_experiment body_sweep body_fit body_specfile query route checkpoint store jobs peers}
mkdir -p "$B/corpus" "$B/crashes" "$B/logs"
if [ -n "$R" ]; then
	echo "fuzzing each harness for $R inputs from seed 1 (at most ${S} s): FUZZ_RUNS=$R make fuzz"
else
	echo "fuzzing each harness for ${S} s: FUZZ_SECONDS=$S make fuzz"
fi
printf '| %-16s | %8s | %12s | %8s | %6s | %7s | %6s | %7s |\n' harness seconds executions 'exec/s' cov ft 'CPU s' crashes
printf '|%s|%s|%s|%s|%s|%s|%s|%s|\n' ------------------ ---------- -------------- ---------- -------- --------- -------- ---------
total=0; crashed=0
for n in $NAMES; do
	bin=$B/fuzz/$n
	case $n in
	body_*) dict=tests/fuzz/dict/json.dict ;;
	query | route) dict=tests/fuzz/dict/$n.dict ;;
	*) dict= ;;
	esac
	log=$B/logs/$n.log
	mkdir -p "$B/corpus/$n"
	# the readers' committed real seeds (all but the regression inputs)
	# must still be accepted: seeds of a format since changed are refused
	# at its first check and fuzz nothing behind it
	case $n in
	checkpoint | store | jobs | peers)
		seeds=$(ls "tests/fuzz/corpus/$n"/* | grep -v '/regress-')
		# shellcheck disable=SC2086
		if ! FUZZ_MUST_ACCEPT=1 "$bin" $seeds >"$B/logs/$n.seeds.log" 2>&1; then
			echo "  $n: a committed seed is refused; the end of $B/logs/$n.seeds.log:"
			grep 'fuzz oracle' "$B/logs/$n.seeds.log" | tail -3 | sed 's/^/  /'
			crashed=1
		fi
		;;
	esac
	# FUZZ_JOBS harnesses at a time (each its own corpus, log and times)
	while [ "$(jobs -rp | wc -l)" -ge "${FUZZ_JOBS:-1}" ]; do wait -n; done
	(/usr/bin/time -f '%U %S' -o "$B/logs/$n.time" \
		nice -n 10 "$bin" ${R:+-runs=$R -seed=1} -max_total_time="$S" -timeout="$T" -rss_limit_mb=2048 \
		-print_final_stats=1 -artifact_prefix="$B/crashes/$n-" ${dict:+-dict=$dict} \
		"$B/corpus/$n" "tests/fuzz/corpus/$n" >"$log" 2>&1
	 echo $? >"$B/logs/$n.rc") &
done
wait
# the table, in the harnesses' order, once all have ended
for n in $NAMES; do
	log=$B/logs/$n.log
	rc=$(cat "$B/logs/$n.rc")
	execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
	rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
	cov=$(grep -o 'cov: [0-9]* ft: [0-9]*' "$log" | tail -1)
	cpu=$(tail -1 "$B/logs/$n.time" 2>/dev/null | awk '{printf "%.0f", $1 + $2}')
	crashes=0
	if [ "$rc" -ne 0 ]; then
		crashes=1
		crashed=1
	fi
	total=$((total + ${execs:-0}))
	printf '| %-16s | %8s | %12s | %8s | %6s | %7s | %6s | %7s |\n' "$n" "$S" "${execs:-?}" \
		"${rate:-?}" "$(echo "$cov" | awk '{print $2}')" "$(echo "$cov" | awk '{print $4}')" \
		"${cpu:-?}" "$crashes"
	if [ "$rc" -ne 0 ]; then
		echo "  $n failed (exit $rc); the end of $log:"
		grep -v '^    #\|^INFO\|^#' "$log" | tail -15 | sed 's/^/  /'
	fi
done
echo "fuzz: $total executions in total, $([ $crashed -eq 0 ] && echo 0 || echo 'some') harness(es) crashed"
[ "$crashed" -eq 0 ]
