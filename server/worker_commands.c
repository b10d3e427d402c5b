/*
 * worker_commands.c - a session's command queue and the worker's commands
 * phase: queued controls (PATCH, experiment segments) applied in order
 * between steps and acknowledged with sim_effective_time(), each appended
 * to the session's control log; and the attached experiment's commands
 * queued, acknowledged and let go. Everything here runs with the session
 * lock held; worker.c calls it, and it calls nothing of worker.c.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

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

/* The experiment's command was applied or refused (lock held). */
static void experiment_commanded(srv_session *s, const srv_cmd *cmd)
{
	if (cmd != s->exp_cmd)
		return;
	s->exp_cmd = NULL;
	if (srv_exp_commanded(s->exp, cmd))
		srv_worker_detach_exp(s, NULL);
}

/* Let the session run at least up to t_end (s): raise until, resume a
 * finished session (lock held). */
void srv_worker_extend_until(srv_session *s, double t_end)
{
	if (s->until > 0 && s->until < t_end)
		s->until = t_end;
	if (s->state == SRV_FINISHED && s->st.t < t_end)
		s->state = SRV_RUNNING;
}

/* The budget part of a control, after its state change
 * (srv_state_after): a CPU grant from now, and the budget's pause flag
 * cleared once the session runs or is paused or resumed by hand (lock
 * held). */
static void apply_budget(srv_session *s, const srv_cmd *cmd)
{
	const api_control *c = &cmd->c;
	if (c->set & API_C_CPU)
		s->cpu_limit = s->cpu_seconds + c->cpu_budget;
	else if ((c->set & API_C_RUNNING) && c->running && s->cpu_paused &&
		 cmd->cpu_grant > 0)
		s->cpu_limit = s->cpu_seconds + cmd->cpu_grant;
	if (s->state != SRV_PAUSED || (c->set & API_C_RUNNING))
		s->cpu_paused = 0;
}

/* Apply queued controls in order and acknowledge each (lock held).
 * Returns 1 if pacing must restart. */
int srv_worker_apply_commands(srv_session *s)
{
	int reanchor = 0;
	srv_cmd *cmd;
	while ((cmd = s->cmd_head)) {
		s->cmd_head = cmd->next;
		if (!s->cmd_head)
			s->cmd_tail = NULL;
		const api_control *c = &cmd->c;
		double t_eff = sim_effective_time(s->sim);
		int rc = SIM_OK;
		if (c->set & (API_C_BETA | API_C_BETA_RATE)) {
			/* SI from api/; a rate alone keeps the target */
			double target = (c->set & API_C_BETA) ? c->beta.si
							      : s->st.beta_target;
			double rate =
				(c->set & API_C_BETA_RATE) ? c->beta_rate.si : 0;
			rc = sim_set_beta(s->sim, target, rate);
		}
		if (rc == SIM_OK && (c->set & API_C_ROTATION))
			rc = sim_set_rotation(s->sim, c->rotation);
		if (rc == SIM_OK && (c->set & API_C_OMEGA_SS))
			rc = sim_set_omega_ss(s->sim, c->omega_ss);
		if (rc == SIM_OK && (c->set & API_C_MOTOR))
			rc = sim_set_drive_on(s->sim, c->motor_on);
		if (rc == SIM_OK && cmd->restart_transport)
			sim_restart_transport(s->sim);
		if (rc == SIM_OK && (c->set & API_C_PACE)) {
			s->pace = c->pace;
			reanchor = 1;
		}
		if (rc == SIM_OK && (c->set & API_C_UNTIL))
			s->until = c->until;
		if (rc == SIM_OK) {
			/* pacing restarts on running and on a resume from a
			 * pause (not on a finished session resumed by until:
			 * it restarts its clocks when it wakes, idle) */
			int was = s->state;
			s->state = srv_state_after(was, s->cpu_paused, s->st.t, c);
			reanchor |= (c->set & API_C_RUNNING) ||
				    (was == SRV_PAUSED && s->state != was);
			apply_budget(s, cmd);
		}
		if (s->pace == API_PACE_MAX && s->until == 0)
			s->until = s->st.t + API_DEFAULT_MAX_UNTIL;
		if (rc == SIM_OK) {
			char json[API_EVENT_MAX];
			api_control_event(json, sizeof json, c, t_eff);
			srv_ring_event(s, "control", json);
			srv_persist_control(s, json);
			s->ckpt_dirty = 1;
		}
		cmd->rc = rc;
		cmd->t_eff = t_eff;
		cmd->done = 1;
		if (cmd->from_experiment)
			experiment_commanded(s, cmd);
	}
	pthread_cond_broadcast(&s->data);
	return reanchor;
}
