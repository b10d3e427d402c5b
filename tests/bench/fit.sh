#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The calibration target (`make bench`, or alone: bash tests/bench/fit.sh
# [OUTDIR]): a 2-parameter fit (e and mu) on 20 points of the czubak2016
# defaults (beta 15..150 deg every 15, both rotations) must converge in
# under 30 s of wall time on 2 cores. The points are the model's own
# v(beta) at e = 0.018 m, mu = 0.5 with Gaussian noise of sigma 0.002 m/s
# (fixed seed), the fit starts at the preset (e = 0.0215 m, mu = 0.4).
# Repeated REPEAT times (default 3: the machine is shared); the table gives
# wall and CPU time (user + sys) of each run and what the fit found.
. "$(dirname "$0")/preamble.sh"
. tests/bench/provenance.sh
prov=$(provenance)
"$cli" sweep --beta 15:150:15 --rotation cw,ccw --set e=0.018 --set mu=0.5 -q --threads 2 > "$work/clean.csv"
awk -F, 'BEGIN { srand(2016); print "beta,rotation,v,sigma" }
	NR > 1 { u1 = rand(); u2 = rand(); if (u1 < 1e-12) u1 = 1e-12
		 n = sqrt(-2 * log(u1)) * cos(6.283185307179586 * u2)
		 printf "%s,%s,%.6f,0.002\n", $1, $2, $3 + 0.002 * n }' "$work/clean.csv" > "$work/data.csv"
cmd="convsim fit --data DATA --free e,mu --threads 2 --curve-step 0"
{
	echo "# Calibration: a 2-parameter fit on 20 points"
	echo
	echo "$prov"
	echo "Made by \`bash tests/bench/fit.sh\` (part of \`make bench\`) on $(nproc) cores, $(date -u +%Y-%m-%d):"
	echo "\`$cmd\`, the 20 points of the czubak2016 defaults at e = 0.018 m, mu = 0.5 plus noise"
	echo "(sigma 0.002 m/s, seed 2016), from the preset's e = 0.0215 m, mu = 0.4. Target: < 30 s wall."
	echo
	echo "| run | wall / s | CPU / s (user+sys) | iterations | evaluations | e / m | mu | status |"
	echo "|---|---|---|---|---|---|---|---|"
} > "$out/fit.md"
for i in $(seq 1 "$repeat"); do
	/usr/bin/time -f "%e %U %S" -o "$work/time" "$cli" fit --data "$work/data.csv" --free e,mu \
		--threads 2 --curve-step 0 -q > "$work/fit.json"
	read -r wall user sys < "$work/time"
	python3 - "$work/fit.json" "$i" "$wall" "$user" "$sys" >> "$out/fit.md" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
e, mu = r["parameters"]
print(f"| {sys.argv[2]} | {float(sys.argv[3]):.1f} | {float(sys.argv[4]) + float(sys.argv[5]):.1f} | "
      f"{r['iterations']} | {r['evaluations']} | {e['value']:.5f} ± {e['standard_error']:.5f} | "
      f"{mu['value']:.3f} ± {mu['standard_error']:.3f} | {r['status']} |")
PY
done
cat "$out/fit.md"
