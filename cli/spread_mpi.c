/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * spread_mpi.c - spread.h on MPI, in convsim-mpi (built where Open MPI
 * is found; the plain convsim hands a launched sweep over to it):
 * the ranks of MPI_COMM_WORLD when a launcher started convsim, one
 * agreement (MPI_Allreduce of the largest status) before the measuring,
 * one MPI_Gatherv of the outcomes' bytes to rank 0 after it, unpacked
 * into point order there. Only the main thread calls MPI (the points'
 * threads never do): MPI_THREAD_FUNNELED. Every rank runs the same
 * binary, so an outcome travels as its bytes (MPI_BYTE) and arrives bit
 * for bit.
 */
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <mpi.h>

#include "handover.h"
#include "spread.h"

void cli_spread_start(cli_spread *sp)
{
	int on = 0, provided;
	sp->rank = 0;
	sp->ranks = 1;
	sp->mpi = 0;
	if (!cli_mpi_launched())
		return;
	MPI_Initialized(&on);
	if (!on) {
		MPI_Init_thread(NULL, NULL, MPI_THREAD_FUNNELED, &provided);
		sp->mpi = 1;
	}
	MPI_Comm_rank(MPI_COMM_WORLD, &sp->rank);
	MPI_Comm_size(MPI_COMM_WORLD, &sp->ranks);
}

int cli_spread_agree(const cli_spread *sp, int rc)
{
	int all = rc;
	if (sp->ranks > 1)
		MPI_Allreduce(&rc, &all, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
	return all;
}

int cli_spread_rank0(const cli_spread *sp, int v)
{
	if (sp->ranks > 1)
		MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
	return v;
}

int cli_spread_same(const cli_spread *sp, unsigned long long v)
{
	unsigned long long lo = v, hi = v;
	if (sp->ranks > 1) {
		MPI_Allreduce(&v, &lo, 1, MPI_UNSIGNED_LONG_LONG, MPI_MIN, MPI_COMM_WORLD);
		MPI_Allreduce(&v, &hi, 1, MPI_UNSIGNED_LONG_LONG, MPI_MAX, MPI_COMM_WORLD);
	}
	return lo == hi;
}

/* Rank q's share of the jobs (k = q, q + ranks, ...). */
static size_t share_of(int q, int ranks, size_t n)
{
	cli_spread s = {.rank = q, .ranks = ranks};
	return cli_spread_share(&s, n);
}

int cli_spread_gather(const cli_spread *sp, void *items, size_t item_size, const int *index,
		      size_t n)
{
	if (sp->ranks == 1)
		return 0;
	if (n > (size_t)INT_MAX / (item_size ? item_size : 1)) {
		fprintf(stderr, "convsim sweep: rank %d: %zu points of %zu bytes are more than one "
				"MPI message carries\n",
			sp->rank, n, item_size);
		return -1;
	}
	char *all = items;
	size_t mine = cli_spread_share(sp, n);
	char *send = malloc(mine ? mine * item_size : 1);
	char *recv = sp->rank == 0 ? malloc(n ? n * item_size : 1) : NULL;
	int *counts = sp->rank == 0 ? calloc((size_t)sp->ranks, sizeof(int)) : NULL;
	int *displs = sp->rank == 0 ? calloc((size_t)sp->ranks, sizeof(int)) : NULL;
	if (!send || (sp->rank == 0 && (!recv || !counts || !displs))) {
		fprintf(stderr, "convsim sweep: rank %d: out of memory gathering the points\n",
			sp->rank);
		free(send), free(recv), free(counts), free(displs);
		return -1;
	}
	for (size_t j = 0; j < mine; j++) {
		size_t k = (size_t)sp->rank + j * (size_t)sp->ranks;
		memcpy(send + j * item_size, all + (size_t)index[k] * item_size, item_size);
	}
	if (sp->rank == 0)
		for (int q = 0, at = 0; q < sp->ranks; q++) {
			counts[q] = (int)(share_of(q, sp->ranks, n) * item_size);
			displs[q] = at;
			at += counts[q];
		}
	MPI_Gatherv(send, (int)(mine * item_size), MPI_BYTE, recv, counts, displs, MPI_BYTE, 0,
		    MPI_COMM_WORLD);
	if (sp->rank == 0) /* rank q's j-th outcome is job q + j ranks */
		for (int q = 0; q < sp->ranks; q++)
			for (size_t j = 0; j < share_of(q, sp->ranks, n); j++) {
				size_t k = (size_t)q + j * (size_t)sp->ranks;
				memcpy(all + (size_t)index[k] * item_size,
				       recv + (size_t)displs[q] + j * item_size, item_size);
			}
	free(send), free(recv), free(counts), free(displs);
	return 0;
}

void cli_spread_abort(const cli_spread *sp, int code)
{
	fflush(stdout);
	fflush(stderr);
	if (sp->ranks > 1)
		MPI_Abort(MPI_COMM_WORLD, code);
	if (sp->mpi)
		MPI_Finalize();
	exit(code);
}

void cli_spread_end(cli_spread *sp)
{
	if (sp->mpi)
		MPI_Finalize();
	sp->mpi = 0;
}
