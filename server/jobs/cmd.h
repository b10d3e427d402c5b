/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cmd.h - a command to a session's worker: the changes a PATCH asks for,
 * or the beta of an experiment's segment, applied by the worker between
 * steps (session/worker.h has the queue). Here, below the sessions, so
 * that the experiments, which hand commands over, need not see the worker.
 */
#ifndef CONVSIM_CMD_H
#define CONVSIM_CMD_H

#include "api.h"

typedef struct srv_cmd {
	api_control c;           /* the changes, as PATCH parses them */
	int restart_transport;   /* then restart the transport estimator */
	int from_experiment;     /* sent by the attached experiment */
	int loop_step;           /* a closed loop's per-period beta alone:
				    steered (sim_steer_beta: the transport
				    estimate goes on) and logged without a
				    flush of its own (the experiment sends it
				    again after a restore) */
	int replay;              /* taken again from the control log at a
				    restore: applied, not logged again */
	double cpu_grant;        /* CPU s a "running": true grants a session
				    its CPU budget paused (0: none) */
	/* set by the worker, under the session lock */
	int done;                /* applied (or refused): rc and t_eff hold */
	int rc;                  /* SIM_OK or the core's refusal */
	int overtaken;           /* refused, nothing applied: an until the
				    experiment begun since it was admitted
				    would cut short (session_control.c) */
	double t_eff;            /* s: sim_effective_time() when applied */
	size_t logged;           /* the control log's length with its line
				    (0: not logged): durable before a 200 */
	int waited;              /* a handler waits for it (a PATCH) */
	struct srv_cmd *next;
} srv_cmd;

#endif
