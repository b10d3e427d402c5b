#!/usr/bin/env bash
# Cost against the feed's size (part of `make bench`): the full model
# (trough_rotation=true, so every column is integrated) with K columns x L
# layers from 1 x 1 to 20 x 32 at a constant feed mass of 20 kg (m_n =
# 20 / (K L) kg, the czubak2016 feed's mass, so the coupling and the default
# step stay the same), the defaults otherwise, 4 simulated seconds after the
# steady start, one core. Prints CPU seconds per simulated second and fits
# cost = c0 + c1 N^p over N = K L, c0 from the machine alone (no feed).
# Writes $1/scaling.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
mkdir -p "$out"
T=4
run() { # extra settings...: CPU s per simulated s (settling included)
	"$BUILD/convsim" run --duration "$T" --sample-rate 10 --set trough_rotation=true "$@" |
		sed -n 's/.*"cpu_seconds": \([0-9.e+-]*\).*/\1/p' | awk -v T="$T" '{ printf "%.6g", $1 / T }'
}
c0=$(run --set feed=false --set dt=5e-4)
sizes="1x1 1x8 5x1 5x8 5x16 10x8 10x16 20x8 20x16 20x32"
tmp=$(mktemp)
trap 'rm -f "$tmp"' EXIT
for kl in $sizes; do
	K=${kl%x*} L=${kl#*x}
	mn=$(awk -v K="$K" -v L="$L" 'BEGIN { printf "%.17g", 20.0 / (K * L) }')
	c=$(run --set columns="$K" --set layers="$L" --set m_n="$mn")
	echo "$K $L $((K * L)) $c" >> "$tmp"
done
{
	echo "# Cost against the feed's size"
	echo
	echo "Command: \`bash tests/bench/scaling.sh\` (part of \`make bench\`). Full model, K columns x L"
	echo "layers at a constant feed mass of 20 kg, dem defaults (5e-4 s, 20 sub-steps), steady start,"
	echo "$T simulated seconds, one core. Machine alone at the same step: $c0 CPU s per simulated s."
	echo
	echo "| K x L | N | CPU s / sim s | real time x | feed part (CPU s / sim s) |"
	echo "|---|---|---|---|---|"
	awk -v c0="$c0" '{ printf "| %d x %d | %d | %.4g | %.1f | %.4g |\n", $1, $2, $3, $4, 1 / $4, $4 - c0 }' "$tmp"
	echo
	awk -v c0="$c0" '
		{ f = $4 - c0; if (f > 0 && $3 >= 8) { x = log($3); y = log(f); n++; sx += x; sy += y; sxx += x * x; sxy += x * y } }
		END {
			p = (n * sxy - sx * sy) / (n * sxx - sx * sx); a = exp((sy - p * sx) / n)
			printf "Fit over N >= 8: feed part = %.3g N^%.2f CPU s per simulated s (least squares in log-log).\n", a, p
		}' "$tmp"
} > "$out/scaling.md"
cat "$out/scaling.md"
