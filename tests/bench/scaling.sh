#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Cost against the feed's size (part of `make bench`): the full model
# (trough_rotation=true, so every column is integrated) on the whole grid
# K = 1, 2, 5, 10, 20 columns x L = 1, 2, 4, 8, 16, 32 layers at a constant
# feed mass of 20 kg (m_n = 20 / (K L) kg, the czubak2016 feed's mass, so
# the coupling and the default step stay the same), the defaults
# otherwise, one core. The cost of a simulated second is that of the
# 4-s window after the steady start: the CPU seconds of a 4-s run less
# those of the start alone (a 1-ms run: shooting and settling), over 4;
# each the least of three repeats (the machine is shared). Fits, least
# squares in log-log over N = K L >= 8: the feed part (cost less the
# machine alone's, c0) as a N^p, and the total as b N^q. Writes
# $1/scaling.md and $1/scaling.tsv.
set -eu
cd "$(dirname "$0")/../.."
. tests/bench/provenance.sh
prov=$(provenance)
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
mkdir -p "$out"
T=4
cpu() { # duration, settings...: the run's CPU seconds, the least of three
	local d=$1 best= c; shift
	for _ in 1 2 3; do
		c=$("$BUILD/convsim" run -q --duration "$d" --sample-rate 10 --set trough_rotation=true "$@" |
			sed -n 's/.*"cpu_seconds": \([0-9.e+-]*\).*/\1/p')
		best=$(awk -v a="$c" -v b="${best:-$c}" 'BEGIN { printf "%.6g", a < b ? a : b }')
	done
	echo "$best"
}
window() { # settings...: CPU s per simulated s of the window, and the start's CPU s
	local full start
	full=$(cpu "$T" "$@")
	start=$(cpu 0.001 "$@")
	awk -v f="$full" -v s="$start" -v T="$T" 'BEGIN { printf "%.6g %.6g", (f - s) / T, s }'
}
read -r c0 _ <<<"$(window --set feed=false --set dt=1.25e-3)"
tsv="$out/scaling.tsv"
echo "K	L	N	cpu_per_sim_s	start_cpu_s" > "$tsv"
for K in 1 2 5 10 20; do
	for L in 1 2 4 8 16 32; do
		mn=$(awk -v K="$K" -v L="$L" 'BEGIN { printf "%.17g", 20.0 / (K * L) }')
		read -r c s <<<"$(window --set columns="$K" --set layers="$L" --set m_n="$mn")"
		printf '%s\t%s\t%s\t%s\t%s\n' "$K" "$L" $((K * L)) "$c" "$s" >> "$tsv"
	done
done
fit() { # column expression (awk, of $3 = N and f = cost - c0), label
	awk -F'\t' -v c0="$c0" -v label="$2" '
		NR == 1 { next }
		{ f = $4 - c0; y = '"$1"'; if (y > 0 && $3 >= 8) { x = log($3); y = log(y); n++; sx += x; sy += y; sxx += x * x; sxy += x * y } }
		END {
			p = (n * sxy - sx * sy) / (n * sxx - sx * sx); a = exp((sy - p * sx) / n)
			printf "%s = %.3g N^%.2f CPU s per simulated s (%d sizes)", label, a, p, n
		}' "$tsv"
}
table() { # the grid: CPU s per simulated s, real time factor in brackets
	awk -F'\t' '
		NR == 1 { next }
		{ c[$1 " " $2] = $4; if (!($1 in seenK)) { seenK[$1] = 1; Ks[++nk] = $1 }
		  if (!($2 in seenL)) { seenL[$2] = 1; Ls[++nl] = $2 } }
		END {
			printf "| K \\ L |"; for (j = 1; j <= nl; j++) printf " %s |", Ls[j]; printf "\n|---|"
			for (j = 1; j <= nl; j++) printf "---|"; printf "\n"
			for (i = 1; i <= nk; i++) {
				printf "| %s |", Ks[i]
				for (j = 1; j <= nl; j++) { v = c[Ks[i] " " Ls[j]]; printf " %.4g (%.0f×) |", v, 1 / v }
				printf "\n"
			}
		}' "$tsv"
}
{
	echo "# Cost against the feed's size"
	echo
	echo "$prov"
	echo "Command: \`bash tests/bench/scaling.sh\` (part of \`make bench\`). Full model"
	echo "(trough_rotation=true), K columns x L layers at a constant feed mass of 20 kg, dem defaults"
	echo "(1.25e-3 s, 5 sub-steps, feed_events), one core. CPU seconds per simulated second of the 4-s window after the"
	echo "steady start (a 4-s run less the start alone, the least of three repeats), real-time factor in"
	echo "brackets. Machine alone at the same step: $c0 CPU s per simulated s. Raw: scaling.tsv (with"
	echo "the start's own CPU seconds)."
	echo
	table
	echo
	echo "Fits, least squares in log-log over N = K L >= 8:"
	echo
	echo "- $(fit f 'feed part (cost less the machine alone)')"
	echo "- $(fit '$4' 'total')"
} > "$out/scaling.md"
cat "$out/scaling.md"
