/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker.h - a session's worker thread and its command queue.
 *
 * The worker is the only thread that touches a session's sim instance.
 * Every change to a running simulation is a command on the session's
 * queue, applied by the worker between steps: a PATCH from a handler
 * (which waits for the acknowledgement) and the beta of each experiment
 * segment (which the experiment hands to the worker and nobody waits on).
 * The loop itself is described in worker.c; the command, srv_cmd, is in
 * jobs/cmd.h (the experiments hand it over too).
 */
#ifndef CONVSIM_WORKER_H
#define CONVSIM_WORKER_H

#include "api.h"
#include "cmd.h"

typedef struct srv_session srv_session;

/* Append cmd (borrowed until done or taken back) to s's queue and wake the
 * worker. Session lock held. */
void srv_worker_queue(srv_session *s, srv_cmd *cmd);
/* Take cmd back if it is still queued (session lock held); returns 1 if
 * it was, 0 if the worker has taken it. */
int srv_worker_unqueue(srv_session *s, srv_cmd *cmd);
/* The worker thread's body; arg is the srv_session. Returns when the
 * session's stop flag is set. */
void *srv_worker_main(void *arg);
/* The worker's commands phase (worker_control.c): apply the queued
 * controls in order and acknowledge each (lock held). 1 if pacing must
 * restart. */
int srv_worker_apply_commands(srv_session *s);

/* worker_queue.c, for the worker's phases (session lock held): queue the
 * experiment's command, if it handed one over (the one still queued is
 * taken back); let go of the experiment, aborting it with why unless why
 * is NULL, its command taken back if still queued. */
void srv_worker_queue_exp_command(srv_session *s, srv_cmd *cmd);
void srv_worker_detach_exp(srv_session *s, const char *why);

#endif
