/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * feed.h - a LIGGGHTS bed as the coupling (couple.c) sees it: advanced
 * over one coupling interval under the deck's mean acceleration, its
 * state read back. Two implementations, one descriptor each:
 *
 *   local   the bed in this process (bed.c, LIGGGHTS linked in): the CLI's
 *           `convsim run --set feed_model=liggghts` (feed_local.c)
 *   remote  the bed in a child process, `convsim-bed` (dem/cli/
 *           convsim_bed.c), spoken to over two pipes (bed_proto.h): the
 *           daemon, which must not run LIGGGHTS in its own process
 *           (LIGGGHTS ends the process on a command it refuses and is not
 *           known to be thread-safe) (feed_remote.c, built without
 *           LIGGGHTS or MPI)
 *
 * Both carry out the same LIGGGHTS commands in the same order (bed.c), so
 * a bed gives the same numbers in either, bit for bit: the remote's
 * numbers cross the pipe as exact hexadecimal floating point.
 */
#ifndef CONVSIM_DEM_FEED_H
#define CONVSIM_DEM_FEED_H

#include <stddef.h>

#include "dem.h"

typedef struct dem_feed dem_feed;

typedef struct dem_feed_ops {
	const char *name; /* "local", "remote" */
	/* Advance by interval s under the deck's acceleration (ax, ay)
	 * (m/s^2), held; f->state and f->cpu follow. 0, or -1 with msg. */
	int (*advance)(dem_feed *f, double ax, double ay, double interval, char *msg,
		       size_t msglen);
	/* Close the bed (for remote: end and reap the child). NULL accepted
	 * by dem_feed_free. */
	void (*free)(dem_feed *f);
} dem_feed_ops;

struct dem_feed {
	const struct dem_feed_ops *ops;
	dem_bed_state state; /* the bed now, deck frame */
	int grains;
	double cpu;          /* CPU s the bed has used: this process's DEM time
				(local) or the child's whole CPU time (remote) */
};

/* The bed of spec in this process (needs LIGGGHTS: feed_local.c). comm:
 * NULL or an MPI_Comm * (as dem_bed_new). NULL with msg on error. */
dem_feed *dem_feed_local(const dem_bed_spec *spec, const void *comm, char *msg, size_t msglen);
/* The bed of spec in a child process running `bed_path --serve --nice
 * nice_value`, or with ranks > 1 `mpirun -n ranks bed_path ...` (LIGGGHTS
 * splits the bed over the ranks) (no LIGGGHTS here: feed_remote.c). The
 * child leads a process group of its own, which a kill ends whole. Waits
 * for the bed to settle. An answer (the settled bed, an interval's state)
 * that takes longer than timeout s (0: no limit) ends the child as hung
 * and fails the request. watch_fd: -1, or a socket (the creating client's)
 * whose peer's leaving while the bed settles ends the child and fails the
 * request, so that an abandoned create holds nothing. NULL with msg on
 * error (the program missing, the child refusing, ending or hanging, the
 * client gone); *left (NULL: not asked) then says which: 1 when the
 * watched socket's peer left, 0 for every other error. */
dem_feed *dem_feed_remote(const char *bed_path, const dem_bed_spec *spec, int nice_value,
			  int ranks, double timeout, int watch_fd, int *left, char *msg,
			  size_t msglen);
/* The child's process id (remote; 0 for local, NULL, or once it ended
 * and was reaped). */
long dem_feed_pid(const dem_feed *f);
/* Remote: end the child and its process group now (SIGKILL: mpirun's
 * ranks too) if it still runs; from any thread,
 * while another may be in an advance, which then fails. Local, NULL:
 * nothing. */
void dem_feed_kill(const dem_feed *f);

/* Advance (the descriptor's), and free; NULL accepted. */
int dem_feed_advance(dem_feed *f, double ax, double ay, double interval, char *msg,
		     size_t msglen);
void dem_feed_free(dem_feed *f);

#endif
