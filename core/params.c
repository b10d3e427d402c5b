/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * params.c - every named setting with its unit and allowed range, and
 * checked assignment by name (the presets and the default steps:
 * defaults.c).
 * One table drives validation, error messages, the CLI, the API and its
 * OpenAPI document.
 */
#include <math.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "decimal.h"
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
	X(G_PARAM, M_load, REAL, "N m", 0, 1e5, NULL, 1, "load torque against the rotor's turning, constant but near standstill (where it holds the rotor, not turns it)") \
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
	X(G_SCENE, feed_model, ENUM, "", 0, 2, "column|liggghts|auto", 1, "column: the paper's columns of layers; liggghts: a LIGGGHTS bed coupled at the machine step (convsim built with LIGGGHTS, docs/dem.md); auto: the cheapest of the two whose model error is within model_tol, picked at creation (docs/feed-models.md)") \
	X(G_SCENE, model_tol, REAL, "m/s", 0, 1, NULL, 1, "feed_model auto: the largest model error (model_error plus its uncertainty) the feed model may have; 0: none given") \
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
/* the setting "method": the registry's names, in its order (ode.h) */
#define METHOD_CHOICE(descriptor, name) "|" name
#define METHOD_ONE(descriptor, name) +1
static const sim_setting table[] = {SETTINGS(ROW_PUB){
	"method", "integrator", SIM_KIND_ENUM, "", 1, 0, (0 ODE_REGISTRY(METHOD_ONE)) - 1,
	("" ODE_REGISTRY(METHOD_CHOICE)) + 1, "integrator by name"}};
#undef METHOD_ONE
#undef METHOD_CHOICE
#undef ROW_PUB

typedef struct loc {
	int group;
	size_t off;
	size_t size; /* a REAL of sizeof(float) is a float (model_tol) */
} loc;
#define OFF_G_PARAM(f) offsetof(sim_params, f)
#define OFF_G_SCENE(f) offsetof(sim_scene, f)
#define OFF_G_METHOD(f) offsetof(sim_method, f)
#define SIZE_G_PARAM(f) sizeof(((sim_params *)0)->f)
#define SIZE_G_SCENE(f) sizeof(((sim_scene *)0)->f)
#define SIZE_G_METHOD(f) sizeof(((sim_method *)0)->f)
#define ROW_LOC(grp, f, k, u, lo, hi, ch, sc, d) {grp, OFF_##grp(f), SIZE_##grp(f)},
static const loc locs[] = {SETTINGS(ROW_LOC){G_METHOD, 0, 0}};
#undef ROW_LOC

#define N_SETTINGS (sizeof table / sizeof table[0])

const sim_setting *sim_settings(size_t *n)
{
	*n = N_SETTINGS;
	return table;
}

static void *field(sim_params *p, sim_scene *s, sim_method *m, size_t i)
{
	char *base = locs[i].group == G_PARAM ? (char *)p
		     : locs[i].group == G_SCENE ? (char *)s
						 : (char *)m;
	return base + locs[i].off;
}

/* A float setting's value as the shortest decimal that is that float
 * (0.005, not 0.004999999888), so that it reads back as it was set. */
static double float_value(float f)
{
	char buf[32];
	for (int prec = 1; prec < 9; prec++) {
		snprintf(buf, sizeof buf, "%.*g", prec, (double)f);
		double v = strtod(buf, NULL);
		if ((float)v == f)
			return v;
	}
	return (double)f;
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
		else {
			/* "1" marks a number without a unit: nothing follows */
			const char *unit = strcmp(t->unit, "1") == 0 ? "" : t->unit;
			snprintf(msg, len, "%s must be %s in [%g, %g]%s%s", t->name,
				 t->kind == SIM_KIND_INT ? "an integer" : "a finite number", t->min,
				 t->max, *unit ? " " : "", unit);
		}
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
	else if (t->kind == SIM_KIND_REAL && locs[i].size == sizeof(float))
		*(float *)f = (float)value;
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
	if (!sim_decimal(value, out)) /* 0x1e, " 30", "nan": not numbers here */
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

/* sim_get of table[i] (i a valid index): no lookup by name, which cost
 * sim_validate a search of the table for every one of its settings. */
static void get_at(const sim_params *p, const sim_scene *s, const sim_method *m, size_t i,
		   double *value)
{
	const sim_setting *t = &table[i];
	if (strcmp(t->name, "method") == 0) {
		size_t n;
		const sim_method_info *const *mi = sim_methods(&n);
		for (size_t k = 0; k < n; k++)
			if (strcmp(mi[k]->name, m->name) == 0)
				*value = (double)k;
		return;
	}
	const void *f = field((sim_params *)p, (sim_scene *)s, (sim_method *)m, i);
	if (strcmp(t->name, "rotation") == 0)
		*value = *(const int *)f == SIM_CW ? 0 : 1;
	else if (t->kind == SIM_KIND_REAL && locs[i].size == sizeof(float))
		*value = float_value(*(const float *)f);
	else if (t->kind == SIM_KIND_REAL)
		*value = *(const double *)f;
	else
		*value = *(const int *)f;
}

int sim_get(const sim_params *p, const sim_scene *s, const sim_method *m, const char *name,
	    double *value)
{
	int i = find(name);
	if (i < 0)
		return SIM_EUNKNOWN;
	get_at(p, s, m, (size_t)i, value);
	return SIM_OK;
}

void sim_get_setting(const sim_params *p, const sim_scene *s, const sim_method *m,
		     const sim_setting *t, double *value)
{
	get_at(p, s, m, (size_t)(t - table), value);
}

int sim_get_user(const sim_params *p, const sim_scene *s, const sim_method *m, const char *name,
		 double *value)
{
	int i = find(name);
	if (i < 0)
		return SIM_EUNKNOWN;
	double si;
	get_at(p, s, m, (size_t)i, &si);
	*value = sim_setting_from_si(&table[i], si);
	return SIM_OK;
}

double sim_k_c_least(const sim_params *p, const sim_scene *s)
{
	sim_params unit = *p;
	unit.k_c = 1.0;
	double sag = model_column_sag(&unit, s);
	return sag > 0.0 ? pow(sag / MODEL_SAG_MAX, p->p) : 0.0;
}

double sim_m_n_most(const sim_params *p, const sim_scene *s)
{
	sim_params unit = *p;
	unit.m_n = 1.0;
	double sag = model_column_sag(&unit, s);
	return sag > 0.0 ? pow(MODEL_SAG_MAX / sag, p->p) : INFINITY;
}

double sim_k_s_least(const sim_params *p, int which)
{
	return (which == 1 ? p->m1 : p->m2) * p->g / MODEL_STROKE_MAX;
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
		double si;
		get_at(p, s, m, i, &si);
		double v = sim_setting_from_si(&table[i], si);
		/* a stored value converted back may differ in the last bit */
		double tol = 1e-12 * fmax(fabs(table[i].min), fabs(table[i].max));
		if (!isfinite(v) || v < table[i].min - tol || v > table[i].max + tol)
			return range_error(i, msg, msglen);
	}
	if (p->rotation != SIM_CW && p->rotation != SIM_CCW)
		return range_error((size_t)find("rotation"), msg, msglen);
	for (int i = 1; i <= 2; i++) {
		double k = i == 1 ? p->k_s1 : p->k_s2, least = sim_k_s_least(p, i);
		if (k > least)
			continue;
		if (msg)
			snprintf(msg, msglen,
				 "k_s%d must be above %.4g N/m here: on %.4g N/m eliminator %d "
				 "(%.4g kg) would sit %.3g m down its guide at beta 0 or 180 deg "
				 "(the model holds strokes within %g m)",
				 i, least, k, i, i == 1 ? p->m1 : p->m2, least / k * MODEL_STROKE_MAX,
				 MODEL_STROKE_MAX);
		return SIM_EPARAM;
	}
	if (model_column_sag(p, s) >= MODEL_SAG_MAX) {
		char unit[24] = "N/m";
		if (p->p != 1.0)
			snprintf(unit, sizeof unit, "N/m^%g", p->p);
		if (msg)
			snprintf(msg, msglen,
				 "k_c must be at least %.4g %s here: below it a column of %d "
				 "layers of %.4g-kg elements sinks %.3g cm under its own weight at "
				 "rest (the feed model holds %g cm)",
				 sim_k_c_least(p, s), unit, s->layers, p->m_n,
				 100.0 * model_column_sag(p, s), 100.0 * MODEL_SAG_MAX);
		return SIM_EPARAM;
	}
	double slip, machine;
	double bound = sim_max_dt_modes(p, s, m, &slip, &machine);
	if (m->dt > bound) {
		if (msg && slip <= machine)
			snprintf(msg, msglen,
				 "dt must be at most %.3g s for %s with these parameters: above it "
				 "the motor's slip mode (decay rate %.4g 1/s: 2 M_ut / slip_ut over "
				 "the rotor's inertia) makes the step unstable",
				 bound, m->name, model_slip_rate(p, s));
		else if (msg)
			snprintf(msg, msglen,
				 "dt must be at most %.3g s for %s with these parameters: above it "
				 "the machine's fastest mode (|lambda| %.4g 1/s: its stiffest spring "
				 "or damper over the mass it moves) makes the step unstable",
				 bound, m->name, model_machine_rate(p, s));
		return SIM_EPARAM;
	}
	return SIM_OK;
}
