/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_loop.c - the closed loop and the identification as the
 * worker runs them (docs/control.md).
 *
 * Both kinds sample the feed once per excitation period: the worker stops
 * there, and the sample is the mean feed velocity over the period since
 * the last one (feed_displacement's change over the window; the next
 * window is the rotor's last turn long), a whole-period mean at any phase
 * that, unlike the core's per-period feed_velocity, needs no estimator
 * restart to settle after each command. With r the setpoint and y the
 * sample, e = r - y,
 *
 *   beta = beta_ff(r) + s (kp e + I),   clamped to the branch [beta_lo, beta_hi]
 *
 * where beta_ff inverts the v(beta) curve on its monotonic branch and s is
 * the branch's sign of dv/dbeta (the gains are positive whichever way beta
 * moves v). The integral I += T_s ki e is held while beta still slews to
 * its last command (the core ramps it at beta_rate, like any PATCH) and is
 * pulled back by (clamped - unclamped) T_s / T_t (T_t = kp / ki) when the
 * command is at a branch end: both keep it from winding up. Each command
 * goes to the worker as a PATCH does (logged, in the stream), but steered
 * (the segment's transport estimate goes on) and its log line left to the
 * next sync (the experiment sends it again after a restore); a disturbance
 * due rides on the next sample's command, one each, as a PATCH. When a new
 * v(beta) curve is taken up, "auto" gains are tuned again by SIMC from its
 * slope at the operating point (srv_exp_retune).
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "experiment_int.h"
#include "fopdt.h"

#define DEG (M_PI / 180)
#define BAND 0.02 /* settled: within 2 % of the setpoint */

void srv_exp_fit(const double *t, const double *v, size_t n, double t_from, const double *ts,
		 const double *d, int m, double span, api_fopdt *out)
{
	double *ft = malloc((n + 1) * sizeof *ft), *fv = malloc((n + 1) * sizeof *fv);
	size_t k = 0;
	double last = NAN;
	for (size_t i = 0; ft && fv && i < n; i++) {
		if (!isfinite(v[i]) || v[i] == last) /* one value per period */
			continue;
		last = v[i];
		if (t[i] >= t_from)
			ft[k] = t[i], fv[k++] = v[i];
	}
	fopdt_result r = {0};
	/* each sample at the end of its period, when the controller sees it:
	 * the dead time includes the averaging */
	if (k >= 2)
		fopdt_fit(ft, fv, k, ts, d, (size_t)m, span, &r);
	out->k = r.ok ? r.k : NAN, out->k_se = r.ok ? r.k_se : NAN;
	out->t = r.ok ? r.t : NAN, out->t_se = r.ok ? r.t_se : NAN;
	out->l = r.ok ? r.l : NAN, out->l_se = r.ok ? r.l_se : NAN;
	out->v0 = r.ok ? r.y0 : NAN, out->rms = r.ok ? r.rms : NAN;
	out->n = (int)r.n;
	out->ok = r.ok;
	free(ft);
	free(fv);
}

void srv_exp_identify_results(srv_experiment *e)
{
	api_exp_ext *x = &e->ext;
	if (x->kind != API_EXP_IDENTIFY || e->cur % API_EXP_ID_SEGS != API_EXP_ID_SEGS - 1)
		return;
	int p = e->cur / API_EXP_ID_SEGS, base = p * API_EXP_ID_SEGS;
	const api_segment *seg = &e->req.seg[base];
	double ts[API_EXP_ID_SEGS - 1], d[API_EXP_ID_SEGS - 1];
	for (int k = 1; k < API_EXP_ID_SEGS; k++) {
		ts[k - 1] = seg[k].t_command;
		d[k - 1] = seg[k].beta.user - seg[k - 1].beta.user;
	}
	/* from the second half of the settling segment on */
	double from = seg[0].t_command + 0.5 * (seg[1].t_command - seg[0].t_command);
	api_fopdt *m = &x->model[p];
	srv_exp_fit(e->rec_t, e->rec_v, e->rec_n, from, ts, d, API_EXP_ID_SEGS - 1, x->id_hold, m);
	m->t_from = from - e->t0;
}

/* ---- the period clock -------------------------------------------------------- */

double srv_exp_period_of(const sim_status *st)
{
	if (isfinite(st->period) && st->period > 0)
		return st->period;
	double w = fabs(st->rotor_speed) > 1 ? fabs(st->rotor_speed) : st->omega_ss;
	return 2 * M_PI / w;
}

double srv_exp_clock_tick(double *period, double *last, const sim_status *st)
{
	double psi = st->q[3] - st->q[2], v = NAN;
	if (last[0] >= 0 && st->t > last[0]) {
		double dt = st->t - last[0], turn = fabs(psi - last[2]);
		v = (st->feed_displacement - last[1]) / dt;
		if (turn > 0.1) /* the window's mean rotor speed */
			*period = 2 * M_PI * dt / turn;
	}
	last[0] = st->t, last[1] = st->feed_displacement, last[2] = psi;
	return v;
}

void srv_exp_clock_start(srv_experiment *e, const sim_status *st)
{
	api_exp_ext *x = &e->ext;
	x->period = srv_exp_period_of(st);
	x->last_t = -1;
	double last[3] = {-1, 0, 0};
	srv_exp_clock_tick(&x->period, last, st);
	x->last_t = last[0], x->last_x = last[1], x->last_psi = last[2];
	x->t_sample = x->period;
}

int srv_exp_sample(srv_experiment *e, const sim_status *st, double *v)
{
	api_exp_ext *x = &e->ext;
	*v = NAN;
	if (x->kind == API_EXP_SCHEDULE) {
		/* a schedule records the core's per-period feed velocity */
		if (isfinite(st->feed_velocity) && e->rec_n < e->rec_cap &&
		    (e->rec_n == 0 || st->t - e->rec_t[e->rec_n - 1] >= e->rec_spacing)) {
			e->rec_t[e->rec_n] = st->t;
			e->rec_v[e->rec_n++] = st->feed_velocity;
		}
		return 0;
	}
	if (st->t - e->t0 < x->t_sample - 1e-9)
		return 0;
	double last[3] = {x->last_t, x->last_x, x->last_psi};
	*v = srv_exp_clock_tick(&x->period, last, st);
	x->last_t = last[0], x->last_x = last[1], x->last_psi = last[2];
	x->t_sample = st->t - e->t0 + x->period;
	if (isfinite(*v) && e->rec_n < e->rec_cap) {
		e->rec_t[e->rec_n] = st->t;
		e->rec_v[e->rec_n++] = *v;
	}
	return 1;
}

double srv_exp_feedforward(const api_exp_ext *ext, double v)
{
	int n = ext->nff, s = ext->branch_sign;
	if (n < 2)
		return NAN;
	/* along rising beta, v rises (s > 0) or falls */
	if ((v - ext->ff_v[0]) * s <= 0)
		return ext->ff_beta[0];
	for (int i = 1; i < n; i++)
		if ((v - ext->ff_v[i]) * s <= 0) {
			double f = (v - ext->ff_v[i - 1]) / (ext->ff_v[i] - ext->ff_v[i - 1]);
			return ext->ff_beta[i - 1] + f * (ext->ff_beta[i] - ext->ff_beta[i - 1]);
		}
	return ext->ff_beta[n - 1];
}

/* ---- the controller ------------------------------------------------------- */

/* v on the branch at beta (rad), by linear interpolation (clamped). */
static double branch_v(const api_exp_ext *x, double beta)
{
	int i = 1;
	while (i < x->nff - 1 && x->ff_beta[i] < beta)
		i++;
	double f = (beta - x->ff_beta[i - 1]) / (x->ff_beta[i] - x->ff_beta[i - 1]);
	f = f < 0 ? 0 : f > 1 ? 1 : f;
	return x->ff_v[i - 1] + f * (x->ff_v[i] - x->ff_v[i - 1]);
}

void srv_exp_retune(srv_experiment *e, const sim_status *st)
{
	api_exp_ext *x = &e->ext;
	double b0 = srv_exp_feedforward(x, x->sp[e->cur].v);
	/* the secant over the identification's step (4 deg), inside the
	 * branch: the slope the identification's gain stands for */
	double h = (x->tuned.step > 0 ? x->tuned.step : 4) * DEG;
	double a = fmax(b0 - h, x->beta_lo), b = fmin(b0 + h, x->beta_hi);
	double slope = b > a && x->nff >= 2 ? (branch_v(x, b) - branch_v(x, a)) / ((b - a) / DEG) : NAN;
	api_loop_gains *g = &x->gains;
	if (g->kp == 0 && g->ki == 0)
		g->kp = x->kp, g->ki = x->ki;
	int retuned = 0;
	if (x->auto_gains) {
		fopdt_result r = {.k = slope, .t = x->tuned.t, .l = x->tuned.l};
		double kp, ki;
		fopdt_simc(&r, x->tau_c, &kp, &ki);
		retuned = isfinite(kp) && isfinite(ki) && (kp > 0 || ki > 0);
		if (retuned)
			g->kp = kp, g->ki = ki;
	}
	/* the first ones, then the last one in the last entry */
	api_curve_change *k = &g->curves[g->n < API_EXP_MAX_CURVES ? g->n++ : API_EXP_MAX_CURVES - 1];
	k->t = st->t - e->t0;
	k->rotation = st->rotation, k->omega_ss = st->omega_ss;
	k->beta0 = b0 / DEG, k->slope = slope;
	k->retuned = retuned;
	k->kp = g->kp, k->ki = g->ki;
}

double srv_exp_control_boundary(const srv_experiment *e)
{
	const api_exp_ext *x = &e->ext;
	if (x->kind == API_EXP_SCHEDULE || e->state != EXP_RUNNING)
		return INFINITY;
	double t = x->t_sample;
	if (x->next_dist < x->ndist && x->dist[x->next_dist].at < t)
		t = x->dist[x->next_dist].at;
	return e->t0 + t;
}

void srv_exp_dist_commanded(srv_experiment *e, const srv_cmd *cmd, int refused)
{
	for (int k = e->dist_from; !refused && k < e->dist_to; k++) {
		e->ext.dist[k].applied = 1;
		e->ext.dist[k].t_applied = cmd->t_eff;
	}
	e->dist_from = e->dist_to = 0;
}

static double clamp(double v, double lo, double hi)
{
	return v < lo ? lo : v > hi ? hi : v;
}

/* The controller's beta (rad) for the sampled velocity y, its integral
 * advanced. */
static double pi_beta(srv_experiment *e, const sim_status *st, double y)
{
	api_exp_ext *x = &e->ext;
	double r = x->sp[e->cur].v, ts = x->period;
	double err = isfinite(y) ? r - y : 0;
	int s = x->branch_sign;
	double ff = srv_exp_feedforward(x, r) / DEG;
	int given = x->gains.kp == 0 && x->gains.ki == 0; /* no curve change yet */
	double kp = given ? x->kp : x->gains.kp, ki = given ? x->ki : x->gains.ki;
	double u = ff + s * (kp * err + x->integ);
	double lo = x->beta_lo / DEG, hi = x->beta_hi / DEG, cl = clamp(u, lo, hi);
	double rate = e->req.beta_rate.si > 0 ? e->req.beta_rate.si : e->req.spec.params.beta_rate;
	int slewing = fabs(st->beta_target - st->beta) > rate * ts;
	if (ki > 0 && isfinite(y) && !slewing) {
		double tt = kp > 0 ? fmax(kp / ki, ts) : ts;
		x->integ += ts * ki * err + s * (cl - u) * ts / tt;
	}
	return cl * DEG;
}

srv_cmd *srv_exp_control(srv_experiment *e, const sim_status *st, int sampled, double y)
{
	api_exp_ext *x = &e->ext;
	if (x->kind != API_EXP_CONTROL || e->state != EXP_RUNNING)
		return NULL;
	double tau = st->t - e->t0;
	int dist = x->next_dist < x->ndist && x->dist[x->next_dist].at <= tau + 1e-9;
	if (!sampled && !dist)
		return NULL;
	srv_cmd *cmd = &e->cmd;
	memset(cmd, 0, sizeof *cmd);
	e->cmd_starts = 0;
	e->dist_from = e->dist_to = x->next_dist;
	if (dist) {
		api_problem pb;
		const char *set = x->dist[x->next_dist].set;
		if (api_parse_control(set, strlen(set), &e->req.spec, &cmd->c, &pb) != API_OK)
			memset(&cmd->c, 0, sizeof cmd->c); /* checked at the request */
		e->dist_to = ++x->next_dist;
	}
	if (sampled) {
		double b = pi_beta(e, st, y);
		if (fabs(b - e->beta_sent) > 1e-7) {
			cmd->c.set |= API_C_BETA;
			cmd->c.beta = (api_value){b, b / DEG};
			if (e->req.beta_rate.si > 0) {
				cmd->c.set |= API_C_BETA_RATE;
				cmd->c.beta_rate = e->req.beta_rate;
			}
			e->beta_sent = b;
		}
	}
	if (!cmd->c.set)
		return NULL;
	/* beta alone: a step within the segment's estimate (a disturbance
	 * restarts it anyway) */
	cmd->loop_step = !dist;
	cmd->from_experiment = 1;
	return cmd;
}

/* ---- a setpoint's results --------------------------------------------------- */

/* From record index i0 on (times >= t_a): the first time after which v
 * stays within the band of r until the end, minus t_a (0 if never out;
 * NaN if the last sample is out); the largest |r - v| in *maxdev. */
static double settle_after(const srv_experiment *e, size_t i0, size_t i1, double t_a, double r,
			   double *maxdev)
{
	double band = BAND * fabs(r), settled = t_a;
	*maxdev = 0;
	int out_last = 0;
	for (size_t i = i0; i < i1; i++) {
		if (e->rec_t[i] < t_a)
			continue;
		double dev = fabs(r - e->rec_v[i]);
		*maxdev = fmax(*maxdev, dev);
		out_last = dev > band;
		if (out_last)
			settled = i + 1 < i1 ? e->rec_t[i + 1] : NAN;
	}
	return out_last ? NAN : settled - t_a;
}

void srv_exp_control_results(srv_experiment *e)
{
	api_exp_ext *x = &e->ext;
	if (x->kind != API_EXP_CONTROL)
		return;
	api_segment *seg = &e->req.seg[e->cur];
	api_setpoint *sp = &x->sp[e->cur];
	double r = sp->v, t_a = seg->t_command, t_b = seg->t_end;
	/* the first disturbance inside the segment ends the settling */
	double t_dist = t_b;
	for (int k = 0; k < x->ndist; k++)
		if (x->dist[k].applied && x->dist[k].t_applied >= t_a && x->dist[k].t_applied < t_dist)
			t_dist = x->dist[k].t_applied;
	size_t i1 = e->rec_n, iend = e->seg_first;
	while (iend < i1 && e->rec_t[iend] < t_dist)
		iend++;
	double dev;
	sp->settling_time = settle_after(e, e->seg_first, iend, t_a, r, &dev);
	double v0 = isfinite(seg->start_velocity) ? seg->start_velocity : r;
	double step = r - v0, over = 0, iae = 0, sum = 0, quarter = t_b - 0.25 * (t_b - t_a);
	size_t nq = 0;
	for (size_t i = e->seg_first; i < i1; i++) {
		double v = e->rec_v[i], dt = (i + 1 < i1 ? e->rec_t[i + 1] : t_b) - e->rec_t[i];
		if (e->rec_t[i] < t_a)
			continue;
		iae += fabs(r - v) * dt;
		if (i < iend && step != 0)
			over = fmax(over, (v - r) * (step > 0 ? 1 : -1));
		if (e->rec_t[i] >= quarter)
			sum += v, nq++;
	}
	sp->overshoot = fabs(step) > BAND * fabs(r) ? over / fabs(step) : 0;
	sp->iae = iae;
	double mean = nq ? sum / (double)nq : NAN;
	sp->steady_error = fabs(mean - r) / (fabs(r) > 1e-9 ? fabs(r) : 1);
	/* each disturbance's recovery, up to the next one or the end */
	for (int k = 0; k < x->ndist; k++) {
		api_disturbance *d = &x->dist[k];
		if (!d->applied || d->t_applied < t_a || d->t_applied >= t_b)
			continue;
		size_t ik = e->seg_first;
		double t_next = k + 1 < x->ndist && x->dist[k + 1].applied ? x->dist[k + 1].t_applied : t_b;
		while (ik < i1 && e->rec_t[ik] < t_next)
			ik++;
		d->recovery_time = settle_after(e, e->seg_first, ik, d->t_applied, r, &d->max_deviation);
	}
}
