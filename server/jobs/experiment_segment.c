/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_segment.c - one segment of a beta-schedule experiment: its
 * start (the command the worker applies: the segment's beta, then a
 * restart of the transport estimator) and its measurements at its end: the
 * mean velocity from the restarted estimator, the steady velocity as the
 * mean feed velocity over the segment's second half, and the reversal time
 * from the command until the feed velocity first reaches 90 % of that
 * steady value, before that second half begins (else none: the segment
 * was too short for the feed to settle). The worker's answer to a
 * segment's command is read here (its t_command, the end of the one
 * before, or why it was refused), and a segment not done when its
 * experiment ends early ends with it (aborted).
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment_int.h"

srv_cmd *srv_exp_start_segment(srv_experiment *e, int i, const sim_status *st)
{
	api_segment *seg = &e->req.seg[i];
	srv_cmd *cmd = &e->cmd;
	memset(cmd, 0, sizeof *cmd);
	cmd->c.set = API_C_BETA;
	cmd->c.beta = seg->beta;
	if (e->req.beta_rate.si > 0) {
		cmd->c.set |= API_C_BETA_RATE;
		cmd->c.beta_rate = e->req.beta_rate;
	}
	if (e->ext.kind == API_EXP_CONTROL) {
		/* the new setpoint's feedforward with the integral carried over */
		api_exp_ext *x = &e->ext;
		double b = seg->beta.si + x->branch_sign * x->integ * (M_PI / 180);
		b = b < x->beta_lo ? x->beta_lo : b > x->beta_hi ? x->beta_hi : b;
		cmd->c.beta = (api_value){b, b * 180 / M_PI};
	}
	e->beta_sent = cmd->c.beta.si;
	e->cmd_starts = 1;
	e->dist_from = e->dist_to = 0;
	cmd->restart_transport = 1;
	cmd->from_experiment = 1;
	seg->start_velocity = st->feed_velocity;
	/* a segment that commands the beta already set (and reached) changes
	 * nothing there is to time */
	seg->beta_same = seg->beta.si == st->beta_target && st->beta == st->beta_target;
	seg->state = API_SEG_RUNNING;
	e->cur = i;
	e->seg_first = e->rec_n;
	return cmd;
}

void srv_exp_finish_segment(srv_experiment *e, const sim_status *st)
{
	api_segment *seg = &e->req.seg[e->cur];
	seg->t_end = st->t;
	/* the estimator restarted at the segment's command */
	seg->mean_velocity = st->transport_velocity;
	seg->uncertainty = st->transport_velocity_uncertainty;
	seg->steady = st->steady;
	double half = seg->t_command + 0.5 * (seg->t_end - seg->t_command);
	double sum = 0;
	size_t n = 0;
	for (size_t i = e->seg_first; i < e->rec_n; i++)
		if (e->rec_t[i] >= half) {
			sum += e->rec_v[i];
			n++;
		}
	double steady = n ? sum / (double)n : NAN;
	seg->steady_velocity = steady;
	seg->reversal_time = NAN;
	if (isfinite(steady) && steady != 0 && !seg->beta_same)
		for (size_t i = e->seg_first; i < e->rec_n; i++) {
			double v = e->rec_v[i];
			if (e->rec_t[i] >= seg->t_command &&
			    (steady > 0 ? v >= 0.9 * steady
					: v <= 0.9 * steady)) {
				/* reached only inside the half it is averaged
				 * over: the segment ended before the feed
				 * settled, there is no reversal time to tell */
				if (e->rec_t[i] < half)
					seg->reversal_time = e->rec_t[i] - seg->t_command;
				break;
			}
		}
	seg->state = API_SEG_DONE;
	srv_exp_control_results(e);
	srv_exp_identify_results(e);
}

double srv_exp_segment_end(const srv_experiment *e)
{
	return e->state == EXP_RUNNING ? e->t0 + e->req.seg[e->cur].until : INFINITY;
}

double srv_exp_boundary(const srv_experiment *e)
{
	return fmin(srv_exp_segment_end(e), srv_exp_control_boundary(e));
}

/* ---- a new start after a restart (experiment.h srv_exp_readopt) ----------- */

int srv_exp_readopt(srv_experiment *e, const char *session_id)
{
	pthread_mutex_lock(&e->lock);
	int hit = !e->attached && (e->state == EXP_RUNNING || e->state == EXP_WAITING) &&
		  strcmp(e->session_id, session_id) == 0 && e->req.nseg >= 1;
	if (hit && !e->rec_t) {
		e->rec_t = malloc(EXP_RECORDS * sizeof(double));
		e->rec_v = malloc(EXP_RECORDS * sizeof(double));
	}
	if (hit && e->rec_t && e->rec_v) {
		/* every segment as the request left it, then its start */
		for (int i = 0; i < e->req.nseg; i++) {
			api_segment *seg = &e->req.seg[i];
			api_segment_reset(seg, seg->beta, seg->until);
		}
		e->rec_cap = EXP_RECORDS;
		e->rec_n = e->seg_first = 0;
		e->rec_spacing = e->req.seg[e->req.nseg - 1].until / EXP_RECORDS;
		e->state = EXP_WAITING;
		e->cur = 0;
		e->t0 = e->t_now = 0;
		e->error[0] = '\0';
		e->attached = 1;
	} else {
		hit = 0;
	}
	pthread_mutex_unlock(&e->lock);
	return hit;
}

int srv_exp_segment_commanded(srv_experiment *e, const srv_cmd *cmd, char *why, size_t whylen)
{
	api_segment *seg = &e->req.seg[e->cur];
	if (cmd->rc != SIM_OK) {
		if (e->dist_to > e->dist_from)
			snprintf(why, whylen, "disturbances[%d]: the session refused it: %s",
				 e->dist_from, sim_strerror(cmd->rc));
		else
			snprintf(why, whylen, "segment %d: the session refused beta = %g deg: %s",
				 e->cur, cmd->c.beta.user, sim_strerror(cmd->rc));
		return 1;
	}
	if (e->cmd_starts) {
		seg->t_command = cmd->t_eff;
		/* a control acts at the end of the integrator's step: the
		 * segment before ran its beta up to this command, not only to
		 * its boundary's observation inside that step */
		if (e->cur > 0)
			e->req.seg[e->cur - 1].t_end = cmd->t_eff;
	}
	return 0;
}

void srv_exp_end_segments(srv_experiment *e)
{
	for (int i = 0; i < e->req.nseg; i++)
		if (e->req.seg[i].state != API_SEG_DONE)
			e->req.seg[i].state = API_SEG_ABORTED;
}

int srv_exp_req_check(api_experiment_req *req, int cur, char *why, size_t whylen)
{
	req->session_id[sizeof req->session_id - 1] = '\0';
	api_problem pb;
	if (api_check_model(&req->spec, &pb) != API_OK) {
		snprintf(why, whylen, "its session's spec: %.*s",
			 whylen > 24 ? (int)(whylen - 24) : 0, pb.detail);
		return -1;
	}
	const char *bad = NULL;
	if (req->nseg < 1 || req->nseg > API_EXP_MAX_SEGMENTS || cur < 0 || cur >= req->nseg)
		bad = "its segments";
	else if (!isfinite(req->beta_rate.si) || req->beta_rate.si < 0.0)
		bad = "beta_rate";
	for (int i = 0; !bad && i < req->nseg; i++) {
		const api_segment *s = &req->seg[i];
		if (!isfinite(s->beta.si) || !(s->until > (i > 0 ? req->seg[i - 1].until : 0.0)) ||
		    !isfinite(s->until) || s->state < 0 || s->state >= API_SEG_NSTATES)
			bad = "a segment";
	}
	if (bad)
		snprintf(why, whylen, "inconsistent: %s", bad);
	return bad ? -1 : 0;
}
