#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Makes the real seeds of the `store` fuzz harness again (docs/fuzzing.md
# "Fuzzing"): runs the daemon ($BUILD/convsimd, from `make`) on a fresh
# --data-dir with three sessions, a running default one, a finished rk4
# one without feed (`until` 1 s at pace "max") and a running one of
# 2 layers whose checkpoint carries a running experiment, stops it with SIGTERM once
# each has a checkpoint and its .prev, and frames every session's
# spec.bin with each checkpoint as the harness reads them: the byte 3, the
# spec's length as 4 bytes little-endian, spec.bin, then the checkpoint.
# Replaces the non-regression seeds in tests/fuzz/corpus/store/ (the
# regress-* inputs stay). `make fuzz` then checks that the harness accepts
# every one (FUZZ_MUST_ACCEPT=1).
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=tests/fuzz/corpus/store
data=$(mktemp -d)
log=$data.log
# CONVSIM_TETHER: the daemon ends with this script, however it ends
CONVSIM_TETHER=$$ "$BUILD/convsimd" --port 0 --data-dir "$data" --checkpoint-interval 0.5 >"$log" 2>&1 &
pid=$!
trap 'kill "$pid" 2>/dev/null || true; rm -rf "$data" "$log"' EXIT
url=
for _ in $(seq 50); do
	url=$(sed -n 's/.*listening on \(http:[^ ]*\).*/\1/p' "$log" | head -1)
	[ -n "$url" ] && break
	sleep 0.1
done
[ -n "$url" ] || { echo "store_seeds: the daemon did not start:" >&2; cat "$log" >&2; exit 1; }
create() { # body: prints the new session's id
	curl -sf -X POST "$url/api/v1/sessions" -H 'Content-Type: application/json' -d "$1" |
		python3 -c 'import json, sys; print(json.load(sys.stdin)["id"])'
}
running=$(create '{"preset":"czubak2016","pace":1}')
finished=$(create '{"preset":"czubak2016","scene":{"feed":false},"integrator":{"method":"rk4"},"pace":"max","until":1}')
experiment=$(create '{"preset":"czubak2016","scene":{"layers":2},"pace":1}')
curl -sf -o /dev/null -X POST "$url/api/v1/experiments" -H 'Content-Type: application/json' \
	-d '{"session":"'"$experiment"'","schedule":[{"beta":38,"until":30},{"beta":128,"until":60}]}'

# the running session writes a checkpoint every 0.5 s of wall time, the
# finished one when it stops; the shutdown writes each once more, which
# makes the .prev of both
for _ in $(seq 100); do
	[ -f "$data/sessions/$running/checkpoint.bin.prev" ] &&
		[ -f "$data/sessions/$experiment/checkpoint.bin.prev" ] &&
		[ -f "$data/sessions/$finished/checkpoint.bin" ] && break
	sleep 0.1
done
kill -TERM "$pid"
wait "$pid" || true
rm -f "$out"/*-checkpoint-bin "$out"/*-checkpoint-bin-prev
for s in "$running" "$finished" "$experiment"; do
	for ck in checkpoint.bin checkpoint.bin.prev; do
		dir=$data/sessions/$s
		[ -f "$dir/$ck" ] || { echo "store_seeds: $s has no $ck" >&2; exit 1; }
		name=$out/${s: -6}-$(echo "$ck" | tr . -)
		python3 - "$dir/spec.bin" "$dir/$ck" "$name" <<'PY'
import struct, sys
spec = open(sys.argv[1], 'rb').read()
ck = open(sys.argv[2], 'rb').read()
open(sys.argv[3], 'wb').write(bytes([3]) + struct.pack('<I', len(spec)) + spec + ck)
PY
		echo "$name: $(wc -c <"$name") bytes"
	done
done
