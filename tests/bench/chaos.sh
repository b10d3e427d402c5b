#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# Issue 37's chaotic feed (R = 0.5, mu = 0.6): the default sweep's bars
# against a long-window reference. The reference,
# tests/bench/zoo/chaos_ref.tsv (made where missing: vref, as
# tests/bench/vref.sh builds it, at 1.25e-4 s / 40 sub-steps, beta =
# 0..180 deg every 5 deg clockwise, 15 consecutive 4-s windows after the
# steady start; about 200 CPU s): v_ref is the windows' mean, se their
# standard error; its step error is not measured (one level). For each
# build of BUILDS (NAME=DIR pairs, space separated; default: this build)
# the sweep `convsim sweep --beta 0:180:5 --rotation cw --threads 1 --set
# R=0.5 --set mu=0.6` (CPU: the least of 3 runs): the median of bar /
# error (the error taken as at least 2 se), tol_met's share, the points
# whose bar holds v_ref (and within 2 se of it), the worst error (docs/MODEL.md's
# convention) and CPU a point. Writes $1/chaos.md.
set -eu
cd "$(dirname "$0")/../.."
. tests/bench/provenance.sh
prov=$(provenance)
BUILDS=${BUILDS:-this=build}
out=${1:-tests/bench/results}
ref=${REF:-tests/bench/zoo/chaos_ref.tsv}
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
feed=(--set R=0.5 --set mu=0.6)
if [ ! -s "$ref" ]; then
	cc -O2 -Wall -Wextra -Werror -std=c11 -D_POSIX_C_SOURCE=200809L -Icore \
		-o "$tmp/vref" tests/bench/vref.c build/libcore.a -lm -lpthread
	"$tmp/vref" --beta 0:180:5 --rotation cw --windows 4,8,12,16,20,24,28,32,36,40,44,48,52,56,60,64 \
		--threads "${THREADS:-1}" --set dt=1.25e-4 --set substeps=40 "${feed[@]}" > "$ref"
fi
TIMEFORMAT=%U
rows=()
for nb in $BUILDS; do
	name=${nb%%=*} dir=${nb#*=} best=
	for _ in 1 2 3; do
		cpu=$({ time "$dir/convsim" sweep -q --beta 0:180:5 --rotation cw --threads 1 --format csv \
			"${feed[@]}" > "$tmp/$name.csv"; } 2>&1)
		best=$(awk -v a="$cpu" -v b="$best" 'BEGIN { print (b == "" || a < b) ? a : b }')
	done
	rows+=("$(python3 - "$ref" "$tmp/$name.csv" "$name" "$best" <<'EOF'
import csv, math, statistics as st, sys
ref = {}
for line in open(sys.argv[1]):
    f = line.rstrip('\n').split('\t')
    v = [float(x) for x in f[2:-1]]
    ref[float(f[0])] = (st.mean(v), st.stdev(v) / math.sqrt(len(v)))
peak = max(abs(v) for v, _ in ref.values())
rows = list(csv.DictReader(open(sys.argv[2])))
ratio, met, holds, near, worst = [], 0, 0, 0, 0.0
for r in rows:
    vr, se = ref[float(r['beta'])]
    e, u = abs(float(r['velocity']) - vr), float(r['uncertainty'])
    ratio.append(u / max(e, 2 * se))
    met += r['tol_met'] == 'true'
    holds += e <= u
    near += e <= u + 2 * se
    worst = max(worst, e / (abs(vr) if abs(vr) >= 0.3 * peak else peak))
n = len(rows)
print(f"| {sys.argv[3]} | {st.median(ratio):.2f} | {met} of {n} ({100 * met / n:.0f} %) | {holds} | {near} "
      f"| {100 * worst:.2f} % | {1000 * float(sys.argv[4]) / n:.1f} |")
EOF
)")
	echo "chaos: $name" >&2
done
se_max=$(python3 -c '
import math, statistics as st, sys
m = p = 0.0
for line in open(sys.argv[1]):
    v = [float(x) for x in line.split("\t")[2:-1]]
    m = max(m, st.stdev(v) / math.sqrt(len(v))); p = max(p, abs(st.mean(v)))
print(f"{1e3 * m:.2f} mm/s ({100 * m / p:.2f} % of the peak {p:.4f} m/s)")' "$ref")
{
	echo "# The chaotic feed's bars against a long-window reference"
	echo
	echo "$prov"
	echo "Command: \`BUILDS=\"$BUILDS\" bash tests/bench/chaos.sh\`. The sweep \`convsim sweep --beta"
	echo "0:180:5 --rotation cw --threads 1 --set R=0.5 --set mu=0.6\` (37 points, the defaults: tol ="
	echo "1 %, a 4-s window) against \`tests/bench/zoo/chaos_ref.tsv\` (vref at 1.25e-4 s / 40"
	echo "sub-steps, 15 consecutive 4-s windows after the steady start: v_ref their mean, se their"
	echo "standard error, at most $se_max; its step error not measured). \"bar / error\": the median"
	echo "over the points of the bar over |v - v_ref|, that taken as at least 2 se; \"holds\": points"
	echo "whose bar contains v_ref; \"within 2 se\": whose bar does to within the reference's 2 se;"
	echo "CPU: the least of 3 runs of the whole sweep, one core, over the points. $(date -u +%Y-%m-%d)."
	echo
	echo "| build | bar / error (median) | tol_met | holds | within 2 se | worst error | CPU ms a point |"
	echo "|---|---|---|---|---|---|---|"
	printf '%s\n' "${rows[@]}"
} > "$out/chaos.md.tmp"
mv "$out/chaos.md.tmp" "$out/chaos.md"
cat "$out/chaos.md"
