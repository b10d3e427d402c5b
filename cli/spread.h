/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * spread.h - a sweep's points spread over MPI ranks: when mpirun (or a
 * batch scheduler's launcher) starts convsim, every rank plans the same
 * study, measures the points k with k % ranks == rank, and rank 0
 * gathers the outcomes into point order and writes the table. In
 * convsim-mpi (built where Open MPI was found) this is spread_mpi.c; in
 * the plain convsim spread_none.c, which is always one rank and hands a
 * launched sweep over to convsim-mpi (handover.h). The core never sees
 * MPI; only the CLI's sweep calls these.
 */
#ifndef CONVSIM_SPREAD_H
#define CONVSIM_SPREAD_H

#include <stddef.h>

typedef struct cli_spread {
	int rank, ranks; /* this process's rank and the count (0 and 1 alone) */
	int mpi;         /* 1 when MPI was initialized here (cli_spread_end ends it) */
} cli_spread;

/* Join the ranks when a launcher started this process (it sets
 * OMPI_COMM_WORLD_SIZE, PMIX_RANK or PMI_RANK); else, or without MPI,
 * rank 0 of 1 and MPI is not touched. Never fails: an MPI that cannot
 * start ends the process with MPI's own message. */
void cli_spread_start(cli_spread *sp);

/* The largest of every rank's rc (every rank calls it: a collective), so
 * that the ranks stop together when one of them met an error before
 * the measuring starts. One rank: rc. */
int cli_spread_agree(const cli_spread *sp, int rc);

/* Rank 0's v on every rank (a collective; alone: v). */
int cli_spread_rank0(const cli_spread *sp, int v);

/* 1 when every rank has the same v (a collective; alone: 1): the ranks
 * check that they were started with the same options. */
int cli_spread_same(const cli_spread *sp, unsigned long long v);

/* 1 when job k of a spread map is this rank's. */
static inline int cli_spread_mine(const cli_spread *sp, size_t k)
{
	return (int)(k % (size_t)sp->ranks) == sp->rank;
}

/* How many of n jobs are this rank's. */
static inline size_t cli_spread_share(const cli_spread *sp, size_t n)
{
	size_t r = (size_t)sp->rank, m = (size_t)sp->ranks;
	return n > r ? (n - r + m - 1) / m : 0;
}

/* Gather into point order: job k (k = 0..n-1, rank k % ranks's) wrote
 * its outcome into items[index[k]] (item_size bytes each) on its rank;
 * on return rank 0's items hold every job's bytes as its rank wrote them
 * (the other ranks' items are unchanged). A collective. 0, or -1 with
 * the reason on stderr (out of memory, more than MPI's int counts);
 * the caller then calls cli_spread_abort. */
int cli_spread_gather(const cli_spread *sp, void *items, size_t item_size, const int *index,
		      size_t n);

/* End every rank with status code after the caller printed why
 * (MPI_Abort: the launcher kills the others); alone, exit(code). */
void cli_spread_abort(const cli_spread *sp, int code);

/* Leave MPI (MPI_Finalize) where cli_spread_start joined it. */
void cli_spread_end(cli_spread *sp);

#endif
