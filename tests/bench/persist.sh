#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Persistence figures (docs/operations.md "Persistence"), bounded (about 1 minute):
#  1. CPU cost of checkpointing 64 default sessions: the writer thread's
#     CPU with --checkpoint-interval 0.5, scaled to the default 10 s;
#  2. restart with 64 sessions on disk: wall time from exec to all 64
#     listed and running;
#  3. resident memory before, with 100 sessions and after deleting them.
# Loopback and a temporary directory only. Writes $1 (default
# tests/bench/results/persist.md) as well as the terminal.
set -eu
cd "$(dirname "$0")/../.."
BIN=${BUILD:-build}/convsimd
WINDOW=${WINDOW:-10}
. tests/bench/provenance.sh
res=${1:-tests/bench/results/persist.md}
prov=$(provenance)
exec > >(tee "$res")
echo "# Persistence figures"
echo
echo "Command: \`WINDOW=$WINDOW bash tests/bench/persist.sh\` (not part of \`make bench\`; about a minute). $prov"
echo
dir=$(mktemp -d)
trap 'kill -9 $pid 2>/dev/null || true; rm -rf "$dir"' EXIT

start() { # args...; sets pid, base
	# CONVSIM_TETHER: the daemon ends with this script, however it ends
	CONVSIM_TETHER=$$ "$BIN" --port 0 --log-level "${LOGLEVEL:-warn}" "$@" >"$dir/out" 2>"$dir/err" &
	pid=$!
	for _ in $(seq 200); do grep -q listening "$dir/out" 2>/dev/null && break; sleep 0.01; done
	base="http://127.0.0.1:$(grep -o '[0-9]*$' "$dir/out")/api/v1"
}
cpu() { awk '{print $14 + $15}' "/proc/$pid/stat"; } # clock ticks
rss() { awk '/VmRSS/ {print $2}' "/proc/$pid/status"; } # kB
make_sessions() { # n
	for _ in $(seq "$1"); do
		curl -sf -XPOST "$base/sessions" -H 'Content-Type: application/json' -d '{}' -o /dev/null
	done
}
hz=$(getconf CLK_TCK)

# 1. the writer thread ("store") with checkpoints every 0.5 s, scaled to
#    the default 10 s; the worker's part (copying a few kB between steps)
#    is below the resolution of this count
mkdir -p "$dir/data"
start --data-dir "$dir/data" --checkpoint-interval 0.5
make_sessions 64
sleep 2
writer() { cat /proc/$pid/task/*/stat | awk '/\(store\)/ {print $14 + $15}'; }
w0=$(writer); c0=$(cpu); sleep "$WINDOW"; w1=$(writer); c1=$(cpu)
files=$(find "$dir/data/sessions" -name checkpoint.bin | wc -l)
kill -9 "$pid"; wait "$pid" 2>/dev/null || true
num() { printf '%.*f' "$1" "$(echo "scale=6; $2" | bc)"; } # digits, bc expression
echo "- 64 sessions ($files checkpointed), daemon $(num 3 "($c1 - $c0) / $hz / $WINDOW") cores; writer thread at 0.5 s: $(num 3 "($w1 - $w0) * 100 / $hz / $WINDOW") % of one core"
echo "- checkpointing at the default 10 s: $(num 4 "($w1 - $w0) * 100 / $hz / $WINDOW * 0.5 / 10") % of one core"

# 2. restart: the last load left 64 sessions on disk (killed with -9)
t0=$(date +%s.%N)
LOGLEVEL=info start --data-dir "$dir/data"
until [ "$(curl -sf "$base/sessions" | grep -o '"state":"running"' | wc -l)" -ge 64 ]; do sleep 0.005; done
t1=$(date +%s.%N)
echo "- restart with 64 sessions on disk: all running again after $(num 2 "$t1 - $t0") s (exec to listing)"
grep restored "$dir/err" | sed "s/^/- the log: /" || true
kill -9 "$pid"; wait "$pid" 2>/dev/null || true

# 3. memory after deleting 100 sessions
start --max-sessions 100
r0=$(rss)
make_sessions 100
r1=$(rss)
for id in $(curl -sf "$base/sessions" | grep -o '"id":"[0-9a-f]*"' | cut -d'"' -f4); do
	curl -sf -XDELETE -H 'Content-Type: application/json' "$base/sessions/$id" -o /dev/null
done
sleep 1
r2=$(rss)
echo "- RSS: idle $((r0 / 1024)) MB, 100 sessions $((r1 / 1024)) MB, after deleting them $((r2 / 1024)) MB"
