#!/usr/bin/env bash
# Accuracy of the transport velocity over the whole beta range, per step
# of the default method (dem: macro step dt, feed sub-steps): v(beta) for
# beta = 0..180 deg every 20 deg, both rotations, full czubak2016 scene,
# against dt = 5e-5 s. The default (sim_default_dt, sim_default_substeps)
# is the fastest setting that stays within 1 % of the peak velocity
# everywhere. Writes $1/beta_range.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${1:-tests/bench/results}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
# dt:substeps; the first is the reference
steps="5e-5:1 1e-4:1 2e-4:1 5e-4:1 1e-3:1 5e-4:5 1e-3:10 1e-3:8 1e-3:5 2e-3:20"
for st in $steps; do
	dt=${st%:*} sub=${st#*:}
	"$BUILD/convsim" sweep --beta 0:180:20 --rotation cw,ccw --duration 6 --threads 2 \
		--set dt="$dt" --set substeps="$sub" 2>/dev/null | tail -n +2 > "$tmp/$st.csv"
	"$BUILD/convsim" run --duration 6 --set dt="$dt" --set substeps="$sub" > "$tmp/$st.json"
done
{
	echo "# Transport velocity over the beta range against the step"
	echo
	echo "Command: \`bash tests/bench/beta_range.sh\` (part of \`make bench\`)."
	echo "Full czubak2016 scene, dem (with more than one sub-step its coupling is corrected), v over [2, 6] s, beta = 0..180 deg every"
	echo "20 deg for cw and ccw (20 runs per step), against dt = 5e-5 s. Real-time factor from one"
	echo "6-s run at beta = 38 deg, cw, on one core."
	echo
	echo "| dt (s) | sub-steps | real time × | worst abs(dv) / peak abs(v) | worst relative where abs(v) > 0.3 peak |"
	echo "|---|---|---|---|---|"
	for st in $steps; do
		dt=${st%:*} sub=${st#*:}
		rtf=$(sed -n 's/.*"real_time_factor": \([0-9.e+-]*\).*/\1/p' "$tmp/$st.json")
		paste -d, "$tmp/5e-5:1.csv" "$tmp/$st.csv" | awk -F, -v dt="$dt" -v nsub="$sub" -v rtf="$rtf" '
			{ ref[NR] = $3; v[NR] = $6; a = $3 < 0 ? -$3 : $3; if (a > peak) peak = a }
			END {
				for (i = 1; i <= NR; i++) {
					d = v[i] - ref[i]; if (d < 0) d = -d
					if (d > wa) wa = d
					a = ref[i] < 0 ? -ref[i] : ref[i]
					if (a > 0.3 * peak && d / a > wr) wr = d / a
				}
				printf "| %s | %s | %.0f | %.2g %% | %.2g %% |\n", dt, nsub, rtf, 100 * wa / peak, 100 * wr
			}'
	done
} > "$out/beta_range.md"
cat "$out/beta_range.md"
