/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker.h - a session's worker thread and its command queue.
 *
 * The worker is the only thread that touches a session's sim instance.
 * Every change to a running simulation is a command on the session's
 * queue, applied by the worker between steps: a PATCH from a handler
 * (which waits for the acknowledgement) and the beta of each experiment
 * segment (which the experiment hands to the worker and nobody waits on).
 * The loop itself is described in worker.c.
 */
#ifndef CONVSIM_WORKER_H
#define CONVSIM_WORKER_H

#include "api.h"

typedef struct srv_session srv_session;

typedef struct srv_cmd {
	api_control c;           /* the changes, as PATCH parses them */
	int restart_transport;   /* then restart the transport estimator */
	int from_experiment;     /* sent by the attached experiment */
	int replay;              /* taken again from the control log at a
				    restore: applied, not logged again */
	double cpu_grant;        /* CPU s a "running": true grants a session
				    its CPU budget paused (0: none) */
	/* set by the worker, under the session lock */
	int done;                /* applied (or refused): rc and t_eff hold */
	int rc;                  /* SIM_OK or the core's refusal */
	double t_eff;            /* s: sim_effective_time() when applied */
	size_t logged;           /* the control log's length with its line
				    (0: not logged): durable before a 200 */
	int waited;              /* a handler waits for it (a PATCH) */
	struct srv_cmd *next;
} srv_cmd;

/* Append cmd (borrowed until done or taken back) to s's queue and wake the
 * worker. Session lock held. */
void srv_worker_queue(srv_session *s, srv_cmd *cmd);
/* Take cmd back if it is still queued (session lock held); returns 1 if
 * it was, 0 if the worker has taken it. */
int srv_worker_unqueue(srv_session *s, srv_cmd *cmd);
/* The worker thread's body; arg is the srv_session. Returns when the
 * session's stop flag is set. */
void *srv_worker_main(void *arg);

/* worker_queue.c, for the worker's phases (session lock held): queue the
 * experiment's command, if it handed one over (the one still queued is
 * taken back); let go of the experiment, aborting it with why unless why
 * is NULL, its command taken back if still queued. */
void srv_worker_queue_exp_command(srv_session *s, srv_cmd *cmd);
void srv_worker_detach_exp(srv_session *s, const char *why);

#endif
