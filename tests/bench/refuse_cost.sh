#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# What a creation refused for CPU costs the daemon (tests/bench/
# refuse_cost.mjs, a few seconds): the figures behind docs/budgets.md
# "What a refusal costs". OLD=path/to/convsimd (OLD_NAME its label) runs an
# earlier build the same way first. Writes $1/refuse_cost.md.
set -eu
cd "$(dirname "$0")/../.."
out=${1:-tests/bench/results}
. tests/bench/provenance.sh
line=$(provenance)
CONVSIMD="${BUILD:-build}/convsimd" node tests/bench/refuse_cost.mjs > "$out/refuse_cost.md"
stamp "$out/refuse_cost.md" "$line"
{
	echo
	echo "Load average $(cut -d' ' -f1-3 /proc/loadavg) after. A refusal's CPU: the daemon's CPU (user + sys, /proc, 10-ms"
	echo "ticks) over the refused creations less what its running sessions spent in as long a quiet window just"
	echo "before, over the creations; the latency is the client's, a keep-alive connection each."
} >> "$out/refuse_cost.md"
cat "$out/refuse_cost.md"
