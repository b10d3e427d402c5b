/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * study_json.c - the varied settings of a sweep request: "vary" (each
 * member a number setting by name with {"from","to","step"} or a list of
 * values, in its user unit), "lhs" and "seed", checked and planned by the
 * core's study (core/study.h) into the request's points; a plain v(beta)
 * sweep as the study over beta alone. A 4xx names the member ("vary.mu",
 * "lhs") and, for a setting, its range; nothing is kept then.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"
#include "suggest.h"
#include "units.h"

static const char *const range_members[] = {"from", "to", "step", NULL};

/* A study's refusal of member `field` (setting `name`) as a problem: an
 * unknown name with the nearest one, a setting that is not a number as
 * an invalid value, a value out of range with the range (api_fail adds it
 * for a field ending in a setting's name). */
static api_err study_problem(int rc, const char *field, const char *name, const char *msg,
			     api_problem *pb)
{
	const sim_setting *t = sim_setting_find(name);
	if (rc == SIM_ENOMEM)
		return api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
	if (!t) {
		size_t n;
		const sim_setting *all = sim_settings(&n);
		const char *near = sim_suggest(name, &all->name, n, sizeof *all);
		return api_fail(pb, API_UNKNOWN, field,
				"%s: unknown setting \"%s\"%s%s%s; GET /api/v1/presets lists the settings",
				field, name, near ? " (did you mean \"" : "", near ? near : "",
				near ? "\"?)" : "");
	}
	int number = (t->kind == SIM_KIND_REAL || t->kind == SIM_KIND_INT) &&
		     strcmp(name, "rotation") != 0;
	api_fail(pb, number ? API_RANGE : API_INVALID, field, "%s: %s", field, msg);
	if (number) { /* "vary" is no settings group: the range is added here */
		pb->has_range = 1;
		pb->min = t->min;
		pb->max = t->max;
	}
	return pb->code;
}

/* A list of n values of field that repeats one: a 422 naming the repeat,
 * field[k] (sim_study_repeat, the rule the study itself keeps). */
static api_err list_repeat(const char *field, const double *values, size_t n, api_problem *pb)
{
	size_t first = 0;
	long again = sim_study_repeat(values, n, &first);
	if (again < 0)
		return API_OK;
	char at[112];
	snprintf(at, sizeof at, "%s[%ld]", field, again);
	return api_fail(pb, API_INVALID, at, "%s repeats %s[%zu] (%.15g): each point runs once; "
			"list each value once", at, field, first, values[again]);
}

/* One member of "vary" as an axis of st: {"from","to","step"} or a
 * list of numbers, on the request's model. */
static api_err parse_axis(const cJSON *it, const api_sweep_req *req, sim_study *st,
			  api_problem *pb)
{
	char field[96], msg[256] = "", sub[128];
	const api_spec *sp = &req->spec;
	snprintf(field, sizeof field, "vary.%.80s", it->string);
	/* the setting before its values: ["cw", "ccw"] for rotation is
	 * refused as rotation, not as a list of non-numbers */
	int rc = sim_study_check_axis(st, it->string, msg, sizeof msg);
	if (rc != SIM_OK)
		return study_problem(rc, field, it->string, msg, pb);
	if (cJSON_IsObject(it)) {
		snprintf(sub, sizeof sub, "%s.", field);
		api_err e = api_check_members(it, range_members, sub, pb);
		if (e != API_OK)
			return e;
		double g[3];
		for (int k = 0; k < 3; k++) {
			const cJSON *v = cJSON_GetObjectItemCaseSensitive(it, range_members[k]);
			if (!cJSON_IsNumber(v))
				return api_fail(pb, API_TYPE, field, "%s.%s must be a number",
						field, range_members[k]);
			g[k] = v->valuedouble;
		}
		double count = sim_study_range_count(g[0], g[1], g[2]);
		if (count > API_SWEEP_MAX_POINTS)
			return api_fail_range(pb, field, 1, API_SWEEP_MAX_POINTS,
					      "%s: %g:%g:%g gives %.0f values; a sweep takes 1 to %d",
					      field, g[0], g[1], g[2], count, API_SWEEP_MAX_POINTS);
		rc = sim_study_add_range(st, &sp->params, &sp->scene, &sp->method, it->string,
					 g[0], g[1], g[2], msg, sizeof msg);
	} else if (cJSON_IsArray(it)) {
		int n = cJSON_GetArraySize(it), k = 0;
		if (n < 1 || n > API_SWEEP_MAX_POINTS)
			return api_fail_range(pb, field, 1, API_SWEEP_MAX_POINTS,
					      "%s has %d values; a sweep takes 1 to %d", field, n,
					      API_SWEEP_MAX_POINTS);
		double *values = malloc((size_t)n * sizeof *values);
		if (!values)
			return api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		for (const cJSON *v = it->child; v; v = v->next, k++) {
			if (!cJSON_IsNumber(v)) {
				free(values);
				return api_fail(pb, API_TYPE, field, "%s[%d] must be a number",
						field, k);
			}
			values[k] = v->valuedouble;
		}
		api_err e = list_repeat(field, values, (size_t)n, pb);
		if (e != API_OK) {
			free(values);
			return e;
		}
		rc = sim_study_add_list(st, &sp->params, &sp->scene, &sp->method, it->string,
					values, (size_t)n, msg, sizeof msg);
		free(values);
	} else {
		return api_fail(pb, API_TYPE, field,
				"%s must be {\"from\",\"to\",\"step\"} or an array of values",
				field);
	}
	return rc == SIM_OK ? API_OK : study_problem(rc, field, it->string, msg, pb);
}

/* The study's points in all (per sense times nrot senses) within a
 * sweep's 1 to API_SWEEP_MAX_POINTS, before they are made: else
 * out-of-range naming lhs (with the sample sizes that fit) or vary. */
static api_err study_points(const sim_study *st, int nrot, api_problem *pb)
{
	double per = sim_study_count(st), all = per * nrot;
	int most = API_SWEEP_MAX_POINTS;
	if (all <= most)
		return API_OK;
	if (!st->lhs)
		return api_fail_range(pb, "vary", 1, most, "the study has %.0f points (%.0f per "
				      "rotation sense); a sweep takes 1 to %d", all, per, most);
	return api_fail_range(pb, "lhs", 1, most / nrot, "the study has %.0f points (%.0f per "
			      "rotation sense); a sweep takes 1 to %d: lhs 1 to %d with %d rotation "
			      "sense%s", all, per, most, most / nrot, nrot, nrot == 1 ? "" : "s");
}

/* "lhs" (1 to API_SWEEP_MAX_POINTS points) and "seed" (0 to 2^32 - 1),
 * whole numbers. */
static api_err parse_sample(const cJSON *lhs, const cJSON *seed, sim_study *st,
			    api_problem *pb)
{
	double v = 0;
	api_err e = API_OK;
	if (lhs) {
		e = api_parse_real(lhs, "lhs", 1, API_SWEEP_MAX_POINTS, 0, &v, pb);
		if (e == API_OK && v != floor(v))
			e = api_fail_range(pb, "lhs", 1, API_SWEEP_MAX_POINTS,
					   "lhs must be a whole number of points in [1, %d]",
					   API_SWEEP_MAX_POINTS);
		st->lhs = (size_t)v;
	}
	st->seed = 1;
	if (e == API_OK && seed) {
		e = api_parse_real(seed, "seed", 0, 4294967295.0, 0, &v, pb);
		if (e == API_OK && v != floor(v))
			e = api_fail_range(pb, "seed", 0, 4294967295.0,
					   "seed must be a whole number in [0, 4294967295]");
		st->seed = (uint64_t)v;
	}
	return e;
}

/* The planned study into the request: its names, each point's values
 * and beta (the axis's, else the model's), the sample. */
static api_err take_study(const sim_study *st, api_sweep_req *req, api_problem *pb)
{
	size_t n = st->npoints, na = st->naxes;
	api_value *betas = malloc((n ? n : 1) * sizeof *betas);
	double *values = malloc((n * na > 0 ? n * na : 1) * sizeof *values);
	if (!betas || !values) {
		free(betas);
		free(values);
		return api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
	}
	long beta_axis = -1;
	req->nvary = (int)na;
	for (size_t a = 0; a < na; a++) {
		snprintf(req->vary[a], sizeof req->vary[a], "%s", st->axis[a].setting->name);
		if (strcmp(req->vary[a], "beta") == 0)
			beta_axis = (long)a;
	}
	memcpy(values, st->values, n * na * sizeof *values);
	for (size_t k = 0; k < n; k++) {
		if (beta_axis >= 0) {
			betas[k].user = sim_study_value(st, k, (size_t)beta_axis);
			betas[k].si = betas[k].user * RAD_PER_DEG;
		} else {
			betas[k].si = req->spec.params.beta;
			betas[k].user = api_user_of("beta", betas[k].si);
		}
	}
	free(req->betas);
	req->betas = betas;
	req->values = values;
	req->nbeta = (int)n;
	req->lhs = (int)st->lhs;
	req->seed = (uint32_t)st->seed;
	return API_OK;
}

api_err api_parse_study(const cJSON *vary, const cJSON *lhs, const cJSON *seed,
			api_sweep_req *req, api_problem *pb)
{
	sim_study st = {0};
	api_err e = API_OK;
	if (!vary && (lhs || seed))
		return api_fail(pb, API_INVALID, lhs ? "lhs" : "seed",
				"%s samples the ranges of vary: give vary", lhs ? "lhs" : "seed");
	if (seed && !lhs)
		return api_fail(pb, API_INVALID, "seed",
				"seed shuffles a Latin-hypercube sample: it applies only with lhs");
	if (vary && !cJSON_IsObject(vary))
		return api_fail(pb, API_TYPE, "vary",
				"vary must be an object of settings, each {\"from\",\"to\",\"step\"} "
				"or an array of values");
	/* the axes: vary's settings and beta's grid when given */
	int nvary = vary ? cJSON_GetArraySize(vary) : 0, most = SIM_STUDY_MAX_AXES - !!req->betas;
	if (vary && (nvary < 1 || nvary > most))
		return api_fail_range(pb, "vary", 1, most, "vary has %d settings; a sweep varies 1 to "
				      "%d%s", nvary, most, req->betas ? " besides beta" : "");
	/* beta first: the "beta" member's grid (for a plain sweep, the
	 * study over beta alone) */
	if (req->betas) {
		double *user = malloc((size_t)req->nbeta * sizeof *user);
		char msg[256] = "";
		int rc = user ? SIM_OK : SIM_ENOMEM;
		for (int k = 0; user && k < req->nbeta; k++)
			user[k] = req->betas[k].user;
		if (rc == SIM_OK && (e = list_repeat("beta", user, (size_t)req->nbeta, pb)) != API_OK) {
			free(user);
			return e;
		}
		if (rc == SIM_OK)
			rc = sim_study_add_list(&st, &req->spec.params, &req->spec.scene,
						&req->spec.method, "beta", user, (size_t)req->nbeta,
						msg, sizeof msg);
		free(user);
		if (rc != SIM_OK)
			e = study_problem(rc, "beta", "beta", msg, pb);
	}
	for (const cJSON *it = vary ? vary->child : NULL; e == API_OK && it; it = it->next)
		e = strcmp(it->string, "beta") == 0 && req->betas
			    ? api_fail(pb, API_INVALID, "vary.beta",
				       "beta is varied twice: as \"beta\" and as vary.beta")
			    : parse_axis(it, req, &st, pb);
	if (e == API_OK)
		e = parse_sample(lhs, seed, &st, pb);
	if (e == API_OK)
		e = study_points(&st, req->nrot, pb);
	char msg[256] = "";
	int rc = e == API_OK ? sim_study_plan(&st, msg, sizeof msg) : SIM_OK;
	if (rc != SIM_OK) /* a sample of a list, or no memory */
		e = api_fail(pb, rc == SIM_ENOMEM ? API_UNAVAILABLE : API_INVALID,
			     rc == SIM_ENOMEM ? NULL : st.lhs ? "lhs" : "vary", "%s", msg);
	/* each point measures after its own transient: t_end (sweep_json.c
	 * checked it against the model's) must exceed the largest varied */
	double transient = sim_study_largest(&st, "transient", 0);
	if (e == API_OK && !(req->t_end > transient)) {
		e = api_fail_range(pb, "t_end", transient, API_SWEEP_T_END_MAX,
				   "t_end (%g s) must exceed scene.transient = %g s (the largest "
				   "of vary.transient: the transport velocity is measured after "
				   "it) and be at most %g s", req->t_end, transient,
				   API_SWEEP_T_END_MAX);
	}
	if (e == API_OK)
		e = take_study(&st, req, pb);
	sim_study_free(&st);
	return e;
}
