/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker_queue.c - a session's command queue: controls (PATCH, experiment
 * segments) wait there for the worker's commands phase (worker.c), which
 * applies them in order between steps. The attached experiment has at
 * most one command in it at a time, taken back when it is let go.
 * Everything here runs with the session lock held; worker.c and the
 * handlers call it, and it calls nothing of worker.c.
 */
#include "experiment.h"
#include "session_int.h"

/* ---- the command queue ------------------------------------------------------ */

void srv_worker_queue(srv_session *s, srv_cmd *cmd)
{
	cmd->next = NULL;
	if (s->cmd_tail)
		s->cmd_tail->next = cmd;
	else
		s->cmd_head = cmd;
	s->cmd_tail = cmd;
	pthread_cond_broadcast(&s->wake);
}

int srv_worker_unqueue(srv_session *s, srv_cmd *cmd)
{
	srv_cmd **pp = &s->cmd_head, *prev = NULL;
	while (*pp && *pp != cmd) {
		prev = *pp;
		pp = &(*pp)->next;
	}
	if (!*pp)
		return 0;
	*pp = cmd->next;
	if (s->cmd_tail == cmd)
		s->cmd_tail = prev;
	return 1;
}

/* ---- the attached experiment ---------------------------------------------- */

/* Queue the experiment's command, if it handed one over (lock held). */
void srv_worker_queue_exp_command(srv_session *s, srv_cmd *cmd)
{
	if (!cmd)
		return;
	if (s->exp_cmd)
		srv_worker_unqueue(s, s->exp_cmd);
	s->exp_cmd = cmd;
	srv_worker_queue(s, cmd);
}

/* Let go of the experiment, aborting it with why unless why is NULL; its
 * command is taken back if still queued (lock held). */
void srv_worker_detach_exp(srv_session *s, const char *why)
{
	if (!s->exp)
		return;
	if (s->exp_cmd)
		srv_worker_unqueue(s, s->exp_cmd);
	s->exp_cmd = NULL;
	if (why)
		srv_exp_abort(s->exp, why);
	s->exp = NULL;
	s->exp_started = 0;
}
