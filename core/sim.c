/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim.c - one simulation instance: owns the const model, the controls, the
 * state, the chosen integrator's workspace and the observers (the
 * transport-velocity estimator of estimator.c, the energy baselines); the
 * `steady` start's settling; stepping with observation on the step's
 * interpolant; the controls. The caller decides when to step
 * (sim_advance); controls take effect at the integrator's current time.
 * What the instance shows is computed in sim_status.c after each change,
 * with an evaluation that counts nothing.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "feed.h"
#include "sim_int.h"
#include "units.h"

#include "sim_check.h" /* the divergence guards */


/* Settling of the `steady` start: scene.settle simulated seconds before
 * t = 0 (0.6 s in czubak2016; rounded up to whole steps for the
 * fixed-step methods), with more damping on the suspension (per spring set
 * and direction model.settle_damping, the trough's critical damping on its
 * springs), full over the first SETTLE_FULL of it, then faded out. The
 * feed moves from its first period on and its reaction shifts the forced
 * response; the shift would set off the suspension's slow mode (tau = 2 M
 * / b, about 3.7 s for czubak2016), which the added damping lets die
 * within the settling. That damper acts on the spring set's velocity
 * relative to its velocity on the start's forced response (the orbit
 * dynamics_steady_start found, at the rotor's present phase), so the
 * forced response itself carries no added damping and the fade does not
 * move the machine off it. Measured (docs/MODEL.md "Start"): without feed one
 * period after t = 0 the orbit closes within 2e-10 of its size after 0.6
 * s (with the former damper on the velocity itself, 2,000 N s/m: 1e-3
 * after 0.6 s, 2.3e-5 after 1 s); with feed the trough's period means
 * stray over the first 2 s by at most 4.5e-6 m (median 1.0e-6 m) at 13
 * angles, where the former 1 s left 7.0e-6 m (2.4e-6 m). */
#define SETTLE_FULL 0.3

/* Run the integrator from -settle to t = 0 with the settling damping;
 * SIM_OK or the integrator's failure (s->error says why). No settling when
 * scene.settle is 0. */
static int settle(sim *s)
{
	model_ctl *ctl = &s->ctl;
	double span = s->md.sc.settle;
	if (!(span > 0.0))
		return SIM_OK;
	if (!s->ode->dense)
		span = ceil(span / s->cfg.dt - 1e-9) * s->cfg.dt;
	ctl->settle_b = 1.0;
	ctl->settle_t0 = -span * (1.0 - SETTLE_FULL);
	ramp_hold(&ctl->beta_ramp, -span, s->md.p.beta, 0.0);
	if (s->md.phi_prescribed)
		ramp_hold(&ctl->psi_ramp, -span, ctl->psi_ramp.b_end, ctl->psi_ramp.v_end);
	s->t_int = -span;
	int e = SIM_OK;
	while (e == SIM_OK && s->t_int < 0.0) {
		e = s->ode->step(s->ws, &s->sys, &s->t_int, s->y, 0.0);
		double q[NQ_FULL], qd[NQ_FULL];
		if (e == SIM_OK)
			e = check_state(s, q, qd);
		else
			snprintf(s->error, sizeof s->error, "step size underflow while settling");
		if (e == SIM_OK && s->t_int < 0.0 && cpu_bound_passed(&s->cpu)) {
			e = SIM_ECPU;
			snprintf(s->error, sizeof s->error, "the settling stopped at the CPU limit, "
				 "%.3g of its %.3g simulated s settled", s->t_int + span, span);
		}
	}
	s->cpu.ran = e == SIM_ECPU ? s->t_int + span : span;
	s->t_int = 0.0;
	ctl->settle_b = 0.0;
	ramp_hold(&ctl->beta_ramp, 0.0, s->md.p.beta, 0.0);
	s->ode->reset(s->ws);
	s->sys.rhs_evals = 0;
	return e;
}

/* Time zero of every observer: energy accumulators and baselines, the
 * estimator, the observed state, and with origins the feed displacements'
 * origins too; then the status. */
static void zero_observers(sim *s, int origins)
{
	const model *md = &s->md;
	double *acc = s->y + 2 * md->npos;
	for (int a = 0; a < ACC_N; a++)
		acc[a] = 0.0;
	s->e_disturb = 0.0;
	memcpy(s->y_obs, s->y, sizeof(double) * (size_t)md->n);
	memcpy(s->y_prev, s->y, sizeof(double) * (size_t)md->n);
	s->t_obs = s->t_prev = s->t_int;
	s->e0 = dynamics_energy_stored(md, &s->ctl, s->t_int, s->y, &s->kin0, &s->pot0);
	s->elastic0 = 0.0;
	if (md->nf > 0) {
		double q[NQ_FULL], qd[NQ_FULL];
		model_full_coords(md, &s->ctl, s->t_int, s->y, q, qd);
		s->elastic0 = dynamics_contact_energy(md, s->y, q, qd);
	}
	if (origins) {
		s->X0 = md->nf > 0 ? feed_mean_xi(md, s->y, -1) : 0.0;
		for (int k = 0; k < md->dk.K; k++)
			s->X0k[k] = feed_mean_xi(md, s->y, k);
	}
	estimator_init(&s->est, md, &s->ctl, s->t_int, s->y, md->sc.transient);
	sim_update_status(s);
}

/* The settling of a full model (trough_rotation) on a symmetric machine
 * with the Kloss drive and dem, done through the symmetric reduction:
 * there alpha = 0 and identical columns are the full model's solution
 * but for the small rocking the reduction drops (the moments of the
 * eliminator masses, off G by their strokes, and the drive's reaction on
 * the trough: alpha about 1e-6 rad, < 2e-6 rad after 1 s), so its
 * settled state is the reduced scene's, each column at its own deck
 * point. The reduced settling costs a fifth of the
 * feed's part (one column for K). Returns -1 where it does not apply (the
 * caller settles the full model), else SIM_OK or the settling's failure. */
static int settle_reduced(sim *s)
{
	const model *md = &s->md;
	if (!sim_reduced_settles(s))
		return -1;
	sim_scene rsc = md->sc;
	rsc.trough_rotation = 0;
	int err;
	sim *r = sim_alloc(&md->p, &rsc, &s->cfg, &err, NULL, 0);
	if (!r)
		return -1;
	if (r->md.layout != MODEL_LAYOUT_TROUGH2 || r->md.dk.K != 1 || r->md.L != md->L) {
		sim_free(r);
		return -1;
	}
	/* the reduced scene's own start (it settles itself: alpha fixed) */
	r->cpu = s->cpu;
	int e = sim_start(r, s->error, sizeof s->error);
	s->cpu.ran = r->cpu.ran;
	if (e != SIM_OK) {
		sim_free(r);
		return e;
	}
	/* the machine: the reduced scene's full coordinates, alpha = 0 */
	double q[NQ_FULL], qd[NQ_FULL];
	model_full_coords(&r->md, &r->ctl, 0.0, r->y, q, qd);
	for (int c = 0; c < md->nq; c++) {
		s->y[c] = q[md->col[c][0]];
		s->y[md->npos + c] = qd[md->col[c][0]];
	}
	/* the feed: every column as the reduced one, moved to its deck point */
	const model *rm = &r->md;
	for (int k = 0; k < md->dk.K; k++)
		for (int j = 0; j < md->L; j++) {
			int e_s = k * md->L + j;
			s->y[md->nq + e_s] = r->y[rm->nq + j] + (md->dk.d[k] - rm->dk.d[0]);
			s->y[md->nq + md->nf + e_s] = r->y[rm->nq + rm->nf + j];
			s->y[md->npos + md->nq + e_s] = r->y[rm->npos + rm->nq + j];
			s->y[md->npos + md->nq + md->nf + e_s] = r->y[rm->npos + rm->nq + rm->nf + j];
		}
	s->ctl.beta_ramp = r->ctl.beta_ramp;
	s->ctl.psi_ramp = r->ctl.psi_ramp;
	s->ctl.settle_b = 0.0;
	s->t_int = 0.0;
	sim_free(r);
	return SIM_OK;
}

int sim_start(sim *s, char *msg, size_t msglen)
{
	dynamics_equilibrium(&s->md, &s->ctl, s->y);
	if (s->md.sc.start == SIM_START_STEADY && s->ctl.drive_on) {
		int e = settle_reduced(s);
		if (e < 0) {
			dynamics_steady_start(&s->md, &s->ctl, s->y, &s->md.settle_orbit);
			e = settle(s);
		}
		if (e != SIM_OK) {
			if (msg)
				snprintf(msg, msglen, "%s", s->error);
			return e;
		}
	}
	zero_observers(s, 1);
	return SIM_OK;
}

sim *sim_new_windowed(const sim_params *p, const sim_scene *sc, const sim_method *m,
		      double shadow_window, double cpu_deadline, double *settled, int *err,
		      char *msg, size_t msglen)
{
	sim *s = sim_alloc(p, sc, m, err, msg, msglen);
	if (!s)
		return NULL;
	cpu_bound_start(&s->cpu, cpu_deadline);
	int e = sim_start(s, msg, msglen);
	if (settled)
		*settled = s->cpu.ran;
	cpu_bound_start(&s->cpu, INFINITY);
	if (e != SIM_OK) {
		if (err)
			*err = e;
		sim_free(s);
		return NULL;
	}
	if (shadow_window > 0.0)
		s->shadow_window = shadow_window;
	shadow_begin(s);
	return s;
}

sim *sim_new(const sim_params *p, const sim_scene *sc, const sim_method *m, int *err, char *msg,
	     size_t msglen)
{
	return sim_new_windowed(p, sc, m, 0.0, INFINITY, NULL, err, msg, msglen);
}

const char *sim_last_error(const sim *s)
{
	return s->error;
}

double sim_effective_time(const sim *s)
{
	/* the integrator's time, never before the observed one (they differ
	 * by the round-off of summed steps when the integrator stands on it) */
	return fmax(s->t_int, s->t_obs);
}

/* The state at t within the last step [t_prev, t_int] into y_obs, for the
 * fixed-step methods: positions on the cubic Hermite interpolant of the
 * step's end values and rates, rates and energy accumulators linear. */
static void interpolate_step(sim *s, double t)
{
	const model *md = &s->md;
	double H = s->t_int - s->t_prev, u = (t - s->t_prev) / H;
	const double *a = s->y_prev, *b = s->y;
	for (int i = 0; i < md->npos; i++)
		s->y_obs[i] = ode_hermite(a[i], a[md->npos + i], b[i], b[md->npos + i], H, u);
	for (int i = md->npos; i < md->n; i++)
		s->y_obs[i] = a[i] + u * (b[i] - a[i]);
}

/* Steps whole steps until the integrator reaches t_end (never shortened to
 * land on it, so that when and how often the caller observes changes
 * nothing), then observes at t_end on the step's interpolant. */
static int advance(sim *s, double t_end)
{
	if (s->failed)
		return s->failed;
	if (!isfinite(t_end) || t_end < s->t_obs - 1e-12)
		return SIM_ETIME;
	const double eps = 1e-12 * fmax(1.0, fabs(t_end));
	size_t n = (size_t)s->md.n;
	while (s->t_int < t_end - eps) {
		double t0 = s->t_int;
		/* a fixed step's end: k dt, not the sum of the steps */
		const double t_fixed = (double)(s->k_fixed + 1) * s->cfg.dt;
		/* the state before the step, for interpolate_step: read only
		 * at the end, so kept before the step that ends the loop */
		if (!s->ode->dense && t_fixed >= t_end - eps)
			memcpy(s->y_prev, s->y, sizeof(double) * n);
		int e = s->ode->step(s->ws, &s->sys, &s->t_int, s->y,
				     s->ode->dense ? t_end : INFINITY);
		if (e == SIM_OK && !s->ode->dense)
			s->t_int = t_fixed;
		double q[NQ_FULL], qd[NQ_FULL]; /* at t_int, for both observers */
		if (e == SIM_OK)
			e = check_state(s, q, qd);
		else
			snprintf(s->error, sizeof s->error,
				 "step size underflow at t = %.9g s (tolerance too tight or a "
				 "discontinuity the method cannot pass)",
				 s->t_int);
		if (e != SIM_OK) {
			s->failed = e;
			sim_update_status(s);
			return e;
		}
		if (!s->ode->dense)
			s->k_fixed++;
		s->t_prev = t0;
		s->steps++;
		estimator_step(&s->est, &s->md, t0, s->t_int, s->y, q, qd);
		if (s->t_int < t_end - eps && cpu_bound_passed(&s->cpu)) {
			/* observed where the integrator stands; it goes on from there */
			memcpy(s->y_obs, s->y, sizeof(double) * n);
			s->t_obs = s->t_int;
			sim_update_status(s);
			return SIM_ECPU;
		}
	}
	if (s->t_int > t_end + eps) {
		if (s->ode->dense)
			s->ode->interpolate(s->ws, t_end, s->y_obs);
		else
			interpolate_step(s, t_end);
		s->t_obs = t_end;
	} else {
		/* the integrator stands on t_end up to the round-off of its
		 * summed steps */
		memcpy(s->y_obs, s->y, sizeof(double) * n);
		s->t_obs = t_end;
	}
	sim_update_status(s);
	return SIM_OK;
}


int sim_advance(sim *s, double t_end)
{
	if (s->shadow && !s->failed && t_end > s->shadow_until && t_end >= s->t_obs) {
		int e = advance(s, s->shadow_until);
		if (e != SIM_OK)
			return e;
		if (advance(s->shadow, s->shadow_until) == SIM_ECPU)
			return SIM_ECPU; /* finished at the next call */
		shadow_finish(s);
		sim_update_status(s);
	}
	int e = advance(s, t_end);
	int es = s->shadow && e == SIM_OK ? advance(s->shadow, t_end) : SIM_OK;
	if (es == SIM_ECPU)
		return es; /* it catches up at the next call */
	if (es != SIM_OK) {
		shadow_finish(s);
		sim_update_status(s);
	}
	return e;
}

/* ---- controls ---- */

/* After a control: the integrator forgets cached derivatives, and the
 * transport estimate starts over at the first period boundary after
 * `settled` (the control's ramp, if any, has ended then), so that it and
 * its error bar and steady flag speak of the new regime only. */
static void control_changed(sim *s, double settled)
{
	s->ode->reset(s->ws);
	estimator_restart(&s->est, fmax(s->t_int, settled));
	shadow_begin(s);
	sim_update_status(s);
}

/* beta's new ramp (sim_set_beta, sim_steer_beta): SIM_OK or SIM_EPARAM
 * (nothing changed). */
static int beta_ramp(sim *s, double beta, double rate)
{
	if (!sim_setting_check(sim_setting_find("beta"), beta))
		return SIM_EPARAM;
	if (isfinite(rate) && rate > 0.0) {
		if (!sim_setting_check(sim_setting_find("beta_rate"), rate))
			return SIM_EPARAM;
		s->ctl.beta_rate = rate;
	} else if (!isfinite(rate)) {
		return SIM_EPARAM;
	}
	ramp_to_position(&s->ctl.beta_ramp, s->t_int, beta, s->ctl.beta_rate,
			 s->md.p.beta_accel);
	return SIM_OK;
}

int sim_set_beta(sim *s, double beta, double rate)
{
	int e = beta_ramp(s, beta, rate);
	if (e == SIM_OK)
		control_changed(s, s->ctl.beta_ramp.t_end);
	return e;
}

int sim_steer_beta(sim *s, double beta, double rate)
{
	int e = beta_ramp(s, beta, rate);
	if (e != SIM_OK)
		return e;
	/* the integrator forgets its cached derivatives as after any
	 * control; a running shadow takes the same command, so that both
	 * estimates still see the same controls over the same periods */
	s->ode->reset(s->ws);
	if (s->shadow && sim_steer_beta(s->shadow, beta, rate) != SIM_OK)
		shadow_stop(s);
	sim_update_status(s);
	return SIM_OK;
}

static void ideal_speed(sim *s)
{
	if (!s->md.phi_prescribed)
		return;
	double target = s->ctl.drive_on ? (double)s->ctl.rotation * s->ctl.omega_ss : 0.0;
	ramp_to_rate(&s->ctl.psi_ramp, s->t_int, target, s->md.p.drive_accel);
}

int sim_set_rotation(sim *s, int rotation)
{
	if (rotation != SIM_CW && rotation != SIM_CCW)
		return SIM_EPARAM;
	s->ctl.rotation = rotation;
	ideal_speed(s);
	control_changed(s, s->md.phi_prescribed ? s->ctl.psi_ramp.t_end : s->t_int);
	return SIM_OK;
}

int sim_set_omega_ss(sim *s, double omega_ss)
{
	if (!sim_setting_check(sim_setting_find("omega_ss"), omega_ss))
		return SIM_EPARAM;
	s->ctl.omega_ss = omega_ss;
	ideal_speed(s);
	control_changed(s, s->md.phi_prescribed ? s->ctl.psi_ramp.t_end : s->t_int);
	return SIM_OK;
}

int sim_set_drive_on(sim *s, int on)
{
	s->ctl.drive_on = on != 0;
	ideal_speed(s);
	control_changed(s, s->md.phi_prescribed ? s->ctl.psi_ramp.t_end : s->t_int);
	return SIM_OK;
}

int sim_set_deck_load(sim *s, double fx, double fy, double moment)
{
	if (s->md.sc.feed_model != SIM_FEED_EXTERNAL || !isfinite(fx) || !isfinite(fy) ||
	    !isfinite(moment))
		return SIM_EPARAM;
	s->ctl.deck_load[0] = fx;
	s->ctl.deck_load[1] = fy;
	s->ctl.deck_load[2] = moment;
	/* the integrator's cached derivatives held the old load */
	s->ode->reset(s->ws);
	sim_update_status(s);
	return SIM_OK;
}

void sim_restart_transport(sim *s)
{
	estimator_restart(&s->est, s->t_int);
	shadow_begin(s);
	sim_update_status(s);
}

int sim_place_feed(sim *s, const double *xi, const double *eta, const double *xi_dot,
		   const double *eta_dot)
{
	const model *md = &s->md;
	if (s->t_int != s->t_obs)
		return SIM_ETIME;
	const double *src[4] = {xi, eta, xi_dot, eta_dot};
	int off[4] = {md->nq, md->nq + md->nf, md->npos + md->nq, md->npos + md->nq + md->nf};
	for (int a = 0; a < 4; a++)
		for (int e = 0; src[a] && e < md->nf; e++)
			if (!isfinite(src[a][e]))
				return SIM_EPARAM;
	/* a fresh workspace: split methods cache the feed's reaction */
	void *ws = s->ode->alloc(md, &s->cfg);
	if (!ws)
		return SIM_ENOMEM;
	s->ode->free(s->ws);
	s->ws = ws;
	for (int a = 0; a < 4; a++)
		if (src[a])
			memcpy(s->y + off[a], src[a], sizeof(double) * (size_t)md->nf);
	zero_observers(s, 0); /* displacements still count from the start */
	shadow_begin(s);
	return SIM_OK;
}
