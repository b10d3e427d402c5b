/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * handover.h - the plain convsim links neither MPI nor LIGGGHTS, so that
 * it starts in a few milliseconds; the two commands that need them are
 * handed to convsim-mpi, the same command line built with both, which
 * sits beside it: a sweep started by an MPI launcher (spread.h) and a
 * run with feed_model=liggghts (cli_run_coupled). The hand-over is an
 * exec of that binary with the same arguments: the same process, its
 * launcher's environment, its streams and its exit status
 * (docs/mpi.md "Two binaries").
 */
#ifndef CONVSIM_HANDOVER_H
#define CONVSIM_HANDOVER_H

/* What the build has that convsim-mpi can be handed: bits. */
enum { CLI_HAS_MPI = 1, CLI_HAS_LIGGGHTS = 2 };

/* Keep main's argv (borrowed for the life of the process) for a later
 * hand-over. */
void cli_handover_init(char **argv);

/* 1 when this build has a convsim-mpi with every bit of what (CLI_HAS_*)
 * to hand over to: Open MPI (and LIGGGHTS) found when it was built. */
int cli_handover_has(unsigned what);

/* 1 when a launcher started this process: Open MPI's mpirun
 * (OMPI_COMM_WORLD_SIZE), a PMIx launcher (PMIX_RANK: Open MPI 5,
 * Slurm's srun --mpi=pmix) or a PMI one (PMI_RANK). */
int cli_mpi_launched(void);

/* Replace this process by convsim-mpi (beside this binary) with main's
 * arguments. Returns only when that cannot be done: 1 after
 * "convsim CMD: WHY needs convsim-mpi ...: the reason" on stderr. */
int cli_handover(const char *cmd, const char *why);

#endif
