#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# What a stream client costs the daemon per record formatted and sent
# (tests/bench/stream_cost.mjs, about a minute): the figures behind a
# stream's charge in the cores for paced sessions (server/base/
# budget_stream.c, docs/budgets.md "Streams"). Writes $1/stream_cost.md.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-tests/bench/results}
. tests/bench/provenance.sh
line=$(provenance)
CONVSIMD="${BUILD:-build}/convsimd" node tests/bench/stream_cost.mjs "${STREAM_COST_N:-60}" "${STREAM_COST_S:-10}" > "$out/stream_cost.md"
stamp "$out/stream_cost.md" "$line"
echo >> "$out/stream_cost.md"
echo "Load average $(cut -d' ' -f1-3 /proc/loadavg) after. A record's CPU: the daemon's CPU with the streams less" >> "$out/stream_cost.md"
echo "that without, over the records the clients received (the daemon's clock ticks at 10 ms)." >> "$out/stream_cost.md"
cat "$out/stream_cost.md"
