/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker_int.h - what the worker's phases share across its files: the
 * wall-clock anchors of pacing and metering, and the phases of the CPU
 * budget (worker_budget.c) that the loop in worker.c calls, and the clocks'
 * functions (worker_clock.c). Session lock
 * held in all of them.
 */
#ifndef CONVSIM_WORKER_INT_H
#define CONVSIM_WORKER_INT_H

#include "session_int.h"

/* Wall-clock anchors of pacing and metering. */
typedef struct clocks {
	double anchor_wall, anchor_t; /* pacing: wall time at simulated t */
	double rate_wall, rate_t;     /* metering window start */
	uint64_t rate_steps;
	double cpu_wall;              /* when the CPU clock was last read */
	double stepped_wall;          /* srv_now() after the last step, until
					 the cpu phase takes it (NAN) */
	double publish_wall;          /* when readers were last woken */
	double batch_start;           /* pacing: when the last batch began */
	double batch_end;             /* pacing: samples due by then step now */
	int batch_steps;              /* pacing: steps since the batch began */
	int want_all;                 /* pacing: a stream waited for every
					 sample at the last wake-up */
	double cost_cpu, cost_t;      /* CPU s and simulated t at the start of
					 the cost window */
	int cost_windows;             /* cost windows measured since the
					 worker started */
} clocks;

/* Restart pacing and metering from now (after a pause or a pace change). */
void srv_worker_restart_clocks(clocks *c, const srv_session *s);
/* Wake the readers if a record one of them waits for was pushed
 * (publish_wakes says whether to, and marks the records published);
 * publish_batch wakes them with the lock let go, at the end of a paced
 * batch. */
int srv_worker_publish_wakes(srv_session *s, clocks *c);
void srv_worker_publish(srv_session *s, clocks *c);
void srv_worker_publish_batch(srv_session *s, clocks *c);

/* need: the session's hold on the paced cores follows what it needs now. */
void srv_worker_commit_need(srv_session *s, clocks *c);
/* the worker's CPU time (and a LIGGGHTS bed's) into cpu_seconds, now */
void srv_worker_read_cpu(srv_session *s);
/* cpu: read the worker's CPU time; a running session that spent its
 * grant pauses. */
void srv_worker_check_cpu(srv_session *s, clocks *c);
/* turn: a running pace "max" session steps only while it holds a CPU
 * slot; 1 if it must wait. */
int srv_worker_take_turn(srv_session *s, clocks *c);

#endif
