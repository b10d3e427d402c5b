/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * study.c - a design study's points (study.h): axes over numeric settings
 * checked against the settings table, their full grid or a seeded Latin
 * hypercube, a task's settings applied to a model, and the mirror
 * reduction over tasks that agree on every axis but beta.
 *
 * The Latin hypercube (McKay, Beckman and Conover, Technometrics 21,
 * 1979): each axis's range is cut into n equal strata, the points take
 * one stratum of each axis by an independent random permutation per axis
 * and a uniform position inside it. The generator is splitmix64 (Steele,
 * Lea and Flood, OOPSLA 2014), so that a seed gives the same sample on
 * every machine.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_mirror.h"
#include "study.h"
#include "units.h"

/* The axis setting `name` may take: a number setting not yet an axis. */
static const sim_setting *axis_setting(const sim_study *st, const char *name, char *msg,
				       size_t msglen)
{
	const sim_setting *t = sim_setting_find(name);
	if (!t) {
		snprintf(msg, msglen, "unknown setting '%s'", name);
		return NULL;
	}
	if (strcmp(t->name, "rotation") == 0) {
		snprintf(msg, msglen, "rotation is not varied as a setting: the rotation senses are "
				      "a list of their own (cw, ccw or both)");
		return NULL;
	}
	if (t->kind != SIM_KIND_REAL && t->kind != SIM_KIND_INT) {
		snprintf(msg, msglen, "%s is %s, not a number: a study varies number settings; set "
				      "it once for the whole study",
			 t->name, t->kind == SIM_KIND_BOOL ? "true or false" : "a choice");
		return NULL;
	}
	for (size_t a = 0; a < st->naxes; a++)
		if (st->axis[a].setting == t) {
			snprintf(msg, msglen, "%s is varied twice", t->name);
			return NULL;
		}
	if (st->naxes == SIM_STUDY_MAX_AXES) {
		snprintf(msg, msglen, "at most %d settings are varied", SIM_STUDY_MAX_AXES);
		return NULL;
	}
	return t;
}

int sim_study_check_axis(const sim_study *st, const char *name, char *msg, size_t msglen)
{
	return axis_setting(st, name, msg, msglen) ? SIM_OK : SIM_EUNKNOWN;
}

double sim_study_largest(const sim_study *st, const char *name, double otherwise)
{
	for (size_t a = 0; a < st->naxes; a++) {
		if (strcmp(st->axis[a].setting->name, name) != 0)
			continue;
		double top = -INFINITY;
		if (st->values) /* planned: its points (a sample's too) */
			for (size_t k = 0; k < st->npoints; k++)
				top = fmax(top, sim_study_value(st, k, a));
		else
			for (size_t k = 0; k < st->axis[a].n; k++)
				top = fmax(top, st->axis[a].values[k]);
		return top;
	}
	return otherwise;
}

/* Value v (user units) set as setting t on a scratch copy of the model:
 * the same check as --set (range, whole numbers). */
static int check_value(const sim_setting *t, const sim_params *p, const sim_scene *s,
		       const sim_method *m, double v, char *msg, size_t msglen)
{
	sim_params p2 = *p;
	sim_scene s2 = *s;
	sim_method m2 = *m;
	return sim_set_user(&p2, &s2, &m2, t->name, v, msg, msglen);
}

/* v as the decimal a user means: rounded to 12 significant digits, so
 * that 0.2 + 4 x 0.1 is 0.6, not 0.6000000000000001 (whole numbers and
 * values with fewer digits pass unchanged). */
static double decimal(double v)
{
	char buf[32];
	snprintf(buf, sizeof buf, "%.12g", v);
	return strtod(buf, NULL);
}

double sim_study_range_count(double from, double to, double step)
{
	if (!(to >= from) || !(step > 0) || !isfinite(step))
		return NAN;
	return floor((to - from) / step + 1e-9) + 1;
}

int sim_study_add_range(sim_study *st, const sim_params *p, const sim_scene *s,
			const sim_method *m, const char *name, double from, double to,
			double step, char *msg, size_t msglen)
{
	const sim_setting *t = axis_setting(st, name, msg, msglen);
	if (!t)
		return SIM_EUNKNOWN;
	int rc = check_value(t, p, s, m, from, msg, msglen);
	if (rc == SIM_OK)
		rc = check_value(t, p, s, m, to, msg, msglen);
	if (rc != SIM_OK)
		return rc;
	if (!(to >= from) || !(step > 0) || !isfinite(step)) {
		snprintf(msg, msglen, "%s: a range needs FROM <= TO and STEP > 0, got %g:%g:%g",
			 t->name, from, to, step);
		return SIM_EPARAM;
	}
	double count = sim_study_range_count(from, to, step);
	if (count > SIM_STUDY_MAX_POINTS) {
		snprintf(msg, msglen, "%s: %g:%g:%g gives %.0f values; at most %d", t->name, from,
			 to, step, count, SIM_STUDY_MAX_POINTS);
		return SIM_EPARAM;
	}
	sim_study_axis *ax = &st->axis[st->naxes];
	ax->values = malloc((size_t)count * sizeof(double));
	if (!ax->values)
		return SIM_ENOMEM;
	ax->setting = t;
	ax->from = from;
	ax->to = to;
	ax->step = step;
	ax->n = (size_t)count;
	for (size_t k = 0; k < ax->n; k++)
		ax->values[k] = decimal(from + step * (double)k);
	for (size_t k = 0; k < ax->n; k++) /* whole-number settings: every value */
		if ((rc = check_value(t, p, s, m, ax->values[k], msg, msglen)) != SIM_OK) {
			free(ax->values);
			ax->values = NULL;
			return rc;
		}
	st->naxes++;
	return SIM_OK;
}

long sim_study_repeat(const double *values, size_t n, size_t *first)
{
	for (size_t k = 1; k < n; k++)
		for (size_t j = 0; j < k; j++)
			if (values[j] == values[k]) {
				*first = j;
				return (long)k;
			}
	return -1;
}

int sim_study_add_list(sim_study *st, const sim_params *p, const sim_scene *s,
		       const sim_method *m, const char *name, const double *values, size_t n,
		       char *msg, size_t msglen)
{
	const sim_setting *t = axis_setting(st, name, msg, msglen);
	if (!t)
		return SIM_EUNKNOWN;
	if (n == 0 || n > SIM_STUDY_MAX_POINTS) {
		snprintf(msg, msglen, "%s: a list needs 1 to %d values", t->name,
			 SIM_STUDY_MAX_POINTS);
		return SIM_EPARAM;
	}
	for (size_t k = 0; k < n; k++) {
		int rc = check_value(t, p, s, m, values[k], msg, msglen);
		if (rc != SIM_OK)
			return rc;
	}
	size_t first = 0;
	long again = sim_study_repeat(values, n, &first);
	if (again >= 0) {
		snprintf(msg, msglen, "%s: %.15g is listed twice: each point runs once; list each "
			 "value once", t->name, values[again]);
		return SIM_EPARAM;
	}
	sim_study_axis *ax = &st->axis[st->naxes];
	ax->values = malloc(n * sizeof(double));
	if (!ax->values)
		return SIM_ENOMEM;
	memcpy(ax->values, values, n * sizeof(double));
	ax->setting = t;
	ax->n = n;
	ax->step = 0;
	ax->from = ax->to = values[0];
	for (size_t k = 1; k < n; k++) {
		ax->from = fmin(ax->from, values[k]);
		ax->to = fmax(ax->to, values[k]);
	}
	st->naxes++;
	return SIM_OK;
}

/* splitmix64: the next 64 random bits of *state. */
static uint64_t next_bits(uint64_t *state)
{
	uint64_t z = (*state += 0x9e3779b97f4a7c15ULL);
	z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
	z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
	return z ^ (z >> 31);
}

/* A uniform number in [0, 1) from the top 53 bits. */
static double next_unit(uint64_t *state)
{
	return (double)(next_bits(state) >> 11) * 0x1.0p-53;
}

/* The Latin hypercube into st->values (allocated, npoints = lhs). */
static int plan_lhs(sim_study *st, size_t *perm)
{
	uint64_t state = st->seed;
	size_t n = st->lhs;
	for (size_t a = 0; a < st->naxes; a++) {
		const sim_study_axis *ax = &st->axis[a];
		for (size_t k = 0; k < n; k++)
			perm[k] = k;
		for (size_t k = n; k > 1; k--) { /* Fisher-Yates */
			size_t j = (size_t)(next_bits(&state) % k);
			size_t tmp = perm[k - 1];
			perm[k - 1] = perm[j];
			perm[j] = tmp;
		}
		for (size_t k = 0; k < n; k++) {
			double u = ((double)perm[k] + next_unit(&state)) / (double)n;
			double v = ax->from + (ax->to - ax->from) * u;
			if (ax->setting->kind == SIM_KIND_INT)
				v = nearbyint(v);
			st->values[k * st->naxes + a] = fmin(fmax(v, ax->from), ax->to);
		}
	}
	return SIM_OK;
}

double sim_study_count(const sim_study *st)
{
	double count = 1;
	if (st->lhs)
		return (double)st->lhs;
	for (size_t a = 0; a < st->naxes; a++)
		count *= (double)st->axis[a].n;
	return count;
}

int sim_study_plan(sim_study *st, char *msg, size_t msglen)
{
	double count = sim_study_count(st);
	for (size_t a = 0; st->lhs && a < st->naxes; a++)
		if (st->axis[a].step == 0 && st->axis[a].n > 1) {
			snprintf(msg, msglen, "%s: a Latin-hypercube sample needs a range "
					      "FROM:TO:STEP, not a list",
				 st->axis[a].setting->name);
			return SIM_EPARAM;
		}
	if (count > SIM_STUDY_MAX_POINTS) {
		snprintf(msg, msglen, "the study has %.0f points; at most %d", count,
			 SIM_STUDY_MAX_POINTS);
		return SIM_EPARAM;
	}
	size_t n = (size_t)count;
	free(st->values);
	st->values = malloc((n ? n : 1) * (st->naxes ? st->naxes : 1) * sizeof(double));
	size_t *perm = st->lhs ? malloc(n * sizeof(size_t)) : NULL;
	if (!st->values || (st->lhs && !perm)) {
		free(perm);
		snprintf(msg, msglen, "out of memory");
		return SIM_ENOMEM;
	}
	st->npoints = n;
	if (st->lhs) {
		plan_lhs(st, perm);
		free(perm);
		return SIM_OK;
	}
	for (size_t k = 0; k < n; k++) { /* the last axis varies fastest */
		size_t rest = k;
		for (size_t a = st->naxes; a-- > 0;) {
			const sim_study_axis *ax = &st->axis[a];
			st->values[k * st->naxes + a] = ax->values[rest % ax->n];
			rest /= ax->n;
		}
	}
	return SIM_OK;
}

/* Point k's axis values on the model (no rotation). */
static int apply_point(const sim_study *st, size_t k, sim_params *p, sim_scene *s,
		       sim_method *m, char *msg, size_t msglen)
{
	for (size_t a = 0; a < st->naxes; a++) {
		int rc = sim_set_user(p, s, m, st->axis[a].setting->name, sim_study_value(st, k, a),
				      msg, msglen);
		if (rc != SIM_OK)
			return rc;
	}
	return SIM_OK;
}

int sim_study_apply(const sim_study *st, size_t t, sim_params *p, sim_scene *s, sim_method *m,
		    char *msg, size_t msglen)
{
	p->rotation = st->rotation[t / st->npoints];
	return apply_point(st, t % st->npoints, p, s, m, msg, msglen);
}

/* 1 when points i and j agree on every axis but beta. */
static int same_but_beta(const sim_study *st, size_t i, size_t j)
{
	for (size_t a = 0; a < st->naxes; a++)
		if (strcmp(st->axis[a].setting->name, "beta") != 0 &&
		    sim_study_value(st, i, a) != sim_study_value(st, j, a))
			return 0;
	return 1;
}

size_t sim_study_mirror_plan(const sim_study *st, const sim_params *p, const sim_scene *s,
			     const sim_method *m, long *source)
{
	size_t ntasks = sim_study_tasks(st), np = st->npoints, measured = ntasks;
	char *grouped = calloc(np ? np : 1, 1);
	size_t *task = malloc((ntasks ? ntasks : 1) * sizeof(size_t));
	double *beta = malloc((ntasks ? ntasks : 1) * sizeof(double));
	int *rot = malloc((ntasks ? ntasks : 1) * sizeof(int));
	long *local = malloc((ntasks ? ntasks : 1) * sizeof(long));
	if (!grouped || !task || !beta || !rot || !local) {
		measured = (size_t)-1;
		goto done;
	}
	for (size_t t = 0; t < ntasks; t++)
		source[t] = -1;
	for (size_t k = 0; k < np; k++) {
		if (grouped[k])
			continue;
		/* the group of points that differ from k in beta alone, on
		 * the model at their common values */
		sim_params pg = *p;
		sim_scene sg = *s;
		sim_method mg = *m;
		if (apply_point(st, k, &pg, &sg, &mg, NULL, 0) != SIM_OK) {
			grouped[k] = 1;
			continue;
		}
		size_t n = 0;
		for (size_t r = 0; r < st->nrot; r++)
			for (size_t j = k; j < np; j++) {
				if (!same_but_beta(st, k, j))
					continue;
				sim_params pj = pg;
				sim_scene sj = sg;
				sim_method mj = mg;
				apply_point(st, j, &pj, &sj, &mj, NULL, 0);
				task[n] = r * np + j;
				beta[n] = pj.beta;
				rot[n] = st->rotation[r];
				n++;
				grouped[j] = 1;
			}
		sim_mirror_plan(&pg, &sg, n, beta, rot, local);
		for (size_t i = 0; i < n; i++)
			if (local[i] >= 0) {
				source[task[i]] = (long)task[local[i]];
				measured--;
			}
	}
done:
	free(grouped);
	free(task);
	free(beta);
	free(rot);
	free(local);
	return measured;
}

static int cmp_double(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

int sim_curve_covers(const double *beta_deg, size_t n)
{
	if (n < 2)
		return 0;
	double *b = malloc(n * sizeof *b);
	if (!b)
		return 0;
	memcpy(b, beta_deg, n * sizeof *b);
	qsort(b, n, sizeof *b, cmp_double);
	int ok = b[0] <= 1e-9 && b[n - 1] >= 180.0 - 1e-9;
	for (size_t i = 1; ok && i < n; i++)
		ok = b[i] - b[i - 1] <= SIM_CURVE_GAP_MAX + 1e-9;
	free(b);
	return ok;
}

int sim_study_curve(const sim_study *st)
{
	if (st->naxes != 1 || strcmp(st->axis[0].setting->name, "beta") != 0)
		return 0;
	double *b = malloc(st->npoints * sizeof *b);
	for (size_t k = 0; b && k < st->npoints; k++)
		b[k] = sim_study_value(st, k, 0);
	int curve = b && sim_curve_covers(b, st->npoints);
	free(b);
	return curve;
}

int sim_tol_met_at_peak(const sim_measurement *r, double tol, double peak)
{
	double v = fabs(r->transport_velocity);
	return r->tol_met && r->uncertainty <= tol * (v >= 0.3 * peak ? v : peak);
}

void sim_study_free(sim_study *st)
{
	if (!st)
		return;
	for (size_t a = 0; a < st->naxes; a++) {
		free(st->axis[a].values);
		st->axis[a].values = NULL;
	}
	free(st->values);
	st->values = NULL;
}
