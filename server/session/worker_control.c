/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker_control.c - the worker's commands phase: queued controls (PATCH,
 * experiment segments) applied in order and acknowledged. Each control is
 * a row of the one PATCH table (api.h API_CONTROLS: member, bit; parse
 * and echo in api/control.c); its apply column is here, by the same id.
 */
#include <math.h>

#include "experiment.h"
#include "session_int.h"

/* ---- the attached experiment (its command queue: worker_queue.c) ---------- */

/* The experiment's command was applied or refused (lock held). */
static void experiment_commanded(srv_session *s, const srv_cmd *cmd)
{
	if (cmd != s->exp_cmd)
		return;
	s->exp_cmd = NULL;
	if (srv_exp_commanded(s->exp, cmd))
		srv_worker_detach_exp(s, NULL);
}

/* The budget part of a control, after its state change
 * (srv_state_after): a CPU grant from now, and the budget's pause flag
 * cleared once the session runs or is paused or resumed by hand (lock
 * held). */
static void apply_budget(srv_session *s, const srv_cmd *cmd)
{
	const api_control *c = &cmd->c;
	if (c->set & API_C_CPU)
		s->budget.cpu_limit = s->budget.cpu_seconds + c->cpu_budget;
	else if ((c->set & API_C_RUNNING) && c->running && s->budget.cpu_paused &&
		 cmd->cpu_grant > 0)
		s->budget.cpu_limit = s->budget.cpu_seconds + cmd->cpu_grant;
	if (s->state != SRV_PAUSED || (c->set & API_C_RUNNING))
		s->budget.cpu_paused = 0;
}

/* Append cmd's line to the control log: an experiment's names it (lock
 * held). The log's length with it. */
static size_t log_control(srv_session *s, const srv_cmd *cmd, double t_eff)
{
	char line[API_EVENT_MAX];
	api_control_log_line(line, sizeof line, &cmd->c, t_eff,
			     cmd->from_experiment && s->exp ? srv_exp_id(s->exp) : NULL);
	return srv_control_log_append(s, line, cmd->waited ? SRV_LINE_WAITED
					       : cmd->loop_step ? SRV_LINE_LATER : SRV_LINE_FLUSH);
}

/* ---- the PATCH controls' apply column (api.h API_CONTROLS, by id) ---------- */

/* Apply one control of cmd to the session (lock held): a SIM_* code;
 * *reanchor set when pacing must restart. */
typedef int (*control_apply)(srv_session *s, const srv_cmd *cmd, int *reanchor);

/* beta and beta_rate: SI from api/; a rate alone keeps the target. */
static int apply_beta(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	const api_control *c = &cmd->c;
	(void)reanchor;
	double target = (c->set & API_C_BETA) ? c->beta.si : s->st.beta_target;
	double rate = (c->set & API_C_BETA_RATE) ? c->beta_rate.si : 0;
	return (cmd->loop_step ? sim_steer_beta : sim_set_beta)(s->sim, target, rate);
}

static int apply_rotation(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)reanchor;
	return sim_set_rotation(s->sim, cmd->c.rotation);
}

static int apply_omega_ss(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)reanchor;
	return sim_set_omega_ss(s->sim, cmd->c.omega_ss);
}

/* The column feed's disturbances (sim_set_feed; NaN keeps the other). */
static int apply_m_n(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)reanchor;
	return sim_set_feed(s->sim, cmd->c.m_n, NAN);
}

static int apply_mu(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)reanchor;
	return sim_set_feed(s->sim, NAN, cmd->c.mu);
}

static int apply_motor(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)reanchor;
	return sim_set_drive_on(s->sim, cmd->c.motor_on);
}

static int apply_pace(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	s->pace = cmd->c.pace;
	*reanchor = 1;
	return SIM_OK;
}

static int apply_until(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)reanchor;
	s->until = cmd->c.until;
	return SIM_OK;
}

/* A row whose change is the session's state or budget, applied once all
 * of the command's other rows are (srv_state_after, apply_budget). */
static int apply_later(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	(void)s;
	(void)cmd;
	(void)reanchor;
	return SIM_OK;
}

/* In the table's order; beta_rate is applied with beta (one ramp). */
static const control_apply control_applies[API_CTL_COUNT] = {
	[API_CTL_BETA] = apply_beta,
	[API_CTL_BETA_RATE] = apply_later, /* with beta */
	[API_CTL_ROTATION] = apply_rotation,
	[API_CTL_OMEGA_SS] = apply_omega_ss,
	[API_CTL_M_N] = apply_m_n,
	[API_CTL_MU] = apply_mu,
	[API_CTL_RUNNING] = apply_later,
	[API_CTL_MOTOR] = apply_motor,
	[API_CTL_PACE] = apply_pace,
	[API_CTL_UNTIL] = apply_until,
	[API_CTL_CPU] = apply_later,
};

/* The changes to the machine that restart the transport estimate of a
 * LIGGGHTS bed, as the core's restarts. */
#define DEM_RESTARTS (API_C_BETA | API_C_ROTATION | API_C_OMEGA_SS | API_C_MOTOR)

#define CONTROL_BIT(id, member, bit, fn) [API_CTL_##id] = bit,
static const unsigned control_bits[API_CTL_COUNT] = {API_CONTROLS(CONTROL_BIT)};
#undef CONTROL_BIT

/* Apply one command: its controls row by row until one fails, then
 * (all applied) the transport restarts, the state and the budget (lock
 * held). A SIM_* code. */
static int apply_command(srv_session *s, const srv_cmd *cmd, int *reanchor)
{
	const api_control *c = &cmd->c;
	int rc = SIM_OK;
	for (size_t i = 0; i < API_CTL_COUNT && rc == SIM_OK; i++)
		if ((c->set & control_bits[i]) ||
		    (i == API_CTL_BETA && (c->set & API_C_BETA_RATE)))
			rc = control_applies[i](s, cmd, reanchor);
	if (rc != SIM_OK)
		return rc;
	if (cmd->restart_transport)
		sim_restart_transport(s->sim);
	if (s->dem.link && (cmd->restart_transport || (c->set & DEM_RESTARTS)))
		s->dem.restart = 1;
	/* pacing restarts on running and on a resume from a pause (not on a
	 * finished session resumed by until: it restarts its clocks when it
	 * wakes, idle) */
	int was = s->state;
	s->state = srv_state_after(was, s->budget.cpu_paused, s->st.t, c);
	*reanchor |= (c->set & API_C_RUNNING) || (was == SRV_PAUSED && s->state != was);
	apply_budget(s, cmd);
	return SIM_OK;
}

int srv_worker_apply_commands(srv_session *s)
{
	int reanchor = 0;
	srv_cmd *cmd;
	while ((cmd = s->cmd_head)) {
		s->cmd_head = cmd->next;
		if (!s->cmd_head)
			s->cmd_tail = NULL;
		double t_eff = sim_effective_time(s->sim);
		/* an until admitted while the experiment attached since was
		 * still waiting, now begun, that it would cut short: refused
		 * whole, as admission refuses it */
		cmd->overtaken = !cmd->from_experiment && !cmd->replay &&
				 (cmd->c.set & API_C_UNTIL) &&
				 srv_until_cuts_experiment(s, cmd->c.until);
		int rc = cmd->overtaken ? SIM_EPARAM : apply_command(s, cmd, &reanchor);
		if (s->pace == API_PACE_MAX && s->until == 0) {
			/* an end for pace "max" (api.h): part of what this
			 * control did, so its answer, event and log line say it */
			s->until = s->st.t + API_DEFAULT_MAX_UNTIL;
			cmd->c.until = s->until;
			cmd->c.set |= API_C_UNTIL;
		}
		if (rc == SIM_OK) {
			/* the control log keeps the control (log_control); the
			 * stream's event also carries the scene's model error
			 * after it */
			char ring[API_EVENT_MAX];
			sim_model_error me;
			sim_get_status(s->sim, &s->st);
			api_model_check(&s->spec, &s->st, &me);
			api_control_event_model(ring, sizeof ring, &cmd->c, t_eff, &me);
			srv_ring_event(s, "control", ring);
			if (cmd->from_experiment && s->restore.exp_relogged > 0)
				s->restore.exp_relogged--; /* in the log since before the restore */
			else if (!cmd->replay)
				cmd->logged = log_control(s, cmd, t_eff);
			s->persist.ckpt_dirty = 1;
		}
		cmd->rc = rc;
		cmd->t_eff = t_eff;
		cmd->done = 1;
		if (cmd->from_experiment)
			experiment_commanded(s, cmd);
	}
	/* the status shows the accepted targets at once: no step publishes
	 * one while paused or finished, nor before the answer when running */
	sim_get_status(s->sim, &s->st);
	pthread_cond_broadcast(&s->data);
	return reanchor;
}

