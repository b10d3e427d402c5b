/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * spread_none.c - spread.h in the plain convsim, which links no MPI:
 * always rank 0 of 1, so a sweep measures every point itself. Started by
 * an MPI launcher where Open MPI was found at build time, it hands the
 * sweep to convsim-mpi (handover.h), which links spread_mpi.c; built
 * without MPI (`make NO_MPI=1`) it runs the whole study on every rank.
 */
#include <stdlib.h>

#include "handover.h"
#include "spread.h"

void cli_spread_start(cli_spread *sp)
{
	if (cli_mpi_launched() && cli_handover_has(CLI_HAS_MPI))
		exit(cli_handover("sweep", "a sweep started by an MPI launcher"));
	sp->rank = 0;
	sp->ranks = 1;
	sp->mpi = 0;
}

int cli_spread_agree(const cli_spread *sp, int rc)
{
	(void)sp;
	return rc;
}

int cli_spread_rank0(const cli_spread *sp, int v)
{
	(void)sp;
	return v;
}

int cli_spread_same(const cli_spread *sp, unsigned long long v)
{
	(void)sp, (void)v;
	return 1;
}

int cli_spread_gather(const cli_spread *sp, void *items, size_t item_size, const int *index,
		      size_t n)
{
	(void)sp, (void)items, (void)item_size, (void)index, (void)n;
	return 0;
}

void cli_spread_abort(const cli_spread *sp, int code)
{
	(void)sp;
	exit(code);
}

void cli_spread_end(cli_spread *sp)
{
	(void)sp;
}
