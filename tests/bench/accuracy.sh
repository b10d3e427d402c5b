#!/usr/bin/env bash
# The accuracy gate (part of `make bench`): the 74-point v(beta) curve,
# beta = 0..180 deg every 5 deg, both senses, with the defaults of
# `convsim sweep` (what daemon sweeps use too), against the converged
# reference tests/bench/results/vref.tsv (tests/bench/vref.sh). Also the
# full model (trough_rotation=true) at the same defaults, so the automatic
# symmetric reduction's own error shows. Accuracy convention (MODEL.md):
# a point is within 1 % when |v - v_ref| <= 0.01 |v_ref| where
# |v_ref| >= 0.3 peak, else <= 0.01 peak. Each point's error bar u (the
# sweep's `uncertainty`) must contain v_ref. Writes $1/accuracy.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
ref=tests/bench/results/vref.tsv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
TIMEFORMAT=%U
sweep() { # name, extra arguments...: one core, CPU seconds into $tmp/name.cpu
	local name=$1; shift
	{ time "$BUILD/convsim" sweep --beta 0:180:5 --rotation cw,ccw --threads 1 --format csv "$@" \
		> "$tmp/$name.csv" 2>/dev/null; } 2> "$tmp/$name.cpu"
}
sweep default
sweep full --set trough_rotation=true
gate() { # name: the summary row of one sweep against the reference
	awk -F'[,\t]' -v name="$1" -v cpu="$(cat "$tmp/$1.cpu")" '
		function abs(x) { return x < 0 ? -x : x }
		FNR == 1 { next }
		NR == FNR { k = $1 " " $2; vref[k] = $3; a = abs($3); if (a > peak) peak = a; next }
		{
			k = $1 " " $2; v = $3; u = $4; d = abs(v - vref[k])
			den = abs(vref[k]) >= 0.3 * peak ? abs(vref[k]) : peak
			e = d / den; n++
			if (e > worst) { worst = e; at = $1 "° " $2 }
			if (e > 0.01) bad++
			if (!(d <= u)) outside++
			if ($5 != "true") unsteady++
		}
		END {
			printf "| %s | %d | %.2f %% (%s) | %d | %d | %d | %s |\n", name, n, 100 * worst, at,
				bad, outside, unsteady, cpu
		}' "$ref" "$tmp/$1.csv"
}
{
	echo "# The v(beta) curve against the converged reference"
	echo
	echo "Command: \`bash tests/bench/accuracy.sh\` (part of \`make bench\`). 74 points (beta = 0..180 deg"
	echo "every 5 deg, cw and ccw), \`build/convsim sweep --beta 0:180:5 --rotation cw,ccw --threads 1\`"
	echo "with its defaults, against \`tests/bench/results/vref.tsv\` (\`tests/bench/vref.sh\`). Error by"
	echo "MODEL.md's convention; \"outside u\": points whose |v - v_ref| exceeds the reported"
	echo "uncertainty; CPU: seconds on one core for the whole curve."
	echo
	echo "| run | points | worst error | beyond 1 % | outside u | not steady | CPU s |"
	echo "|---|---|---|---|---|---|---|"
	gate default
	gate full
	echo
	echo "Per point (default run): beta, rotation, v, uncertainty, v_ref, error (convention, %)."
	echo
	echo '```'
	awk -F'[,\t]' '
		function abs(x) { return x < 0 ? -x : x }
		FNR == 1 { next }
		NR == FNR { k = $1 " " $2; vref[k] = $3; a = abs($3); if (a > peak) peak = a; next }
		{
			k = $1 " " $2; den = abs(vref[k]) >= 0.3 * peak ? abs(vref[k]) : peak
			printf "%5s %-3s %+.5f ± %.5f  ref %+.5f  %+.2f %%\n", $1, $2, $3, $4, vref[k],
				100 * ($3 - vref[k]) / den
		}' "$ref" "$tmp/default.csv"
	echo '```'
} > "$out/accuracy.md"
sed -n '1,/^Per point/p' "$out/accuracy.md"
