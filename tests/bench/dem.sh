#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The feed against LIGGGHTS (`make bench-dem`, docs/dem.md): convsim-dem on
# one core, one DEM process at a time, niced; every run's JSON line goes to
# tests/bench/results/dem.jsonl and the tables with the column model's
# domain to tests/bench/results/dem.md. The deck's fitted acceleration
# drives the bed at every DEM step (--intervals 0). The scope is a stated
# subset of the issue's (docs/dem.md "What is not done"), chosen to run in
# about an hour of one core. DEM_QUICK=1: one seed, 1-s runs, into
# $BUILD/bench-dem.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
dem="$BUILD/convsim-dem"
if [ "${DEM_QUICK:-0}" = 1 ]; then
	out="$BUILD/bench-dem"; seeds="1"; more=""; dur=1; tr=0.4
else
	out=tests/bench/results; seeds="1 2 3"; more="2 3"; dur=2; tr=0.5
fi
mkdir -p "$out"
jl="$out/dem.jsonl"
# DEM_GROUPS="p1 p2": run those parts only, in place of their rows in
# dem.jsonl (the others kept); default: every part afresh, in this order
parts=${DEM_GROUPS:-curve ladder ladder-top depth ladder-seeds stiffness rolling restitution tangential one-grain}
want() { case " $parts " in *" $1 "*) return 0;; esac; return 1; }
if [ -n "${DEM_GROUPS:-}" ] && [ -f "$jl" ]; then
	python3 - "$jl" $parts <<'PY'
import json, sys
path, drop = sys.argv[1], set(sys.argv[2:])
rows = [l for l in open(path) if l.strip() and json.loads(l).get("part") not in drop]
open(path, "w").writelines(rows)
PY
else
	: > "$jl"
fi
. tests/bench/provenance.sh
prov=$(provenance)
start=$(date +%s)
part=""
run() { # group, convsim-dem options...
	local group=$1; shift
	local line
	line=$(nice -n 15 "$dem" --duration "$dur" --transient "$tr" --intervals 0 "$@" | tr -d '\n ')
	printf '{"group":"%s","part":"%s","args":"%s",%s\n' "$group" "$part" "$*" "${line#\{}" >> "$jl"
	echo "bench-dem: $group $*: $(printf '%s' "$line" | sed -e 's/.*"v_dem":\([^,]*\),"v_column":\([^,]*\),.*/v_dem \1, v_column \2/')"
}
angles="15 30 45 60 75 90 105 120 137 150 165"
# the preset's curve: a 4-diameter bed, both senses, packing seeds
part=curve
want curve && for seed in $seeds; do
	for rot in cw ccw; do
		for beta in $angles; do
			run curve --depth 4 --set layers=4 --set beta=$beta --set rotation=$rot --seed $seed
		done
	done
done
# the stiffness ladder on the same bed at every angle: k_c sets both
# models' stiffness over mass (k_c/m_n: 2e7, 2e8, 2e9 1/s^2; the 2e6 rung
# is the curve's), the column model's feed sub-steps grow with it so that
# it is converged (docs/dem.md: 160 to 2e8, 500 at 2e9); seed 1, then
# seeds 2 and 3 at 2e7 (docs/dem.md)
ladder() { # seeds
	for seed in "$@"; do
		for rot in cw ccw; do
			for beta in $angles; do
				run ladder --depth 4 --set layers=4 --set beta=$beta --set rotation=$rot \
					--set k_c=$k --set substeps=$sub --seed $seed
			done
		done
	done
}
sub=160
part=ladder
want ladder && for k in 1e7 1e8; do ladder 1; done
# the top rung, its own part (about half an hour of one core)
part=ladder-top
want ladder-top && k=1e9 sub=500 && ladder 1
# depth, with packing seeds
part=depth
want depth && for depth in 1 2 4 8 16; do
	for seed in $seeds; do
		run depth --depth $depth --set layers=$depth --set beta=30 --seed $seed
	done
done
part=ladder-seeds
k=1e7 sub=160
want ladder-seeds && [ -n "$more" ] && ladder $more
# an 8-diameter bed's ladder at 30 deg
part=stiffness
want stiffness && for k in 1e7 1e8; do
	run stiffness --depth 8 --set layers=8 --set beta=30 --set k_c=$k --set substeps=160 --seed 1
done
# rolling friction on, restitution 0.5, and friction without a tangential spring
part=rolling
want rolling && for seed in $seeds; do
	run rolling --depth 8 --set layers=8 --set beta=30 --mu-roll 0.1 --seed $seed
done
part=restitution
want restitution && run restitution --depth 8 --set layers=8 --set beta=30 --restitution 0.5 --set R=0.5 --seed 1
part=tangential
want tangential && for seed in $seeds; do
	run tangential --depth 4 --set layers=4 --set beta=30 --tangential viscous --seed $seed
done
# one grain of 4 mm, rotation frozen, the preset's contacts at 30 deg
# clockwise: the formula drive against the acceleration held over 32
# intervals a period and over 4 and 1 DEM steps (225 and 901 intervals;
# docs/dem.md "Coupling interval")
part=one-grain
want one-grain && for n in 0 32 225 901; do
	run one-grain --grains 1 --d-min 0.004 --d-max 0.004 --freeze-rotation --set layers=1 \
		--set beta=30 --intervals $n --seed 1
done
python3 tests/bench/dem_plot.py "$jl" "make bench-dem" "$(date -u +%Y-%m-%d)" > "$out/dem.svg"
python3 tests/bench/dem_report.py "$jl" "make bench-dem" "$(date -u +%Y-%m-%d)" \
	"$(( $(date +%s) - start ))" ${DEM_GROUPS:+" for the parts $DEM_GROUPS (DEM_GROUPS), the other rows kept"} \
	> "$out/dem.md"
stamp "$out/dem.md" "$prov"
# the curve's points for the calibrated preset's fit (docs/dem.md "Calibrated to a bed")
want curve && python3 tests/bench/dem_report.py --bed4-csv "$jl" > "$out/dem_bed4.csv"
cat "$out/dem.md"
