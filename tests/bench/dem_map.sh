#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The DEM reference map (`make bench-dem-map`, docs/dem.md "The map"):
# builds convsim-dem from the map's commit into build-demmap/COMMIT/ (the
# commit of the rows already in tests/bench/results/dem_map.csv, else
# DEM_MAP_BUILD, else HEAD with dem/ and core/ committed), runs the parts'
# missing rows (DEM_MAP_PARTS="p1 p2", default all, in the plan's order;
# tests/bench/dem_map.py plan lists them) at nice 19, one LIGGGHTS process
# at a time (DEM_MAP_JOBS=N: a point's seeds N at once), and writes the
# report tests/bench/results/dem_map.md and its plot, dem_map.svg
# (tests/bench/dem_map_plot.py).
# Resumable: rows already in the CSV are skipped, a row's finished seeds
# are kept in dem_map_runs.jsonl. `dem_map.sh inputs` (make
# bench-dem-inputs) runs tests/bench/dem_inputs.py by the same build instead.
set -eu
cd "$(dirname "$0")/../.."
csv=tests/bench/results/dem_map.csv
commit=${DEM_MAP_BUILD:-}
if [ -z "$commit" ] && [ -s "$csv" ]; then
	commit=$(python3 -c 'import csv,sys; r=[x["build"] for x in csv.DictReader(open(sys.argv[1])) if x.get("build")]; print(r[0] if r else "")' "$csv")
fi
if [ -z "$commit" ]; then
	if ! git diff --quiet HEAD -- dem core Makefile; then
		echo "bench-dem-map: commit dem/, core/ and the Makefile first: the map's rows name one build" >&2
		exit 2
	fi
	commit=$(git rev-parse HEAD)
fi
dir=build-demmap/$commit
bin=$dir/src/build/convsim-dem
if [ ! -x "$bin" ]; then
	echo "bench-dem-map: building convsim-dem at $commit into $dir"
	rm -rf "$dir" && mkdir -p "$dir/src"
	git archive "$commit" | tar -x -C "$dir/src"
	nice -n 19 make -C "$dir/src" -j2 BUILD=build build/convsim-dem >"$dir/build.log" 2>&1 ||
		{ tail -20 "$dir/build.log" >&2; exit 1; }
fi
status=0
if [ "${1:-}" = inputs ]; then # make bench-dem-inputs: the map's inputs changed, by its build
	python3 tests/bench/dem_inputs.py run "$bin" "$commit" || status=$?
	python3 tests/bench/dem_inputs.py report > tests/bench/results/dem_inputs.md
	exit $status
fi
python3 tests/bench/dem_map.py run "$bin" "$commit" ${DEM_MAP_PARTS:-} || status=$?
python3 tests/bench/dem_map_report.py > tests/bench/results/dem_map.md
python3 tests/bench/dem_map_plot.py > tests/bench/results/dem_map.svg
exit $status
