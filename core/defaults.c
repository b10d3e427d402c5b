/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * defaults.c - the presets (czubak2016, docs/model-numerics.md "Parameters", and the
 * fitted ones) and a scene's default steps, from its own time scales and
 * the method's descriptor (dt_feed, dt_free; sim_default_dt).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model.h"
#include "ode.h"
#include "sim.h"
#include "units.h"

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
	snprintf(m->name, sizeof m->name, "%s", sim_default_method());
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

/* A coupled feed too heavy for dem's corrector: single steps of
 * HEAVY_FEED_STEP (kind_default_dt), no sub-steps (sim_default_substeps). */
static int heavy_feed(const sim_params *p, const sim_scene *s)
{
	return s->feed_coupling && model_feed_mass_ratio(p, s) > MODEL_CORRECTOR_MAX_RATIO;
}

static double kind_default_dt(const sim_params *p, const sim_scene *s, const sim_method *m)
{
	int feed = s->feed && s->columns > 0 && s->layers > 0;
	const ode_method *om = ode_find(m->name);
	if (om && om->info.dt_feed > 0)
		return feed ? om->info.dt_feed : om->info.dt_free;
	double dt, top;
	if (feed && heavy_feed(p, s)) {
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
	double slip, machine;
	return sim_max_dt_modes(p, s, m, &slip, &machine);
}

double sim_max_dt_modes(const sim_params *p, const sim_scene *s, const sim_method *m,
			double *slip, double *machine)
{
	const ode_method *om = ode_find(m->name);
	*slip = *machine = INFINITY;
	if (!om || !(om->info.real_limit > 0.0))
		return INFINITY;
	double rate = model_slip_rate(p, s);
	if (rate > 0.0)
		*slip = om->info.real_limit / rate;
	rate = model_machine_rate(p, s);
	if (rate > 0.0)
		*machine = om->info.radius_limit / rate;
	return fmin(*slip, *machine);
}

double sim_default_feed_step(const sim_params *p, const sim_scene *s, const sim_method *m)
{
	double hmax = m->feed_events ? FEED_STEP_MAX_EVENTS : FEED_STEP_MAX;
	return fmin(hmax, sim_contact_period(p, s) / CONTACT_STEPS) * tol_scale(m);
}

/* Where a fast machine's stability bound cuts the machine step to less
 * than SIM_SHADOW_SUBSTEPS feed steps, it still gets that many, so that a
 * shadow measures the feed step's error there: with fewer none runs and
 * the preset's calibrated term stood for it (M_ut 269 N m, k_y 27670 N/m,
 * mu 0.48 at 60 deg cw: 2.4e-4 s with 1 sub-step, 1.16 % of |v| off with
 * a bar of 0.87 %; with 3, 0.06 % off and its bar measured). A heavy feed
 * keeps its single steps. */
int sim_default_substeps(const sim_params *p, const sim_scene *s, const sim_method *m, double dt)
{
	int n = (int)ceil(dt / sim_default_feed_step(p, s, m) - 1e-9);
	const ode_method *om = ode_find(m->name);
	if (n < SIM_SHADOW_SUBSTEPS && om && om->info.shadow && m->feed_events &&
	    !heavy_feed(p, s))
		n = SIM_SHADOW_SUBSTEPS;
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
