/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * params.c - every named setting with its unit and allowed range, the
 * czubak2016 preset (docs/MODEL.md "Parameters"), and checked assignment by name.
 * One table drives validation, error messages, the CLI, the API and its
 * OpenAPI document.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "model.h"
#include "ode.h"
#include "sim.h"
#include "units.h"

enum { G_PARAM, G_SCENE, G_METHOD };

/* X(group, field, kind, unit, min, max, choices, scale, doc)
 * scale: the SI value of one user unit (RAD_PER_DEG for degrees). */
#define SETTINGS(X)                                                                        \
	X(G_PARAM, l1, REAL, "m", 0.05, 10, NULL, 1, "x of spring set 1 (body point (l1, -h))") \
	X(G_PARAM, l2, REAL, "m", 0.05, 10, NULL, 1, "x of spring set 2 is -l2")               \
	X(G_PARAM, h, REAL, "m", -2, 2, NULL, 1, "spring sets below G")                        \
	X(G_PARAM, k_x, REAL, "N/m", 100, 1e8, NULL, 1, "horizontal stiffness per spring set") \
	X(G_PARAM, k_y, REAL, "N/m", 100, 1e8, NULL, 1, "vertical stiffness per spring set")   \
	X(G_PARAM, b_x, REAL, "N s/m", 0, 1e6, NULL, 1, "horizontal damping per spring set")   \
	X(G_PARAM, b_y, REAL, "N s/m", 0, 1e6, NULL, 1, "vertical damping per spring set")     \
	X(G_PARAM, M_r, REAL, "kg", 1, 1e5, NULL, 1, "trough mass")                            \
	X(G_PARAM, J_r, REAL, "kg m^2", 0.01, 1e12, NULL, 1, "trough moment of inertia about G (large values pin its rotation)") \
	X(G_PARAM, m, REAL, "kg", 0.001, 1000, NULL, 1, "unbalanced mass")                     \
	X(G_PARAM, e, REAL, "m", 0, 0.5, NULL, 1, "eccentricity of the unbalanced mass")       \
	X(G_PARAM, J_w, REAL, "kg m^2", 1e-6, 10, NULL, 1, "rotor moment of inertia")          \
	X(G_PARAM, w_x, REAL, "m", -5, 5, NULL, 1, "vibrator axle, body x")                    \
	X(G_PARAM, w_y, REAL, "m", -5, 5, NULL, 1, "vibrator axle, body y")                    \
	X(G_PARAM, b_phi, REAL, "N m s^2", 0, 1, NULL, 1, "bearing drag b_phi w|w|")           \
	X(G_PARAM, M_load, REAL, "N m", 0, 1e5, NULL, 1, "constant load torque against the rotation") \
	X(G_PARAM, M_ut, REAL, "N m", 0.1, 1e5, NULL, 1, "motor breakdown torque")            \
	X(G_PARAM, omega_ss, REAL, "rad/s", 1, 1000, NULL, 1, "motor synchronous speed")       \
	X(G_PARAM, slip_ut, REAL, "rad/s", 0.1, 500, NULL, 1, "breakdown slip omega_ss - omega_ut") \
	X(G_PARAM, rotation, ENUM, "", 0, 1, "cw|ccw", 1, "sense of the unbalanced mass")      \
	X(G_PARAM, m1, REAL, "kg", 0.001, 1e4, NULL, 1, "eliminator 1 mass")                   \
	X(G_PARAM, m2, REAL, "kg", 0.001, 1e4, NULL, 1, "eliminator 2 mass")                   \
	X(G_PARAM, k_s1, REAL, "N/m", 1, 1e9, NULL, 1, "eliminator 1 spring")                  \
	X(G_PARAM, k_s2, REAL, "N/m", 1, 1e9, NULL, 1, "eliminator 2 spring")                  \
	X(G_PARAM, b_s1, REAL, "N s/m", 0, 1e6, NULL, 1, "eliminator 1 damper")                \
	X(G_PARAM, b_s2, REAL, "N s/m", 0, 1e6, NULL, 1, "eliminator 2 damper")                \
	X(G_PARAM, p1_x, REAL, "m", -5, 5, NULL, 1, "guide 1 point, body x")                   \
	X(G_PARAM, p1_y, REAL, "m", -5, 5, NULL, 1, "guide 1 point, body y")                   \
	X(G_PARAM, p2_x, REAL, "m", -5, 5, NULL, 1, "guide 2 point, body x")                   \
	X(G_PARAM, p2_y, REAL, "m", -5, 5, NULL, 1, "guide 2 point, body y")                   \
	X(G_PARAM, c, REAL, "m", -1, 1, NULL, 1, "eliminator mass offset along its guide")     \
	X(G_PARAM, beta, REAL, "deg", 0, 180, NULL, RAD_PER_DEG, "guide angle = vibration direction")  \
	X(G_PARAM, beta_rate, REAL, "deg/s", 0.1, 3600, NULL, RAD_PER_DEG, "slew rate of beta ramps")  \
	X(G_PARAM, beta_accel, REAL, "deg/s^2", 1, 1e6, NULL, RAD_PER_DEG, "acceleration bound of beta ramps") \
	X(G_PARAM, m_n, REAL, "kg", 1e-4, 100, NULL, 1, "feed element mass")                   \
	X(G_PARAM, k_c, REAL, "N/m^p", 100, 1e10, NULL, 1, "contact stiffness k")              \
	X(G_PARAM, p, REAL, "1", 1, 2, NULL, 1, "contact exponent")                             \
	X(G_PARAM, R, REAL, "1", 0.001, 1, NULL, 1, "restitution coefficient")                  \
	X(G_PARAM, mu, REAL, "1", 0, 2, NULL, 1, "friction coefficient")                        \
	X(G_PARAM, h_d, REAL, "m", -1, 1, NULL, 1, "deck height above G")                      \
	X(G_PARAM, column_span, REAL, "m", 0, 5, NULL, 1, "columns at d_k evenly in [-span, span]") \
	X(G_PARAM, g, REAL, "m/s^2", 0, 100, NULL, 1, "gravity")                               \
	X(G_PARAM, drive_accel, REAL, "rad/s^2", 1, 1e6, NULL, 1, "speed ramp of the ideal drive") \
	X(G_SCENE, feed, BOOL, "", 0, 1, NULL, 1, "simulate the feed")                         \
	X(G_SCENE, columns, INT, "", 1, SIM_MAX_COLUMNS, NULL, 1, "feed columns K")                         \
	X(G_SCENE, layers, INT, "", 1, SIM_MAX_LAYERS, NULL, 1, "feed layers L")                           \
	X(G_SCENE, drive, ENUM, "", 0, 1, "motor|ideal", 1, "Kloss motor or constant speed")   \
	X(G_SCENE, trough_rotation, BOOL, "", 0, 1, NULL, 1, "true: integrate alpha even on a symmetric machine; false: the engine drops it there") \
	X(G_SCENE, mirror, BOOL, "", 0, 1, NULL, 1, "true: a sweep or fit over both senses of a mirror-symmetric machine takes (ccw, 180 - beta) as the mirror image of (cw, beta); false: it integrates every point") \
	X(G_SCENE, feed_coupling, BOOL, "", 0, 1, NULL, 1, "false: the feed does not act on the trough") \
	X(G_SCENE, feed_model, ENUM, "", 0, 1, "column|liggghts", 1, "column: the paper's columns of layers; liggghts: a LIGGGHTS bed coupled at the machine step (convsim built with LIGGGHTS, docs/dem.md)") \
	X(G_SCENE, friction, ENUM, "", 0, 1, "coulomb|regularised", 1, "friction law")          \
	X(G_SCENE, friction_eps, REAL, "m/s", 1e-6, 1, NULL, 1, "regularised friction width")  \
	X(G_SCENE, motor_on, BOOL, "", 0, 1, NULL, 1, "drive switched on at t = 0")            \
	X(G_SCENE, transient, REAL, "s", 0, 1e4, NULL, 1, "transport velocity ignores t < transient") \
	X(G_SCENE, start, ENUM, "", 0, 1, "rest|steady", 1, "rest: run-up from static equilibrium (the paper's scene); steady: on the forced response at the loaded speed") \
	X(G_SCENE, settle, REAL, "s", 0, 100, NULL, 1, "steady start: simulated settling before t = 0 (added suspension damping, faded out)") \
	X(G_METHOD, dt, REAL, "s", 0, 1e-2, NULL, 1, "fixed (macro) step, or first step; 0 = the default for the scene kind") \
	X(G_METHOD, rtol, REAL, "1", 1e-13, 0.1, NULL, 1, "relative tolerance (adaptive)")      \
	X(G_METHOD, atol, REAL, "", 1e-15, 1, NULL, 1, "absolute tolerance (adaptive)")        \
	X(G_METHOD, substeps, INT, "", 0, 1000, NULL, 1, "feed sub-steps per macro step (dem); 0 = keep the feed step <= 2.5e-4 s (6.25e-5 s without feed_events)") \
	X(G_METHOD, feed_events, BOOL, "", 0, 1, NULL, 1, "dem: locate slip reversals inside the feed's sub-steps and let the deck yield to the feed's impulses within the machine step; false: the former dem") \
	X(G_METHOD, tol, REAL, "1", 1e-3, 0.2, NULL, 1, "accuracy target of the transport velocity (docs/MODEL.md's convention): the default steps scale with it, a measurement refines its steps until its estimated step error is within it")

#define GNAME_G_PARAM "params"
#define GNAME_G_SCENE "scene"
#define GNAME_G_METHOD "integrator"
#define ROW_PUB(grp, f, k, u, lo, hi, ch, sc, d) \
	{#f, GNAME_##grp, SIM_KIND_##k, u, sc, lo, hi, ch, d},
static const sim_setting table[] = {SETTINGS(ROW_PUB){"method", "integrator", SIM_KIND_ENUM, "", 1,
						 0, 3, "rk4|dopri5|euler|dem",
						 "integrator by name"}};
#undef ROW_PUB

typedef struct loc {
	int group;
	size_t off;
} loc;
#define OFF_G_PARAM(f) offsetof(sim_params, f)
#define OFF_G_SCENE(f) offsetof(sim_scene, f)
#define OFF_G_METHOD(f) offsetof(sim_method, f)
#define ROW_LOC(grp, f, k, u, lo, hi, ch, sc, d) {grp, OFF_##grp(f)},
static const loc locs[] = {SETTINGS(ROW_LOC){G_METHOD, 0}};
#undef ROW_LOC

#define N_SETTINGS (sizeof table / sizeof table[0])

const sim_setting *sim_settings(size_t *n)
{
	*n = N_SETTINGS;
	return table;
}

const char *const sim_preset_names[] = {"czubak2016", "czubak2016-fit", "liggghts-bed4", NULL};

/* liggghts-bed4: the column model's contact fitted to a LIGGGHTS bed of 4
 * grain diameters (367 spheres 3.6-4.4 mm, the preset's contacts) on the
 * preset's deck, one-way, 22 points (11 angles, both senses, 3 packing
 * seeds each) by `convsim fit -p liggghts-bed4 --data
 * tests/bench/results/dem_bed4.csv --free k_c,R,mu --set layers=4 --set
 * feed_coupling=false` (docs/dem.md "Calibrated to a bed"): R 0.177 +-
 * 0.009, mu 0.623 +- 0.007, k_c 2.6e4 N/m, which the data do not pin down
 * (standard error 3.9e4); rms residual 0.0030 m/s against the DEM, 0.0044
 * m/s with the values fitted before the bed's restitution was fixed. */
#define LIGGGHTS_BED4_K_C 25613.34
#define LIGGGHTS_BED4_R 0.17732
#define LIGGGHTS_BED4_MU 0.62285

void sim_preset_czubak2016(sim_params *p, sim_scene *s, sim_method *m)
{
	memset(p, 0, sizeof *p);
	p->l1 = p->l2 = 1.0;
	p->h = 0.0;
	p->b_x = p->b_y = 50.0;
	p->k_x = p->k_y = 75000.0;
	p->b_s1 = p->b_s2 = 60.0;
	p->k_s1 = p->k_s2 = 444132.0;
	p->m1 = p->m2 = 18.0;
	p->M_r = 120.0;
	p->m = 10.0;
	p->J_w = 0.0001;
	p->J_r = 25.0;
	p->R = 0.05;
	p->mu = 0.4;
	p->p = 1.0;
	p->M_ut = 50.0;
	/* corrected (docs/MODEL.md): e printed 0.215 m, omega_ss printed 42.5 rad/s */
	p->e = 0.0215;
	p->omega_ss = 157.08;
	p->slip_ut = 15.5;
	p->rotation = SIM_CW;
	/* chosen where the paper is silent */
	p->w_x = p->w_y = 0.0;
	p->p1_x = -0.3;
	p->p2_x = 0.3;
	p->p1_y = p->p2_y = 0.0;
	p->c = 0.0;
	p->h_d = 0.0;
	p->column_span = 0.8;
	p->m_n = 0.5;
	p->k_c = 1e6;
	p->b_phi = 0.0;
	p->g = 9.81;
	p->beta = 38.0 * RAD_PER_DEG;
	p->beta_rate = 90.0 * RAD_PER_DEG;
	p->beta_accel = 900.0 * RAD_PER_DEG;
	p->drive_accel = 2000.0;

	memset(s, 0, sizeof *s);
	s->feed = 1;
	s->columns = 5;
	s->layers = 8;
	s->drive = SIM_DRIVE_MOTOR;
	s->trough_rotation = 0; /* the engine drops alpha on the symmetric machine */
	s->mirror = 1; /* sweeps derive mirrored points (sim_mirror_plan) */
	s->feed_coupling = 1;
	s->friction = SIM_FRICTION_COULOMB;
	s->friction_eps = 1e-3;
	s->motor_on = 1;
	s->start = SIM_START_STEADY;
	s->transient = 0.0;
	s->settle = 0.6; /* docs/MODEL.md "Start": the settled orbit closes, the gate holds */

	memset(m, 0, sizeof *m);
	snprintf(m->name, sizeof m->name, "%s", "dem");
	m->dt = 0.0; /* chosen by sim_method_defaults() for the scene */
	m->rtol = 1e-6;
	m->atol = 1e-9;
	m->substeps = 0; /* as many as the feed step needs */
	m->feed_events = 1;
	m->tol = 0.01;
}

/* Defaults from the scene's own time scales (docs/machine-zoo.md), so that
 * a machine other than the preset gets steps that hold its accuracy
 * target (tol, 1 % by default):
 *  - the feed step resolves the contact: at most 1/17 of the contact
 *    period 2 pi sqrt(m_n / k_t), k_t the contact's tangent stiffness at
 *    the bottom of a settled column (p k delta^(p-1) at the compression
 *    (W / k)^(1/p) of the column's weight W); below about 17 sub-steps a
 *    contact period dem's v is not yet in its first-order regime and
 *    wanders by several per cent (k_c = 1e7: +6.3 % at 10 sub-steps a
 *    period, -0.3 % from 18 on), and never more than 2.5e-4 s (the
 *    preset's feed step: 5 sub-steps of its 1.25e-3-s machine step);
 *  - the machine step is at most 1/30 of the excitation period 2 pi /
 *    omega_ss and never more than the preset's 1.25e-3 s (32 steps a
 *    period at its 25 Hz; the machine step's error is first order, 0.2
 *    to 0.5 % of v there on the zoo), within 0.7 of the method's
 *    stability bound (sim_max_dt);
 *  - both scale with tol / 1 % below 1 % (dem is first order in both);
 *    a looser tol keeps the 1 % steps, since coarser ones leave the
 *    first-order regime.
 * Without feed_events (the former dem) the feed step is at most 6.25e-5 s;
 * a feed too heavy for the corrector (added mass) takes single steps of
 * 2.5e-5 s; without feed the machine is smooth and RK4 at 1e-3 s keeps the
 * trajectory within 2e-4. */
#define FEED_STEP_MAX 6.25e-5
#define FEED_STEP_MAX_EVENTS 2.5e-4
#define HEAVY_FEED_STEP 2.5e-5
#define FEED_MACHINE_STEP 1.25e-3
#define CONTACT_STEPS 17.0
#define PERIOD_STEPS 30.0

/* tol's factor on the default steps: tol / 1 %, at most 1. */
static double tol_scale(const sim_method *m)
{
	return m->tol > 0.0 && m->tol < 0.01 ? m->tol / 0.01 : 1.0;
}

double sim_contact_period(const sim_params *p, const sim_scene *s)
{
	double k_t = p->k_c;
	if (p->p != 1.0) {
		double W = (double)s->layers * p->m_n * p->g;
		double delta = pow(W / p->k_c, 1.0 / p->p);
		k_t = p->p * p->k_c * pow(delta, p->p - 1.0);
	}
	return 2.0 * M_PI * sqrt(p->m_n / k_t);
}

/* A step rounded down to two significant digits: a step a reader can
 * repeat. */
static double two_digits(double dt)
{
	double scale = pow(10.0, 1.0 - floor(log10(dt))); /* an exact power of ten */
	return floor(dt * scale * (1.0 + 1e-12)) / scale;
}

static double kind_default_dt(const sim_params *p, const sim_scene *s, const sim_method *m)
{
	int feed = s->feed && s->columns > 0 && s->layers > 0;
	if (strcmp(m->name, "euler") == 0)
		return feed ? 5e-6 : 1e-5;
	if (strcmp(m->name, "rk4") == 0)
		return feed ? 1e-5 : 1e-3;
	if (strcmp(m->name, "dopri5") == 0)
		return 1e-5; /* the first step */
	double dt, top;
	if (s->feed_coupling && feed && model_feed_mass_ratio(p, s) > MODEL_CORRECTOR_MAX_RATIO) {
		top = HEAVY_FEED_STEP;
		dt = fmin(top, sim_contact_period(p, s) / CONTACT_STEPS) * tol_scale(m);
	} else if (feed && m->feed_events) {
		top = FEED_MACHINE_STEP;
		dt = fmin(top, 2.0 * M_PI / p->omega_ss / PERIOD_STEPS) * tol_scale(m);
	} else {
		return 1e-3;
	}
	return dt < top ? two_digits(dt) : top;
}

/* The default step's share of the stability bound: RK4 at 0.7 of it keeps
 * 0.32 of the slip mode a step (the exact flow 0.14), at the bound all. */
#define DEFAULT_DT_STABILITY 0.7

double sim_default_dt(const sim_params *p, const sim_scene *s, const sim_method *m)
{
	double dt = kind_default_dt(p, s, m);
	double cap = DEFAULT_DT_STABILITY * sim_max_dt(p, s, m);
	return cap < dt ? two_digits(cap) : dt;
}

double sim_max_dt(const sim_params *p, const sim_scene *s, const sim_method *m)
{
	const ode_method *om = ode_find(m->name);
	double rate = model_slip_rate(p, s);
	if (!om || !(om->info.real_limit > 0.0) || !(rate > 0.0))
		return INFINITY;
	return om->info.real_limit / rate;
}

double sim_default_feed_step(const sim_params *p, const sim_scene *s, const sim_method *m)
{
	double hmax = m->feed_events ? FEED_STEP_MAX_EVENTS : FEED_STEP_MAX;
	return fmin(hmax, sim_contact_period(p, s) / CONTACT_STEPS) * tol_scale(m);
}

int sim_default_substeps(const sim_params *p, const sim_scene *s, const sim_method *m, double dt)
{
	int n = (int)ceil(dt / sim_default_feed_step(p, s, m) - 1e-9);
	return n < 1 ? 1 : n > 1000 ? 1000 : n;
}

/* czubak2016 with the eccentricity and the feed element's mass fitted to
 * the paper's clockwise peaks at 38 and 128 deg (docs/calibration.md "The
 * paper's case": `convsim fit --peaks cw:38,cw:128 --free
 * e:0.005:0.04,m_n:0.25:1 --starts 4`, e = 0.01509 m, m_n = 0.3136 kg,
 * rounded to three digits); everything else as czubak2016. */
#define CZUBAK2016_FIT_E 0.0151
#define CZUBAK2016_FIT_M_N 0.314

int sim_preset(const char *name, sim_params *p, sim_scene *s, sim_method *m)
{
	if (name && strcmp(name, "czubak2016") == 0) {
		sim_preset_czubak2016(p, s, m);
		return SIM_OK;
	}
	if (name && strcmp(name, "czubak2016-fit") == 0) {
		sim_preset_czubak2016(p, s, m);
		p->e = CZUBAK2016_FIT_E;
		p->m_n = CZUBAK2016_FIT_M_N;
		return SIM_OK;
	}
	if (name && strcmp(name, "liggghts-bed4") == 0) {
		sim_preset_czubak2016(p, s, m);
		s->layers = 4;
		p->k_c = LIGGGHTS_BED4_K_C;
		p->R = LIGGGHTS_BED4_R;
		p->mu = LIGGGHTS_BED4_MU;
		return SIM_OK;
	}
	return SIM_EUNKNOWN;
}

int sim_feed_validated(const sim_params *p, const sim_scene *sc, char *why, size_t len)
{
	if (!sc->feed || sc->feed_model != SIM_FEED_COLUMN)
		return -1;
	double k_over_m = p->k_c / p->m_n, beta = p->beta / RAD_PER_DEG;
	int fitted = p->k_c == LIGGGHTS_BED4_K_C && p->R == LIGGGHTS_BED4_R &&
		     p->mu == LIGGGHTS_BED4_MU;
	/* the DEM bed's second peak, which the column model lacks even with
	 * stiff contacts (150 deg cw, 30 deg ccw: 29-33 % apart) */
	int second_peak = p->rotation == SIM_CW ? beta > 137 && beta < 165 : beta > 15 && beta < 45;
	if (sc->layers <= 2 || (sc->layers <= 8 && k_over_m >= 2e7 && !second_peak) ||
	    (fitted && sc->layers <= 4))
		return 1;
	if (why)
		snprintf(why, len,
			 "the column model with %d layers and k_c/m_n = %.3g 1/s^2 at beta %.0f deg %s "
			 "lies outside the domain checked against LIGGGHTS beds (at most 2 layers; at "
			 "most 8 with k_c/m_n >= 2e7 away from 137-165 deg cw and 15-45 deg ccw; beds "
			 "of 4 and 8 diameters move 14 %% and 54 %% slower than the column model says "
			 "with the preset's contacts): feed_model=liggghts couples a DEM bed "
			 "(docs/dem.md)",
			 sc->layers, k_over_m, beta, p->rotation == SIM_CW ? "cw" : "ccw");
	return 0;
}

static void *field(sim_params *p, sim_scene *s, sim_method *m, size_t i)
{
	char *base = locs[i].group == G_PARAM ? (char *)p
		     : locs[i].group == G_SCENE ? (char *)s
						 : (char *)m;
	return base + locs[i].off;
}

static int find(const char *name)
{
	for (size_t i = 0; name && i < N_SETTINGS; i++)
		if (strcmp(table[i].name, name) == 0)
			return (int)i;
	return -1;
}

const sim_setting *sim_setting_find(const char *name)
{
	int i = find(name);
	return i < 0 ? NULL : &table[i];
}

int sim_setting_check(const sim_setting *t, double value)
{
	return isfinite(value) && value >= t->min * t->scale && value <= t->max * t->scale;
}

static int range_error(size_t i, char *msg, size_t len)
{
	const sim_setting *t = &table[i];
	if (msg) {
		if (t->kind == SIM_KIND_ENUM)
			snprintf(msg, len, "%s must be one of %s", t->name, t->choices);
		else if (t->kind == SIM_KIND_BOOL)
			snprintf(msg, len, "%s must be true or false", t->name);
		else
			snprintf(msg, len, "%s must be %s in [%g, %g]%s%s", t->name,
				 t->kind == SIM_KIND_INT ? "an integer" : "a finite number", t->min,
				 t->max, *t->unit ? " " : "", t->unit);
	}
	return SIM_EPARAM;
}

static int unknown_error(const char *name, char *msg, size_t msglen)
{
	if (msg)
		snprintf(msg, msglen, "unknown setting '%s'", name ? name : "");
	return SIM_EUNKNOWN;
}

int sim_set(sim_params *p, sim_scene *s, sim_method *m, const char *name, double value,
	    char *msg, size_t msglen)
{
	int i = find(name);
	if (i < 0)
		return unknown_error(name, msg, msglen);
	const sim_setting *t = &table[i];
	if (!sim_setting_check(t, value))
		return range_error((size_t)i, msg, msglen);
	if (t->kind != SIM_KIND_REAL && value != floor(value))
		return range_error((size_t)i, msg, msglen);
	if (strcmp(t->name, "method") == 0) {
		size_t n;
		const sim_method_info *const *mi = sim_methods(&n);
		snprintf(m->name, sizeof m->name, "%s", mi[(size_t)value]->name);
		return SIM_OK;
	}
	void *f = field(p, s, m, (size_t)i);
	if (strcmp(t->name, "rotation") == 0)
		*(int *)f = value == 0 ? SIM_CW : SIM_CCW;
	else if (t->kind == SIM_KIND_REAL)
		*(double *)f = value;
	else
		*(int *)f = (int)value;
	return SIM_OK;
}

int sim_set_user(sim_params *p, sim_scene *s, sim_method *m, const char *name, double value,
		 char *msg, size_t msglen)
{
	const sim_setting *t = sim_setting_find(name);
	if (!t)
		return unknown_error(name, msg, msglen);
	return sim_set(p, s, m, name, sim_setting_to_si(t, value), msg, msglen);
}

/* A string as setting i's number: the index of an enum choice, 0/1 for a
 * bool ("true", "false", "1", "0"), else a decimal number. */
static int parse_value(size_t i, const char *value, double *out, char *msg, size_t msglen)
{
	const sim_setting *t = &table[i];
	if (t->kind == SIM_KIND_ENUM) {
		const char *c = t->choices;
		for (int idx = 0; c && *c; idx++) {
			size_t len = strcspn(c, "|");
			if (strlen(value) == len && strncmp(c, value, len) == 0) {
				*out = idx;
				return SIM_OK;
			}
			c += len + (c[len] == '|');
		}
		return range_error(i, msg, msglen);
	}
	if (t->kind == SIM_KIND_BOOL) {
		if (strcmp(value, "true") == 0 || strcmp(value, "1") == 0)
			*out = 1;
		else if (strcmp(value, "false") == 0 || strcmp(value, "0") == 0)
			*out = 0;
		else
			return range_error(i, msg, msglen);
		return SIM_OK;
	}
	char *end;
	*out = strtod(value, &end);
	if (end == value || *end != '\0')
		return range_error(i, msg, msglen);
	return SIM_OK;
}

/* sim_set_str (user = 0, SI) and sim_set_user_str (user = 1). */
static int set_str(sim_params *p, sim_scene *s, sim_method *m, const char *name,
		   const char *value, int user, char *msg, size_t msglen)
{
	int i = find(name);
	if (i < 0 || !value)
		return sim_set(p, s, m, name, NAN, msg, msglen);
	double v = NAN; /* parse_value sets it where it returns SIM_OK */
	int e = parse_value((size_t)i, value, &v, msg, msglen);
	if (e != SIM_OK)
		return e;
	return user ? sim_set_user(p, s, m, name, v, msg, msglen)
		    : sim_set(p, s, m, name, v, msg, msglen);
}

int sim_set_str(sim_params *p, sim_scene *s, sim_method *m, const char *name,
		const char *value, char *msg, size_t msglen)
{
	return set_str(p, s, m, name, value, 0, msg, msglen);
}

int sim_set_user_str(sim_params *p, sim_scene *s, sim_method *m, const char *name,
		     const char *value, char *msg, size_t msglen)
{
	return set_str(p, s, m, name, value, 1, msg, msglen);
}

int sim_get(const sim_params *p, const sim_scene *s, const sim_method *m, const char *name,
	    double *value)
{
	int i = find(name);
	if (i < 0)
		return SIM_EUNKNOWN;
	const sim_setting *t = &table[i];
	if (strcmp(t->name, "method") == 0) {
		size_t n;
		const sim_method_info *const *mi = sim_methods(&n);
		for (size_t k = 0; k < n; k++)
			if (strcmp(mi[k]->name, m->name) == 0)
				*value = (double)k;
		return SIM_OK;
	}
	const void *f = field((sim_params *)p, (sim_scene *)s, (sim_method *)m, (size_t)i);
	if (strcmp(t->name, "rotation") == 0)
		*value = *(const int *)f == SIM_CW ? 0 : 1;
	else if (t->kind == SIM_KIND_REAL)
		*value = *(const double *)f;
	else
		*value = *(const int *)f;
	return SIM_OK;
}

int sim_get_user(const sim_params *p, const sim_scene *s, const sim_method *m, const char *name,
		 double *value)
{
	double si;
	int e = sim_get(p, s, m, name, &si);
	if (e == SIM_OK)
		*value = sim_setting_from_si(&table[find(name)], si);
	return e;
}

int sim_validate(const sim_params *p, const sim_scene *s, const sim_method *m, char *msg,
		 size_t msglen)
{
	if (!ode_find(m->name)) {
		if (msg)
			snprintf(msg, msglen, "method must be one of %s", table[N_SETTINGS - 1].choices);
		return SIM_EPARAM;
	}
	for (size_t i = 0; i + 1 < N_SETTINGS; i++) {
		double v;
		sim_get_user(p, s, m, table[i].name, &v);
		/* a stored value converted back may differ in the last bit */
		double tol = 1e-12 * fmax(fabs(table[i].min), fabs(table[i].max));
		if (!isfinite(v) || v < table[i].min - tol || v > table[i].max + tol)
			return range_error(i, msg, msglen);
	}
	if (p->rotation != SIM_CW && p->rotation != SIM_CCW)
		return range_error((size_t)find("rotation"), msg, msglen);
	double bound = sim_max_dt(p, s, m);
	if (m->dt > bound) {
		if (msg)
			snprintf(msg, msglen,
				 "dt must be at most %.3g s for %s with these parameters: above it "
				 "the motor's slip mode (decay rate %.4g 1/s: 2 M_ut / slip_ut over "
				 "the rotor's inertia) makes the step unstable",
				 bound, m->name, model_slip_rate(p, s));
		return SIM_EPARAM;
	}
	return SIM_OK;
}
