#!/usr/bin/env bash
# Runs every test group against the built binaries and prints one closing
# line "N passed, M failed". Unit tests are cmocka binaries; HTTP and
# browser tests are node:test files that start the real daemon on port 0.
set -u
cd "$(dirname "$0")/.."
BUILD=${BUILD:-build}
export BUILD CONVSIMD="$PWD/$BUILD/convsimd" CONVSIM="$PWD/$BUILD/convsim"
mkdir -p tests/out
pass=0; fail=0; failed=()
run() { # name, command...
	local name=$1; shift
	echo "=== $name"
	if timeout 900 "$@"; then pass=$((pass+1)); else fail=$((fail+1)); failed+=("$name"); fi
}
for t in "$BUILD"/tests/test_*; do
	[ -x "$t" ] || continue
	run "$(basename "$t")" "$t"
done
for f in tests/http/*.test.mjs tests/web/*.test.mjs; do
	[ -e "$f" ] || continue
	# shellcheck disable=SC2086
	run "$f" node --test --test-concurrency=1 --test-timeout=300000 "$f"
done
echo
[ ${#failed[@]} -eq 0 ] || printf 'failed: %s\n' "${failed[@]}"
echo "test groups: $pass passed, $fail failed"
[ "$fail" -eq 0 ]
