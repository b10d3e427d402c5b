#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Runs every test group against the built binaries and closes with one line
# "tests: N passed, M failed" counting the individual tests of all groups.
# Unit tests are cmocka binaries; HTTP and browser tests are node:test files
# that start the real daemon on port 0.
set -u
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
export BUILD CONVSIMD="$PWD/$BUILD/convsimd" CONVSIM="$PWD/$BUILD/convsim" CONVSIM_DEM="$PWD/$BUILD/convsim-dem"
export CONVSIM_NOMPI="$PWD/$BUILD/nompi/convsim" # the convsim of `make NO_MPI=1` (make test builds it)
mkdir -p tests/out
log=$(mktemp) times=$(mktemp)
pass=0; fail=0; failed=(); skipped=()
# TESTS_SKIP: an extended regular expression; the groups whose names match
# it do not run and are listed at the end (make check-ci)
skip() { # name: 0 (and listed) when TESTS_SKIP names it
	if [ -n "${TESTS_SKIP:-}" ] && printf '%s\n' "$1" | grep -Eq -- "$TESTS_SKIP"; then
		skipped+=("$1")
		return 0
	fi
	return 1
}
count() { # name, exit code, seconds: the group's tests, from $log
	local name=$1 rc=$2 p f
	# the group's wall time, for the slowest-groups line at the end
	printf '%s\t%s\n' "$3" "$name" >>"$times"
	# cmocka: "[  PASSED  ] N test(s)." / "[  FAILED  ] N test(s), listed below:"
	# node:test: "# pass N" / "# fail N"
	p=$(sed -n -e 's/^\[  PASSED  \] \([0-9]*\) test.*/\1/p' -e 's/^# pass \([0-9]*\)$/\1/p' "$log" | tail -1)
	f=$(sed -n -e 's/^\[  FAILED  \] \([0-9]*\) test.*/\1/p' -e 's/^# fail \([0-9]*\)$/\1/p' "$log" | tail -1)
	p=${p:-0}; f=${f:-0}
	# a group that crashed or timed out counts as one more failure
	if [ "$rc" -ne 0 ] && [ "$f" -eq 0 ]; then f=1; fi
	pass=$((pass + p)); fail=$((fail + f))
	[ "$rc" -eq 0 ] || failed+=("$name")
	# FAIL_FAST=1 (make mutate): stop at the first failing group
	if [ "$rc" -ne 0 ] && [ "${FAIL_FAST:-0}" = 1 ]; then
		printf 'failed group: %s\n' "$name"
		echo "tests: $pass passed, $fail failed"
		exit 1
	fi
}
since() { awk -v a="$EPOCHREALTIME" -v b="$1" 'BEGIN {printf "%.1f", a - b}'; }
run() { # name, command...
	local name=$1; shift
	skip "$name" && return
	echo "=== $name"
	local t0=$EPOCHREALTIME
	timeout 900 "$@" 2>&1 | tee "$log"
	local rc=${PIPESTATUS[0]}
	count "$name" "$rc" "$(since "$t0")"
}
# the unit tests of the sources there are (a binary left in $BUILD by a
# renamed or removed test file does not run), TEST_JOBS at a time: they
# compute, and time themselves on their threads' CPU clocks only, so they
# may share the cores; each writes a log of its own, shown and counted in
# order once all have ended
units=$(mktemp -d)
trap 'rm -rf "$log" "$times" "$units"' EXIT
# the longest first (by CI's logs), so that the last to start end together
longest="test_fit_band test_fit test_checkpoint test_fit_robust test_table"
order=()
for name in $longest $(ls tests/unit/test_*.c | xargs -n1 basename | sed 's/\.c$//'); do
	case " ${order[*]} " in *" $name "*) continue ;; esac
	[ -e "tests/unit/$name.c" ] && order+=("$name")
done
# spawn jobs name command...: name's command in the background, at most
# jobs at a time, its output to a log of its own; shown and counted by shown
spawn() {
	local lanes=$1 name=$2 key=${2//\//_}; shift 2
	while [ "$(jobs -rp | wc -l)" -ge "$lanes" ]; do wait -n; done
	(t0=$EPOCHREALTIME
	 timeout 900 "$@" >"$units/$key.log" 2>&1
	 echo "$? $(since "$t0")" >"$units/$key.end") &
}
shown() { # name: its log shown and counted (after wait)
	local key=${1//\//_} rc secs
	echo "=== $1"
	cp "$units/$key.log" "$log"
	cat "$log"
	read -r rc secs <"$units/$key.end"
	count "$1" "$rc" "$secs"
}
names=()
for name in "${order[@]}"; do
	[ -x "$BUILD/tests/$name" ] || continue
	skip "$name" && continue
	names+=("$name")
	spawn "${TEST_JOBS:-1}" "$name" "$BUILD/tests/$name"
done
wait
for name in $(printf '%s\n' "${names[@]}" | sort); do
	shown "$name"
done
# the floors: no dependency loop in core/, fit/, cli/, api/, each of
# server/'s floors, server/ as a whole or dem/ (where built) (files that use
# each other's symbols, tests/deps.py)
run "dependency loops" sh -c "python3 tests/deps.py --max 1 $BUILD/core $BUILD/fit $BUILD/cli $BUILD/api $BUILD/server/base $BUILD/server/store $BUILD/server/admit $BUILD/server/jobs $BUILD/server/session $BUILD/server/http '$BUILD/server/**' $(ls -d $BUILD/dem 2>/dev/null) && echo '# pass 1'"
# the fast feed model's harness: its leave-one-bed-out never fits on the
# bed it predicts (no convsim runs; `make fast-feed-check` measures)
run "fast feed check (self-test)" python3 tests/bench/fast_feed_check.py --self-test
# model_error between the map's angles: the page is what the table gives and
# the rule there is the engine's (tests/bench/model_error_check.py)
run "model_error between the map's angles (check)" python3 tests/bench/model_error_check.py --check
run "the map as its own fast model (check)" sh -c "python3 tests/bench/depth_surrogate.py --check && echo '# pass 1'"
# the DEM map's plot is what the committed map and model check give, each
# mark its point's value (tests/bench/dem_map_plot.py)
run "DEM map plot" python3 tests/bench/dem_map_plot.py --check
# the inputs' rows are the plan's runs and their report what they give
run "DEM map inputs" python3 tests/bench/dem_inputs.py --check
# the map's runner: a point's seeds side by side, each seed's CPU its own
# process's (a stand-in for convsim-dem; no LIGGGHTS)
run "DEM map runner (self-test)" python3 tests/bench/dem_map.py --self-test
# the size rule: files of at most 500 lines, functions of at most 80
run "file and function sizes" sh -c "python3 tests/size.py --self-test && python3 tests/size.py && echo '# pass 1'"
# the node:test files one at a time (some timing asserts assume a quiet
# machine), or TEST_LANES at a time (make check-ci: a sanitizer build, where
# timeouts scale and those asserts are relaxed: tests/http/lib.mjs SLOW),
# each shown and counted in order once all have ended
files=()
for f in tests/cli/*.test.mjs tests/dem/*.test.mjs tests/http/*.test.mjs tests/web/*.test.mjs; do
	[ -e "$f" ] || continue
	if [ "${TEST_LANES:-1}" -le 1 ]; then
		run "$f" node --test --test-concurrency=1 --test-timeout=300000 "$f"
		continue
	fi
	skip "$f" && continue
	files+=("$f")
	spawn "$TEST_LANES" "$f" node --test --test-concurrency=1 --test-timeout=300000 "$f"
done
wait
for f in ${files[@]+"${files[@]}"}; do
	shown "$f"
done
echo
total=$(awk -F'\t' '{s += $1} END {printf "%.0f", s}' "$times")
echo "slowest groups (of ${total} s in all): $(sort -rn "$times" | head -5 | awk -F'\t' '{printf "%s%s %.0f s", (NR > 1 ? ", " : ""), $2, $1}')"
[ ${#skipped[@]} -eq 0 ] || echo "skipped (TESTS_SKIP): ${skipped[*]}"
[ ${#failed[@]} -eq 0 ] || printf 'failed group: %s\n' "${failed[@]}"
echo "tests: $pass passed, $fail failed"
[ "$fail" -eq 0 ] && [ ${#failed[@]} -eq 0 ]
