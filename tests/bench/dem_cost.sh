#!/usr/bin/env bash
# SPDX-License-Identifier: GPL-3.0-or-later
# The coupled scene's cost (part of `make bench-dem`, docs/dem.md "Cost"):
# `convsim run --set feed_model=liggghts` over 0.25 s for beds of 1, 4, 16
# and 64 diameters (92 to 5868 grains) on 1 and 2 MPI ranks, one run at a
# time, niced: the DEM's CPU seconds (rank 0) and the wall seconds per
# simulated second of coupling (the bed's building and settling excluded
# from the first, included in the second), into
# tests/bench/results/dem_cost.md.
set -eu
cd "$(dirname "$0")/../.."
BUILD=${BUILD:-build}
out=${DEM_COST_OUT:-tests/bench/results/dem_cost.md}
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 OMPI_MCA_rmaps_base_oversubscribe=1
dur=0.25
{
	echo "\`make bench-dem\` (tests/bench/dem_cost.sh), $(date -u +%Y-%m-%d), $(nproc) cores shared, nice 15:"
	echo "\`mpirun -n RANKS $BUILD/convsim run --set feed_model=liggghts --set layers=DEPTH -d $dur -q\`."
	echo
	echo "| depth (d) | grains | ranks | DEM CPU s per simulated s (rank 0) | wall s per simulated s (with set-up) | v (m/s) |"
	echo "|---|---|---|---|---|---|"
	for depth in 1 4 16 64; do
		for ranks in 1 2; do
			nice -n 15 mpirun -n "$ranks" "$BUILD/convsim" run --set feed_model=liggghts \
				--set layers="$depth" -d "$dur" -q | python3 -c "
import json, sys
r = json.load(sys.stdin)
print('| $depth | %d | %d | %.1f | %.1f | %+.4f |' % (r['grains'], r['mpi_ranks'],
      r['dem_cpu_seconds'] / r['duration'], r['wall_seconds'] / r['duration'], r['transport_velocity']))"
		done
	done
} > "$out"
cat "$out"
