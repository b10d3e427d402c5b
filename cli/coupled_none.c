/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * coupled_none.c - `convsim run --set feed_model=liggghts` in a binary
 * without LIGGGHTS: the plain convsim hands the run to convsim-mpi where
 * that was built with LIGGGHTS (handover.h), which links
 * dem/cli/run_coupled.c instead of this; else it says how to get it.
 */
#include <math.h>
#include <stdio.h>

#include "cli.h"
#include "handover.h"

int cli_run_coupled(const cli_opts *o)
{
	(void)o;
	if (cli_handover_has(CLI_HAS_MPI | CLI_HAS_LIGGGHTS))
		return cli_handover("run", "--set feed_model=liggghts");
	fprintf(stderr, "convsim run: --set feed_model=liggghts: this convsim was built without "
			"LIGGGHTS; `make deps` installs it (Debian libliggghts-dev) and `make` then "
			"builds the coupling (docs/dem.md)\n");
	return 2;
}

void cli_liggghts_here(const cli_opts *o, sim_feed_liggghts *lg)
{
	*lg = (sim_feed_liggghts){
		.available = cli_handover_has(CLI_HAS_MPI | CLI_HAS_LIGGGHTS),
		.unavailable = "this convsim was built without LIGGGHTS (`make deps`, then `make`)",
		.cost = NAN,
		.max_cost = o->max_dem_cost,
		.limit = "--max-dem-cost",
	};
}
