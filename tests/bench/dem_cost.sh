#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The coupled scene's cost (part of `make bench-dem`, docs/dem.md "Cost"):
# `convsim run --set feed_model=liggghts` over 0.25 s for beds of 1, 4, 16
# and 64 diameters (92 to 5867 grains) and over 0.1 s for 10,000 grains
# (CONVSIM_DEM_GRAINS: past the 64 layers a scene holds), on 1 and 2 MPI
# ranks, one run at a time, niced: the DEM's CPU seconds (rank 0) and the
# wall seconds per simulated second of coupling (the bed's building and
# settling excluded from the first, included in the second), into
# tests/bench/results/dem_cost.md.
set -eu
cd "$(dirname "$0")/../.."
. tests/bench/provenance.sh
prov=$(provenance)
BUILD=${BUILD:-build}
out=${DEM_COST_OUT:-tests/bench/results/dem_cost.md}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
row() { # depth, grains ("" for depth's), duration
	local depth=$1 grains=$2 dur=$3 ranks
	for ranks in 1 2; do
		CONVSIM_DEM_GRAINS=$grains nice -n 15 mpirun -n "$ranks" -x CONVSIM_DEM_GRAINS "$BUILD/convsim" run \
			--set feed_model=liggghts --set layers="$depth" -d "$dur" -q | python3 -c "
import json, sys
r = json.load(sys.stdin)
print('| $depth | %d | %d | $dur | %.1f | %.1f | %+.4f |' % (r['grains'], r['mpi_ranks'],
      r['dem_cpu_seconds'] / r['duration'], r['wall_seconds'] / r['duration'], r['transport_velocity']))"
	done
}
{
	echo "$prov"
	echo "\`make bench-dem\` (tests/bench/dem_cost.sh), $(date -u +%Y-%m-%d), $(nproc) cores shared, nice 15:"
	echo "\`[CONVSIM_DEM_GRAINS=N] mpirun -n RANKS $BUILD/convsim run --set feed_model=liggghts --set layers=DEPTH -d S -q\`."
	echo
	echo "| depth (d) | grains | ranks | simulated s | DEM CPU s per simulated s (rank 0) | wall s per simulated s (with set-up) | v (m/s) |"
	echo "|---|---|---|---|---|---|---|"
	for depth in 1 4 16 64; do
		row "$depth" "" 0.25
	done
	row 64 10000 0.1
} > "$out"
cat "$out"
