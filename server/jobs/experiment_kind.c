/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_kind.c - what an identification or a closed-loop experiment
 * needs before its session runs it (docs/control.md), computed once in
 * the request's thread with the core's measure function:
 *
 *  - the machine's v(beta) curve for the scene and rotation sense (73
 *    points, 0 to 180 deg by 2.5, each a sim_measure of API_CURVE_WINDOW
 *    s), cached per scene (the last CURVES scenes), and its monotonic
 *    branch between the two peaks: the feedforward, the controller's beta
 *    range and the reachable setpoints;
 *  - each setpoint checked against that range (422 naming it);
 *  - "auto" gains: an identification run on a scratch instance at the
 *    first setpoint's feedforward beta, tuned by SIMC;
 *  - an identification's comparison slope: the v(beta) secant over
 *    beta0 -+ step.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "experiment_int.h"
#include "fopdt.h"
#include "util.h"

#define CURVES 4
#define CURVE_WINDOW SRV_EXP_CURVE_WINDOW
#define DEG (M_PI / 180)
#define SIMC_TAU_L 3.0 /* "auto": tau_c = 3 L unless given */

typedef struct curve_key {
	sim_params p; /* beta and beta_rate zeroed: they do not change v */
	sim_scene s;
	sim_method m;
} curve_key;

static struct {
	pthread_mutex_t lock;
	int n, next;
	curve_key key[CURVES];
	double v[CURVES][API_FF_NODES];
} cache = {.lock = PTHREAD_MUTEX_INITIALIZER};

static void key_of(const api_spec *spec, curve_key *k)
{
	memset(k, 0, sizeof *k);
	memcpy(&k->p, &spec->params, sizeof k->p);
	memcpy(&k->s, &spec->scene, sizeof k->s);
	memcpy(&k->m, &spec->method, sizeof k->m);
	k->p.beta = k->p.beta_rate = 0;
}

/* v at beta (rad) on spec's scene: a steady measurement, stopped once
 * this thread's CPU clock passes deadline (INFINITY: never). 0, SIM_ECPU
 * where stopped, else -1. */
static int measure_at(const api_spec *spec, double beta, double deadline, double *v, char *msg,
		      size_t len)
{
	sim_params p = spec->params;
	p.beta = beta;
	sim_measurement out;
	int rc = sim_measure_bounded(&p, &spec->scene, &spec->method,
				     spec->scene.transient + CURVE_WINDOW, deadline, &out, msg, len);
	*v = out.transport_velocity;
	return rc == SIM_ECPU ? rc : rc == SIM_OK && isfinite(*v) ? 0 : -1;
}

/* The curve of key k from the cache into v: 0, or -1 when not there. */
static int cached(const curve_key *k, double *v)
{
	int rc = -1;
	pthread_mutex_lock(&cache.lock);
	for (int i = 0; rc && i < cache.n; i++)
		if (memcmp(&cache.key[i], k, sizeof *k) == 0) {
			memcpy(v, cache.v[i], sizeof cache.v[i]);
			rc = 0;
		}
	pthread_mutex_unlock(&cache.lock);
	return rc;
}

int srv_exp_curve_cached(const api_spec *spec)
{
	curve_key k;
	double v[API_FF_NODES];
	key_of(spec, &k);
	return cached(&k, v) == 0;
}

int srv_exp_same_curve(const api_spec *a, const api_spec *b)
{
	curve_key ka, kb;
	key_of(a, &ka);
	key_of(b, &kb);
	return memcmp(&ka, &kb, sizeof ka) == 0;
}

/* The curve of spec's scene, from the cache or measured (unlocked while
 * measuring: two requests for a new scene measure it twice) by deadline
 * as measure_at; its codes. */
static int curve_of(const api_spec *spec, double deadline, double *v, char *msg, size_t len)
{
	curve_key k;
	key_of(spec, &k);
	if (cached(&k, v) == 0)
		return 0;
	for (int i = 0; i < API_FF_NODES; i++) {
		int rc = measure_at(spec, 2.5 * i * DEG, deadline, &v[i], msg, len);
		if (rc != 0)
			return rc;
	}
	pthread_mutex_lock(&cache.lock);
	int at = cache.next;
	cache.next = (cache.next + 1) % CURVES;
	if (cache.n < CURVES)
		cache.n++;
	cache.key[at] = k;
	memcpy(cache.v[at], v, sizeof cache.v[at]);
	pthread_mutex_unlock(&cache.lock);
	return 0;
}

/* A curve measured for a running loop, in a thread of its own: measuring
 * in the session's worker would stall it for a second and count against
 * its CPU (the pacing would slow the session down). One at a time. */
static int measuring; /* guarded by cache.lock */

static void *measure_thread(void *arg)
{
	api_spec *spec = arg;
	double v[API_FF_NODES];
	char msg[200];
	if (curve_of(spec, INFINITY, v, msg, sizeof msg) != 0)
		srv_log(SRV_LOG_WARN, "no v(beta) curve at omega_ss %g rad/s: %s",
			spec->params.omega_ss, msg);
	free(spec);
	pthread_mutex_lock(&cache.lock);
	measuring = 0;
	pthread_mutex_unlock(&cache.lock);
	return NULL;
}

static void measure_later(const api_spec *spec)
{
	pthread_mutex_lock(&cache.lock);
	int busy = measuring;
	measuring = 1;
	pthread_mutex_unlock(&cache.lock);
	api_spec *copy = busy ? NULL : malloc(sizeof *copy);
	pthread_t th;
	pthread_attr_t at;
	if (copy) {
		*copy = *spec;
		pthread_attr_init(&at);
		pthread_attr_setdetachstate(&at, PTHREAD_CREATE_DETACHED);
		if (pthread_create(&th, &at, measure_thread, copy) == 0)
			copy = NULL;
		pthread_attr_destroy(&at);
	}
	if (!busy && copy) { /* the thread did not start */
		free(copy);
		pthread_mutex_lock(&cache.lock);
		measuring = 0;
		pthread_mutex_unlock(&cache.lock);
	}
}

/* The branch between the curve's highest and lowest points into ext:
 * nodes in rising beta, its sign, range and ends. -1 when it is not
 * monotonic. */
static int branch_of(const double *v, api_exp_ext *ext)
{
	int hi = 0, lo = 0;
	for (int i = 1; i < API_FF_NODES; i++) {
		if (v[i] > v[hi])
			hi = i;
		if (v[i] < v[lo])
			lo = i;
	}
	int a = hi < lo ? hi : lo, b = hi < lo ? lo : hi;
	ext->branch_sign = hi < lo ? -1 : 1;
	ext->nff = b - a + 1;
	for (int i = a; i <= b; i++) {
		ext->ff_beta[i - a] = 2.5 * i * DEG;
		ext->ff_v[i - a] = v[i];
		if (i > a && (v[i] - v[i - 1]) * ext->branch_sign <= 0)
			return -1;
	}
	ext->v_lo = v[lo];
	ext->v_hi = v[hi];
	ext->beta_lo = ext->ff_beta[0];
	ext->beta_hi = ext->ff_beta[ext->nff - 1];
	return ext->nff >= 2 ? 0 : -1;
}

/* Curve v's branch into x's branch fields: 0, or -2 (x unchanged) when
 * it is not monotonic between its peaks. */
static int curve_into(api_exp_ext *x, const double *v)
{
	api_exp_ext *b = malloc(sizeof *b);
	if (!b)
		return -1;
	int rc = branch_of(v, b) == 0 ? 0 : -2;
	if (rc == 0) {
		x->branch_sign = b->branch_sign, x->nff = b->nff;
		memcpy(x->ff_beta, b->ff_beta, sizeof x->ff_beta);
		memcpy(x->ff_v, b->ff_v, sizeof x->ff_v);
		x->v_lo = b->v_lo, x->v_hi = b->v_hi;
		x->beta_lo = b->beta_lo, x->beta_hi = b->beta_hi;
	}
	free(b);
	return rc;
}

int srv_exp_dist_specs(const api_exp_ext *x, const api_spec *spec, api_spec *out)
{
	int n = 0;
	for (int k = 0; k < x->ndist; k++) {
		api_control c;
		api_problem pb;
		const char *set = x->dist[k].set;
		if (api_parse_control(set, strlen(set), spec, &c, &pb) != API_OK ||
		    !(c.set & (API_C_ROTATION | API_C_OMEGA_SS)))
			continue;
		out[n] = n ? out[n - 1] : *spec;
		if (c.set & API_C_ROTATION)
			out[n].params.rotation = c.rotation;
		if (c.set & API_C_OMEGA_SS)
			out[n].params.omega_ss = c.omega_ss;
		n++;
	}
	return n;
}

/* The curves the scheduled disturbances of rotation or omega_ss lead to,
 * measured now into the cache (the request's thread, until deadline: one
 * stopped is measured when the session gets there), so that the worker
 * finds them there when the session gets there. */
static void prefetch_curves(const api_exp_ext *x, const api_spec *spec, double deadline)
{
	api_spec *at = malloc(API_EXP_MAX_DIST * sizeof *at);
	if (!at)
		return;
	int n = srv_exp_dist_specs(x, spec, at);
	for (int k = 0; k < n; k++) {
		double v[API_FF_NODES];
		char msg[200];
		curve_of(&at[k], deadline, v, msg, sizeof msg);
	}
	free(at);
}

void srv_exp_follow_curve(srv_experiment *e, const sim_status *st)
{
	api_exp_ext *x = &e->ext;
	if (x->kind != API_EXP_CONTROL || e->state != EXP_RUNNING ||
	    (st->rotation == e->curve_rot && st->omega_ss == e->curve_omega))
		return;
	if (e->curve_omega == 0) { /* restored: its curve is the scene's */
		e->curve_rot = st->rotation, e->curve_omega = st->omega_ss;
		return;
	}
	api_spec *spec = malloc(sizeof *spec);
	if (!spec)
		return;
	*spec = e->req.spec;
	spec->params.rotation = st->rotation;
	spec->params.omega_ss = st->omega_ss;
	curve_key k;
	key_of(spec, &k);
	double v[API_FF_NODES];
	int rc = cached(&k, v);
	if (rc != 0)
		measure_later(spec); /* the old curve until then */
	free(spec);
	if (rc != 0)
		return;
	e->curve_rot = st->rotation, e->curve_omega = st->omega_ss;
	if (curve_into(x, v) != 0) {
		srv_log(SRV_LOG_WARN, "experiment %s: the v(beta) curve at omega_ss %g rad/s is not "
			"monotonic between its peaks; the controller keeps its last one",
			e->entry.id, st->omega_ss);
		return;
	}
	x->integ = 0; /* it made up for the old curve */
	x->curve_changes++;
	srv_exp_retune(e, st);
	/* the setpoints still to come start from the new feedforward */
	for (int i = e->cur + 1; i < e->req.nseg; i++) {
		double b = srv_exp_feedforward(x, x->sp[i].v);
		e->req.seg[i].beta = (api_value){b, b / DEG};
	}
}


/* An identification on a scratch instance of spec at beta0 (rad): the
 * schedule an "identify" experiment runs (settle, +d, back, -d, back, each
 * h long), sampled by the same period clock, stopped by deadline as
 * measure_at; its codes. */
static int identify_scratch(const api_spec *spec, double beta0, double d, double h,
			    double rate, double deadline, api_fopdt *m, char *msg, size_t len)
{
	sim_params p = spec->params;
	p.beta = beta0;
	int err;
	sim *s = sim_new_bounded(&p, &spec->scene, &spec->method, deadline, NULL, &err, msg, len);
	if (!s)
		return err == SIM_ECPU ? err : -1;
	sim_status st;
	sim_get_status(s, &st);
	double period = srv_exp_period_of(&st), last[3] = {-1, 0, 0};
	size_t cap = (size_t)(5 * h / (0.5 * period)) + 16, n = 0;
	double *t = malloc(cap * sizeof *t), *v = malloc(cap * sizeof *v);
	const double steps[4] = {d, 0, -d, 0};
	double ts[4], dd[4];
	int rc = t && v ? 0 : -1, k = 1;
	srv_exp_clock_tick(&period, last, &st);
	double t_next = st.t + period;
	while (rc == 0 && n < cap) {
		double t_step = h * k, target = fmin(t_next, t_step);
		rc = sim_advance_bounded(s, target, deadline);
		rc = rc == SIM_OK ? 0 : rc == SIM_ECPU ? rc : -1;
		sim_get_status(s, &st);
		if (rc == 0 && target == t_next) {
			double vk = srv_exp_clock_tick(&period, last, &st);
			if (isfinite(vk))
				t[n] = st.t, v[n++] = vk;
			t_next = st.t + period;
		}
		if (rc == 0 && target == t_step) {
			if (k == 5)
				break;
			ts[k - 1] = sim_effective_time(s);
			dd[k - 1] = steps[k - 1] - (k > 1 ? steps[k - 2] : 0);
			rc = sim_set_beta(s, beta0 + steps[k - 1] * DEG, rate) == SIM_OK ? 0 : -1;
			k++;
		}
	}
	if (rc == 0 && k == 5) {
		srv_exp_fit(t, v, n, 0.5 * h, ts, dd, 4, h, m);
		m->t_from = 0.5 * h; /* s after the scratch run's start */
	} else {
		snprintf(msg, len, "the identification run failed");
	}
	free(t);
	free(v);
	sim_free(s);
	return rc == SIM_ECPU ? rc : rc == 0 && m->ok ? 0 : -1;
}

/* Each setpoint within the branch's range, its beta the feedforward's. */
static api_err check_setpoints(srv_experiment *e, api_problem *pb)
{
	api_exp_ext *x = &e->ext;
	for (int i = 0; i < e->req.nseg; i++) {
		double v = x->sp[i].v;
		if (!(v > x->v_lo && v < x->v_hi)) {
			/* the range stated as the detail prints it, within the
			 * open one: a setpoint at a stated end is taken */
			char field[48];
			double lo = api_round_inward(x->v_lo, 1, 4), hi = api_round_inward(x->v_hi, 0, 4);
			lo = lo > x->v_lo ? lo : api_round_inward(nextafter(x->v_lo, INFINITY), 1, 4);
			hi = hi < x->v_hi ? hi : api_round_inward(nextafter(x->v_hi, -INFINITY), 0, 4);
			snprintf(field, sizeof field, "control.setpoint[%d].v", i);
			return api_fail_range(pb, field, lo, hi,
				 "%s = %g m/s is outside the machine's reachable range [%.4g, %.4g] "
				 "m/s: the v(beta) curve between its minimum at %g deg and its maximum "
				 "at %g deg",
				 field, v, lo, hi,
				 (x->branch_sign < 0 ? x->beta_hi : x->beta_lo) / DEG,
				 (x->branch_sign < 0 ? x->beta_lo : x->beta_hi) / DEG);
		}
		double b = srv_exp_feedforward(x, v);
		e->req.seg[i].beta = (api_value){b, ((b) / DEG)};
	}
	return API_OK;
}

/* "auto": SIMC gains from an identification at the first setpoint. */
static api_err auto_gains(srv_experiment *e, const api_spec *spec, double deadline,
			  api_problem *pb)
{
	api_exp_ext *x = &e->ext;
	char msg[200] = "";
	double b0 = e->req.seg[0].beta.si, rate = e->req.beta_rate.si;
	api_fopdt *m = &x->tuned;
	m->beta0 = b0 / DEG;
	m->step = 4;
	m->slope = NAN; /* no secant measured for it */
	int rc = identify_scratch(spec, b0, m->step, SRV_EXP_SCRATCH_HOLD,
				  rate > 0 ? rate : spec->params.beta_rate, deadline, m, msg, sizeof msg);
	if (rc == SIM_ECPU)
		return srv_exp_stopped(e, spec, deadline, pb);
	if (rc != 0)
		return api_fail(pb, API_INVALID, "control.controller",
				"control.controller \"auto\": the identification at %g deg gave no "
				"model (%s); give kp and ki", m->beta0, msg);
	/* SIMC's tight tau_c = L leaves the preset's loop in a limit cycle
	 * (the feed rings after each beta change, which a first-order model
	 * does not hold: docs/control.md); tau_c = 3 L by default */
	double tau = x->tau_c > 0 ? x->tau_c : SIMC_TAU_L * m->l;
	fopdt_result r = {.k = m->k, .t = m->t, .l = m->l};
	fopdt_simc(&r, tau, &x->kp, &x->ki);
	x->tau_c = tau;
	return isfinite(x->kp) && isfinite(x->ki)
		       ? API_OK
		       : api_fail(pb, API_INVALID, "control.controller",
				  "control.controller \"auto\": the identified gain is zero; give kp "
				  "and ki");
}

api_err srv_exp_prepare(srv_experiment *e, const api_spec *spec, double deadline,
			api_problem *pb)
{
	api_exp_ext *x = &e->ext;
	char msg[200] = "";
	/* the samples are the engine's feed displacement: a scene without a
	 * feed, or whose feed is a LIGGGHTS bed, has none to control */
	if (!spec->scene.feed || spec->scene.feed_model == SIM_FEED_EXTERNAL)
		return api_fail(pb, API_INVALID, "session",
				"%s needs a session whose feed is the engine's own (scene.feed true, not "
				"a LIGGGHTS bed)", x->kind == API_EXP_IDENTIFY ? "identify" : "control");
	if (x->kind == API_EXP_IDENTIFY) {
		for (int i = 0; i < x->npoints; i++) {
			api_fopdt *m = &x->model[i];
			double a, b;
			int rc = measure_at(spec, (m->beta0 - m->step) * DEG, deadline, &a, msg,
					    sizeof msg);
			if (rc == 0)
				rc = measure_at(spec, (m->beta0 + m->step) * DEG, deadline, &b, msg,
						sizeof msg);
			if (rc == SIM_ECPU)
				return srv_exp_stopped(e, spec, deadline, pb);
			if (rc == 0)
				m->slope = (b - a) / (2 * m->step);
		}
		return API_OK;
	}
	if (x->kind != API_EXP_CONTROL)
		return API_OK;
	double v[API_FF_NODES];
	int rc = curve_of(spec, deadline, v, msg, sizeof msg);
	if (rc == SIM_ECPU)
		return srv_exp_stopped(e, spec, deadline, pb);
	if (rc != 0)
		return api_fail(pb, API_INVALID, "control",
				"control: the machine's v(beta) curve could not be measured (%s)", msg);
	if (curve_into(x, v) != 0)
		return api_fail(pb, API_INVALID, "control",
				"control: the machine's v(beta) curve is not monotonic between its "
				"peaks; a controller needs a branch it can invert");
	e->curve_rot = spec->params.rotation, e->curve_omega = spec->params.omega_ss;
	x->curve_changes = 0;
	api_err err = check_setpoints(e, pb);
	if (err == API_OK && x->auto_gains)
		err = auto_gains(e, spec, deadline, pb);
	if (err == API_OK)
		prefetch_curves(x, spec, deadline);
	x->integ = 0;
	x->t_sample = 0;
	x->period = NAN; /* measured from the start */
	return err;
}

/* ---- the kind in the stored record (experiment.c) ---- */

/* The bytes of e's kind that follow its record (an identification's or a
 * closed loop's api_exp_ext; none for a plain schedule, whose record is
 * what it was before there were kinds). */
size_t srv_exp_tail_len(const srv_experiment *e)
{
	return e->ext.kind == API_EXP_SCHEDULE ? 0 : sizeof e->ext;
}

/* A tail read back: 0 when it is one (or none, tail 0). */
int srv_exp_tail_ok(const void *tail, size_t len)
{
	if (len == 0)
		return 0;
	api_exp_ext x;
	if (len != sizeof x)
		return -1;
	memcpy(&x, tail, sizeof x);
	return (x.kind == API_EXP_IDENTIFY || x.kind == API_EXP_CONTROL) &&
			       x.npoints >= 0 && x.npoints <= API_EXP_MAX_POINTS && x.ndist >= 0 &&
			       x.ndist <= API_EXP_MAX_DIST && x.nff >= 0 && x.nff <= API_FF_NODES &&
			       x.next_dist >= 0 && x.next_dist <= x.ndist
		       ? 0
		       : -1;
}
