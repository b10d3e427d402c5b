#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Issue 37's chaotic feed (R = 0.5, mu = 0.6): the default sweep's bars
# against a long-window reference. The reference,
# tests/bench/zoo/chaos_ref.tsv (made where missing: vref, as
# tests/bench/vref.sh builds it, at 1.25e-4 s / 40 sub-steps, beta =
# 0..180 deg every 5 deg clockwise, 15 consecutive 16-s windows after the
# steady start; about 700 CPU s): v_ref is the windows' mean, se their
# standard error; its step error is not measured (one level). For each
# build of BUILDS (NAME=DIR pairs, space separated; default: this build)
# the sweep `convsim sweep --beta 0:180:5 --rotation cw --threads 1 --set
# R=0.5 --set mu=0.6` once for each settling of SETTLES (the settling
# before t = 0 changes the chaotic trajectory, not its statistics: each
# is a realization of the same 37 points), over all of them: the median
# of bar / error (the error taken as at least 2 se), tol_met's share, the
# bars within docs/MODEL.md's 1 % (|v_ref| where at least 0.3 of the
# peak, else the peak), the points whose bar holds v_ref (and within 2 se
# of it), the worst error (MODEL.md's convention) and CPU a point (the
# sweeps' total). Then every point whose bar misses v_ref. Writes
# $1/chaos.md.
set -eu
cd "$(dirname "$0")/../.."
. tests/bench/provenance.sh
prov=$(provenance)
BUILDS=${BUILDS:-this=build}
SETTLES=${SETTLES:-0.6 0.73 0.87}
out=${1:-tests/bench/results}
ref=${REF:-tests/bench/zoo/chaos_ref.tsv}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
feed=(--set R=0.5 --set mu=0.6)
if [ ! -s "$ref" ]; then
	cc -O2 -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -Icore \
		-o "$tmp/vref" tests/bench/vref.c build/libcore.a -lm -lpthread
	"$tmp/vref" --beta 0:180:5 --rotation cw \
		--windows 4,20,36,52,68,84,100,116,132,148,164,180,196,212,228,244 \
		--threads "${THREADS:-1}" --set dt=1.25e-4 --set substeps=40 "${feed[@]}" > "$ref"
fi
TIMEFORMAT=%U
rows=() misses=()
for nb in $BUILDS; do
	name=${nb%%=*} dir=${nb#*=} cpu=0 csvs=()
	for st in $SETTLES; do
		t=$({ time "$dir/convsim" sweep -q --beta 0:180:5 --rotation cw --threads 1 --format csv \
			"${feed[@]}" --set settle="$st" > "$tmp/$name-$st.csv"; } 2>&1)
		cpu=$(awk -v a="$cpu" -v b="$t" 'BEGIN { print a + b }')
		csvs+=("$st=$tmp/$name-$st.csv")
	done
	python3 - "$ref" "$name" "$cpu" "${csvs[@]}" > "$tmp/$name.out" <<'EOF2'
import csv, math, statistics as st, sys
ref = {}
for line in open(sys.argv[1]):
    f = line.rstrip('\n').split('\t')
    v = [float(x) for x in f[2:-1]]
    ref[float(f[0])] = (st.mean(v), st.stdev(v) / math.sqrt(len(v)))
peak = max(abs(v) for v, _ in ref.values())
name, cpu = sys.argv[2], float(sys.argv[3])
ratio, met, model, holds, near, worst, miss = [], 0, 0, 0, 0, 0.0, []
for arg in sys.argv[4:]:
    settle, path = arg.split('=', 1)
    for r in csv.DictReader(open(path)):
        vr, se = ref[float(r['beta'])]
        e, u = abs(float(r['velocity']) - vr), float(r['uncertainty'])
        den = abs(vr) if abs(vr) >= 0.3 * peak else peak
        ratio.append(u / max(e, 2 * se))
        met += r['tol_met'] == 'true'
        model += u <= 0.01 * den
        holds += e <= u
        near += e <= u + 2 * se
        worst = max(worst, e / den)
        if e > u:
            miss.append(f"| {name} | {settle} | {r['beta']} | {1e3 * e:.3f} | {1e3 * u:.3f} | {1e3 * se:.3f} "
                        f"| {r['tol_met']} |")
n = len(ratio)
print(f"| {name} | {st.median(ratio):.2f} | {met} of {n} ({100 * met / n:.0f} %) | {model} | {holds} | {near} "
      f"| {100 * worst:.2f} % | {1000 * cpu / n:.1f} |")
for m in miss:
    print(m)
EOF2
	rows+=("$(head -1 "$tmp/$name.out")")
	while IFS= read -r m; do misses+=("$m"); done < <(tail -n +2 "$tmp/$name.out")
	echo "chaos: $name" >&2
done
se_max=$(python3 -c '
import math, statistics as st, sys
m = p = 0.0
for line in open(sys.argv[1]):
    v = [float(x) for x in line.split("\t")[2:-1]]
    m = max(m, st.stdev(v) / math.sqrt(len(v))); p = max(p, abs(st.mean(v)))
print(f"{1e3 * m:.2f} mm/s ({100 * m / p:.2f} % of the peak {p:.4f} m/s)")' "$ref")
n_settle=$(echo $SETTLES | wc -w)
{
	echo "# The chaotic feed's bars against a long-window reference"
	echo
	echo "$prov"
	echo "Command: \`BUILDS=\"$BUILDS\" SETTLES=\"$SETTLES\" bash tests/bench/chaos.sh\`. The sweep \`convsim"
	echo "sweep --beta 0:180:5 --rotation cw --threads 1 --set R=0.5 --set mu=0.6 --set settle=S\` (37"
	echo "points, the defaults: tol = 1 %, a 4-s window) for each of the $n_settle settlings S (realizations of the"
	echo "same points), against \`tests/bench/zoo/chaos_ref.tsv\` (vref at 1.25e-4 s / 40 sub-steps, 15"
	echo "consecutive 16-s windows after the steady start: v_ref their mean, se their standard error, at"
	echo "most $se_max; its step error not measured). \"bar / error\": the"
	echo "median over the points of the bar over |v - v_ref|, that taken as at least 2 se; \"within 1 %\":"
	echo "bars within docs/MODEL.md's 1 % (of |v_ref| where at least 0.3 of the peak, else of the peak),"
	echo "where \`tol_met\` asks the same of the run's own v, its peak taken as half the trough's largest speed;"
	echo "\"holds\": points whose bar contains v_ref; \"within 2 se\": whose bar does to within the"
	echo "reference's 2 se; CPU: the sweeps' total, one core, over their points. $(date -u +%Y-%m-%d)."
	echo
	echo "| build | bar / error (median) | tol_met | within 1 % | holds | within 2 se | worst error | CPU ms a point |"
	echo "|---|---|---|---|---|---|---|---|"
	printf '%s\n' "${rows[@]}"
	echo
	echo "Every point whose bar misses v_ref (mm/s):"
	echo
	echo "| build | settle | beta | \\|v - v_ref\\| | bar | se | tol_met |"
	echo "|---|---|---|---|---|---|---|"
	if [ ${#misses[@]} -gt 0 ]; then printf '%s\n' "${misses[@]}"; else echo "| none | | | | | | |"; fi
} > "$out/chaos.md.tmp"
mv "$out/chaos.md.tmp" "$out/chaos.md"
cat "$out/chaos.md"
