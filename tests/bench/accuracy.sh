#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The accuracy gate (part of `make bench`): the 74-point v(beta) curve,
# beta = 0..180 deg every 5 deg, both senses, with the defaults of
# `convsim sweep` (what daemon sweeps use too), against the converged
# reference tests/bench/results/vref.tsv (tests/bench/vref.sh). Also the
# full model (trough_rotation=true) at the same defaults, so the automatic
# symmetric reduction's own error shows, and every point run directly
# (mirror=false), so the mirror reduction's does. Accuracy convention (docs/MODEL.md):
# a point is within 1 % when |v - v_ref| <= 0.01 |v_ref| where
# |v_ref| >= 0.3 peak, else <= 0.01 peak. Each point's error bar u (the
# sweep's `uncertainty`) must contain v_ref. Writes $1/accuracy.md.
set -eu
cd "$(dirname "$0")/../.."
. tests/bench/provenance.sh
prov=$(provenance)
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
ref=tests/bench/results/vref.tsv
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
TIMEFORMAT=%U
key() { printf '%s' "$1" | tr ' /+' '___'; }
sweep() { # name, extra arguments...: one core, CPU seconds into $tmp/name.cpu
	local f; f="$tmp/$(key "$1")"; shift
	{ time "$BUILD/convsim" sweep --beta 0:180:5 --rotation cw,ccw --threads 1 --format csv "$@" \
		> "$f.csv" 2>/dev/null; } 2> "$f.cpu"
}
# name | sweep arguments | what the row shows
runs=(
	"default||the defaults (steady start settled 0.6 s, 4-s window, dem 1.25e-3 s / 5 sub-steps with feed_events, symmetric and mirror reductions)"
	"full|--set trough_rotation=true|the same on the full model: the symmetric reduction's own error"
	"direct|--set mirror=false|every point run, none taken as a mirror image: the mirror reduction's own error"
	"settle 1 s|--set settle=1|the former settling's length"
	"settle 0.5 s|--set settle=0.5|shorter settling"
	"settle 0.4 s|--set settle=0.4|shorter still"
	"settle 0.3 s|--set settle=0.3|the shortest settling tried"
	"window 3 s|--duration 3|the defaults with a 3-s window"
	"window 3 s, settle 1 s|--duration 3 --set settle=1|a 3-s window after a 1-s settling"
	"window 2 s|--duration 2|the defaults with a 2-s window"
	"rest 2+2 s|--set start=rest --set transient=2 --duration 4|the former measurement: run-up from rest, window [2, 4] s"
	"rest 8+4 s|--set start=rest --set transient=8 --duration 12|run-up from rest, window [8, 12] s"
	"1.25e-3 / 4|--set substeps=4|feed step 3.1e-4 s"
	"1.25e-3 / 10|--set substeps=10|feed step halved"
	"1e-3 / 4|--set dt=1e-3 --set substeps=4|the former default: machine step 1e-3 s, the same feed step"
	"5e-4 / 2|--set dt=5e-4 --set substeps=2|machine step 5e-4 s, the same feed step"
	"1.8e-3 / 7|--set dt=1.8e-3 --set substeps=7|machine step near its stability bound (1.89e-3 s: the motor's slip mode), feed step 2.6e-4 s"
	"former dem|--set feed_events=false|the former dem (feed_events=false: 1e-3 s / 16 sub-steps, no located reversals, no yielding deck)"
	"former 1e-3 / 12|--set feed_events=false --set substeps=12|the former dem, feed step 8.3e-5 s"
	"former full|--set feed_events=false --set trough_rotation=true|the former dem on the full model"
)
for r in "${runs[@]}"; do
	IFS='|' read -r name args _ <<<"$r"
	# shellcheck disable=SC2086
	sweep "$name" $args
done
gate() { # name, what: the summary row of one sweep against the reference
	local f; f="$tmp/$(key "$1")"
	awk -F'[,\t]' -v name="$1" -v what="$2" -v cpu="$(cat "$f.cpu")" '
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
			printf "| %s | %s | %.2f %% (%s) | %d | %d | %d | %s |\n", name, what, 100 * worst, at,
				bad, outside, unsteady, cpu
		}' "$ref" "$f.csv"
}
{
	echo "# The v(beta) curve against the converged reference"
	echo
	echo "$prov"
	echo "Command: \`bash tests/bench/accuracy.sh\` (part of \`make bench\`). 74 points (beta = 0..180 deg"
	echo "every 5 deg, cw and ccw), \`build/convsim sweep --beta 0:180:5 --rotation cw,ccw --threads 1\`"
	echo "with its defaults, against \`tests/bench/results/vref.tsv\` (\`tests/bench/vref.sh\`). Error by"
	echo "docs/MODEL.md's convention; \"outside u\": points whose |v - v_ref| exceeds the reported"
	echo "uncertainty; CPU: seconds on one core for the whole curve."
	echo
	echo "| run | what | worst error | beyond 1 % | outside u | not steady | CPU s |"
	echo "|---|---|---|---|---|---|---|"
	for r in "${runs[@]}"; do
		IFS='|' read -r name _ what <<<"$r"
		gate "$name" "$what"
	done
	echo
	# the automatic reduction against the full model, point by point (two
	# sweep CSVs side by side: beta,rotation,velocity,uncertainty,steady,... each)
	paste -d, "$tmp/default.csv" "$tmp/full.csv" | awk -F, -v cd="$(cat "$tmp/default.cpu")" \
		-v cf="$(cat "$tmp/full.cpu")" '
		function abs(x) { return x < 0 ? -x : x }
		NR == 1 { next }
		{ h = NF / 2; a = abs($(h + 3)); if (a > peak) peak = a; d = abs($3 - $(h + 3)); if (d > worst) { worst = d; at = $1 "° " $2 } }
		END {
			printf "The symmetric reduction (applied by the defaults) against the full model at the same\n"
			printf "step and start, all 74 points: largest |v - v_full| = %.2g m/s (%.3f %% of the peak, at %s);\n", worst, 100 * worst / peak, at
			printf "speed-up %.2f (CPU of the curve).\n", cf / cd
		}'
	echo
	# the mirror reduction against running every point
	paste -d, "$tmp/default.csv" "$tmp/direct.csv" | awk -F, -v cd="$(cat "$tmp/default.cpu")" \
		-v cf="$(cat "$tmp/direct.cpu")" '
		function abs(x) { return x < 0 ? -x : x }
		NR == 1 { next }
		{
			h = NF / 2; a = abs($(h + 3)); if (a > peak) peak = a; d = abs($3 - $(h + 3)); if (d > worst) { worst = d; at = $1 "° " $2 }
			du = abs($4 - $(h + 4)) / $(h + 4); if (du > wu) wu = du; if ($5 != $(h + 5)) flags++
		}
		END {
			printf "The mirror reduction (applied by the defaults) against running every point, all 74 points:\n"
			printf "largest |v - v_direct| = %.2g m/s (%.4f %% of the peak, at %s), error bars within %.1f %%,\n", worst, 100 * worst / peak, at, 100 * wu
			printf "%d steady flags differ; speed-up %.2f (CPU of the curve).\n", flags, cf / cd
		}'
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
sed -n '1,/^Per point/p' "$out/accuracy.md" | head -n -1
