#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The feed against LIGGGHTS (`make bench-dem`, docs/dem.md): convsim-dem on
# one core, one DEM process at a time, niced; every run's JSON line goes to
# tests/bench/results/dem.jsonl and the table with the column model's
# domain to tests/bench/results/dem.md. The scope is a stated subset of
# the issue's (docs/dem.md "What is not measured"), chosen to run in about
# ten CPU minutes. DEM_QUICK=1: one seed, 1-s runs, into $BUILD/bench-dem.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
dem="$BUILD/convsim-dem"
if [ "${DEM_QUICK:-0}" = 1 ]; then
	out="$BUILD/bench-dem"; seeds="1"; dur=1; tr=0.4
else
	out=tests/bench/results; seeds="1 2 3"; dur=2; tr=0.5
fi
mkdir -p "$out"
jl="$out/dem.jsonl"
# DEM_GROUPS="g1 g2": run those groups only, in place of their rows in
# dem.jsonl (the others kept); default: every group afresh
groups=${DEM_GROUPS:-curve depth stiffness rolling restitution}
want() { case " $groups " in *" $1 "*) return 0;; esac; return 1; }
if [ -n "${DEM_GROUPS:-}" ] && [ -f "$jl" ]; then
	python3 - "$jl" $groups <<'PY'
import json, sys
path, drop = sys.argv[1], set(sys.argv[2:])
rows = [l for l in open(path) if l.strip() and json.loads(l)["group"] not in drop]
open(path, "w").writelines(rows)
PY
else
	: > "$jl"
fi
start=$(date +%s)
run() { # group, convsim-dem options...
	local group=$1; shift
	local line
	line=$(nice -n 15 "$dem" --duration "$dur" --transient "$tr" --intervals 32 "$@" | tr -d '\n ')
	printf '{"group":"%s","args":"%s",%s\n' "$group" "$*" "${line#\{}" >> "$jl"
	echo "bench-dem: $group $*: $(printf '%s' "$line" | sed -e 's/.*"v_dem":\([^,]*\),"v_column":\([^,]*\),.*/v_dem \1, v_column \2/')"
}
# the preset's curve: a 4-diameter bed, both senses
want curve && for rot in cw ccw; do
	for beta in 15 30 45 60 90 120 137 150 165; do
		run curve --depth 4 --set layers=4 --set beta=$beta --set rotation=$rot --seed 1
	done
done
# depth, with packing seeds
want depth && for depth in 1 2 4 8 16; do
	for seed in $seeds; do
		run depth --depth $depth --set layers=$depth --set beta=30 --seed $seed
	done
done
# the stiffness ladder: k_c sets both beds' stiffness over mass (k_c/m_n;
# the 2e6 rung is the depth group's); the column model's feed sub-steps
# grow with it, so that it is converged (docs/dem.md)
want stiffness && for rung in 1e7:160 1e8:160 1e10:640; do
	run stiffness --depth 8 --set layers=8 --set beta=30 --set k_c=${rung%%:*} \
		--set substeps=${rung##*:} --seed 1
done
# rolling friction on, and restitution 0.5
want rolling && for seed in $seeds; do
	run rolling --depth 8 --set layers=8 --set beta=30 --mu-roll 0.1 --seed $seed
done
want restitution && run restitution --depth 8 --set layers=8 --set beta=30 --restitution 0.5 --set R=0.5 --seed 1
python3 tests/bench/dem_plot.py "$jl" "make bench-dem" "$(date -u +%Y-%m-%d)" > "$out/dem.svg"
python3 tests/bench/dem_report.py "$jl" "make bench-dem" "$(date -u +%Y-%m-%d)" \
	"$(( $(date +%s) - start ))" ${DEM_GROUPS:+" for the groups $DEM_GROUPS (DEM_GROUPS), the other rows kept"} \
	> "$out/dem.md"
cat "$out/dem.md"
