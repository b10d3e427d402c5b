/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_json.c - calibration fits in JSON (POST /api/v1/fits): the request
 * (the model members as for sessions, the free parameters, the data as
 * points, as CSV text or as peaks, and the solver's options) into a
 * fit_request checked whole by the fitting module's fit_check, and the
 * job's progress and result back. The result itself is the fitting
 * module's JSON (fit_out.c), the same text `convsim fit` prints.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit.h"
#include "json_int.h"
#include "units.h"

const char *const api_members_fit[] = {"preset", "params", "scene", "integrator", "free",
				       "points", "csv", "peaks", "t_end", "curve_step",
				       "max_iter", "fd_step", "starts", NULL};
const char *const api_members_fit_free[] = {"name", "min", "max", "start", "prior", NULL};
const char *const api_members_fit_prior[] = {"mean", "sd", "factor", NULL};
const char *const api_members_fit_point[] = {"beta", "rotation", "v", "sigma", NULL};
const char *const api_members_fit_peak[] = {"beta", "rotation", "sigma", NULL};

/* A number member (NaN when absent and optional). */
static api_err number(const cJSON *o, const char *name, const char *prefix, int required,
		      double *out, api_problem *pb)
{
	const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, name);
	*out = NAN;
	if (!it && !required)
		return API_OK;
	if (!cJSON_IsNumber(it)) {
		char field[64];
		snprintf(field, sizeof field, "%s%s", prefix, name);
		return api_fail(pb, API_TYPE, field, "%s must be a number", field);
	}
	*out = it->valuedouble;
	return API_OK;
}

/* The first three members of names, numbers, into v (NaN when absent; the
 * first required when required is set). */
static api_err numbers(const cJSON *o, const char *prefix, const char *const *names,
		       int required, double v[3], api_problem *pb)
{
	api_err e = API_OK;
	for (int k = 0; k < 3 && e == API_OK; k++)
		e = number(o, names[k], prefix, required && k == 0, &v[k], pb);
	return e;
}

static api_err rotation(const cJSON *o, const char *prefix, int *rot, api_problem *pb)
{
	const cJSON *it = cJSON_GetObjectItemCaseSensitive(o, "rotation");
	char field[64];
	snprintf(field, sizeof field, "%srotation", prefix);
	if (!cJSON_IsString(it) ||
	    (strcmp(it->valuestring, "cw") != 0 && strcmp(it->valuestring, "ccw") != 0))
		return api_fail_choices(pb, cJSON_IsString(it) ? API_RANGE : API_TYPE, field,
					sim_setting_find("rotation")->choices,
					"%s must be \"cw\" or \"ccw\"", field);
	*rot = it->valuestring[1] == 'w' ? SIM_CW : SIM_CCW;
	return API_OK;
}

/* A count of data (what: "points has 1001 entries") outside what a fit of
 * req's free parameters takes, nfree to most: out-of-range with those
 * counts as min and max. */
static api_err data_count(api_problem *pb, const char *field, const char *what,
			  const fit_request *req, int most)
{
	int k = req->nfree;
	return api_fail_range(pb, field, k, most, "%s; a fit of %d free parameter%s takes %d to %d",
			      what, k, k == 1 ? "" : "s", k, most);
}

/* "points": [{beta, rotation, v, sigma?}] or "csv": "beta,rotation,v..." */
static api_err parse_points(const cJSON *root, fit_request *req, fit_point **pts,
			    api_problem *pb)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, "points");
	const cJSON *csv = cJSON_GetObjectItemCaseSensitive(root, "csv");
	char msg[FIT_MSG], prefix[40];
	if (arr && csv)
		return api_fail(pb, API_INVALID, "csv", "give points or csv, not both");
	if (csv) {
		if (!cJSON_IsString(csv))
			return api_fail(pb, API_TYPE, "csv", "csv must be a string (CSV text)");
		fit_range rows;
		if (fit_parse_csv(csv->valuestring, pts, &req->npoints, msg, sizeof msg, &rows) !=
		    SIM_OK) {
			char what[FIT_MSG + 8];
			snprintf(what, sizeof what, "csv: %s", msg);
			if (rows.has)
				return data_count(pb, "csv", what, req, FIT_MAX_POINTS);
			if (rows.choices) /* a row's rotation */
				return api_fail_choices(pb, API_RANGE, "csv", rows.choices, "%s",
							what);
			return api_fail(pb, API_INVALID, "csv", "%s", what);
		}
		req->points = *pts;
		return API_OK;
	}
	if (!arr)
		return API_OK;
	int n = cJSON_IsArray(arr) ? cJSON_GetArraySize(arr) : -1;
	if (n < 0)
		return api_fail(pb, API_TYPE, "points",
				"points must be an array of at most %d {beta, rotation, v, sigma}",
				FIT_MAX_POINTS);
	if (n > FIT_MAX_POINTS) {
		snprintf(prefix, sizeof prefix, "points has %d entries", n);
		return data_count(pb, "points", prefix, req, FIT_MAX_POINTS);
	}
	*pts = calloc((size_t)n + 1, sizeof **pts);
	if (!*pts)
		return api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
	req->points = *pts;
	api_err e = API_OK;
	int i = 0;
	for (const cJSON *p = arr->child; p && e == API_OK; p = p->next, i++) {
		fit_point *pt = &(*pts)[i];
		snprintf(prefix, sizeof prefix, "points[%d].", i);
		if (!cJSON_IsObject(p))
			return api_fail(pb, API_TYPE, "points", "points[%d] must be an object", i);
		e = api_check_members(p, api_members_fit_point, prefix, pb);
		if (e == API_OK)
			e = number(p, "beta", prefix, 1, &pt->beta, pb);
		if (e == API_OK)
			e = number(p, "v", prefix, 1, &pt->v, pb);
		if (e == API_OK)
			e = number(p, "sigma", prefix, 0, &pt->sigma, pb);
		if (e == API_OK)
			e = rotation(p, prefix, &pt->rotation, pb);
		pt->beta *= RAD_PER_DEG;
	}
	req->npoints = (size_t)n;
	return e;
}

static api_err parse_peaks(const cJSON *root, fit_request *req, api_problem *pb)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, "peaks");
	if (!arr)
		return API_OK;
	int n = cJSON_IsArray(arr) ? cJSON_GetArraySize(arr) : -1;
	char prefix[40];
	if (n < 0)
		return api_fail(pb, API_TYPE, "peaks",
				"peaks must be an array of at most %d {rotation, beta, sigma}",
				FIT_MAX_PEAKS);
	if (n > FIT_MAX_PEAKS) {
		snprintf(prefix, sizeof prefix, "peaks has %d entries", n);
		return data_count(pb, "peaks", prefix, req, FIT_MAX_PEAKS);
	}
	api_err e = API_OK;
	for (const cJSON *p = arr->child; p && e == API_OK; p = p->next) {
		fit_peak *pk = &req->peaks[req->npeaks];
		snprintf(prefix, sizeof prefix, "peaks[%d].", req->npeaks++);
		if (!cJSON_IsObject(p))
			return api_fail(pb, API_TYPE, "peaks", "%.20s must be an object", prefix);
		e = api_check_members(p, api_members_fit_peak, prefix, pb);
		if (e == API_OK)
			e = number(p, "beta", prefix, 1, &pk->beta, pb);
		if (e == API_OK)
			e = number(p, "sigma", prefix, 0, &pk->sigma, pb);
		if (e == API_OK)
			e = rotation(p, prefix, &pk->rotation, pb);
		pk->beta *= RAD_PER_DEG;
		pk->sigma *= RAD_PER_DEG;
	}
	return e;
}

/* free[i].prior: {"mean": M, "sd": S} (normal) or {"mean": M, "factor": F}
 * (log-normal), in the parameter's unit. */
static api_err parse_prior(const cJSON *pr, fit_request *req, const char *name, int i,
			   api_problem *pb)
{
	char prefix[40], field[48], msg[FIT_MSG];
	snprintf(prefix, sizeof prefix, "free[%d].prior.", i);
	snprintf(field, sizeof field, "free[%d].prior", i);
	if (!cJSON_IsObject(pr))
		return api_fail(pb, API_TYPE, field, "%s must be {mean, sd} or {mean, factor}", field);
	double v[3]; /* mean, sd, factor */
	api_err e = api_check_members(pr, api_members_fit_prior, prefix, pb);
	if (e == API_OK)
		e = numbers(pr, prefix, api_members_fit_prior, 1, v, pb);
	if (e != API_OK)
		return e;
	const char *member = NULL;
	fit_range range;
	if (fit_set_prior(req, name, v[0], v[1], v[2], msg, sizeof msg, &member, &range) == SIM_OK)
		return API_OK;
	if (!range.has)
		return api_fail(pb, API_INVALID, field, "%s", msg);
	snprintf(field, sizeof field, "free[%d].prior.%s", i, member);
	return api_fail_range(pb, field, range.min, range.max, "%s", msg);
}

/* "free": ["e", {"name": "b_s1", "min": 0, "max": 500, "start": 60,
 * "prior": {"mean": 80, "sd": 20}}] */
static api_err parse_free(const cJSON *root, fit_request *req, api_problem *pb)
{
	const cJSON *arr = cJSON_GetObjectItemCaseSensitive(root, "free");
	int n = cJSON_IsArray(arr) ? cJSON_GetArraySize(arr) : -1;
	if (n < 0)
		return api_fail(pb, arr ? API_TYPE : API_INVALID, "free",
				"free must list 1 to %d parameter names (or {name, min, max, "
				"start})", FIT_MAX_FREE);
	if (n < 1 || n > FIT_MAX_FREE)
		return api_fail_range(pb, "free", 1, FIT_MAX_FREE,
				      "free has %d entries; a fit takes 1 to %d free parameters", n,
				      FIT_MAX_FREE);
	char field[48], msg[FIT_MSG], prefix[32], member[8];
	fit_range range;
	int i = 0;
	for (const cJSON *f = arr->child; f; f = f->next, i++) {
		double v[3] = {NAN, NAN, NAN}; /* min, max, start */
		const char *name = cJSON_IsString(f) ? f->valuestring : NULL;
		snprintf(prefix, sizeof prefix, "free[%d].", i);
		if (cJSON_IsObject(f)) {
			api_err e = api_check_members(f, api_members_fit_free, prefix, pb);
			const cJSON *nm = cJSON_GetObjectItemCaseSensitive(f, "name");
			name = cJSON_IsString(nm) ? nm->valuestring : NULL;
			if (e == API_OK)
				e = numbers(f, prefix, api_members_fit_free + 1, 0, v, pb);
			if (e != API_OK)
				return e;
		}
		double lo = v[0], hi = v[1], start = v[2];
		snprintf(field, sizeof field, "free[%d]", i);
		if (!name)
			return api_fail(pb, API_TYPE, field, "%s must be a parameter name or "
					"{name, min, max, start}", field);
		int rc = fit_add_free(req, name, lo, hi, member, sizeof member, msg, sizeof msg,
				      &range);
		if (rc != SIM_OK && range.has) {
			snprintf(field, sizeof field, "%s%s", prefix, member);
			return api_fail_range(pb, field, range.min, range.max, "%s", msg);
		}
		if (rc != SIM_OK)
			return api_fail(pb, rc == SIM_EUNKNOWN ? API_UNKNOWN : API_INVALID, field,
					"%s", msg);
		if (!isnan(start))
			req->free[req->nfree - 1].start = sim_setting_to_si(sim_setting_find(name), start);
		const cJSON *pr = cJSON_IsObject(f) ? cJSON_GetObjectItemCaseSensitive(f, "prior") : NULL;
		if (pr) {
			api_err e = parse_prior(pr, req, name, i, pb);
			if (e != API_OK)
				return e;
		}
	}
	return API_OK;
}

/* The solver's options with their defaults (fit_request_init). */
static api_err parse_options(const cJSON *root, fit_request *req, api_problem *pb)
{
	double v;
	api_err e = number(root, "t_end", "", 0, &v, pb);
	if (e == API_OK && !isnan(v))
		req->t_end = v;
	if (e == API_OK && (e = number(root, "curve_step", "", 0, &v, pb)) == API_OK && !isnan(v))
		req->curve_step = v * RAD_PER_DEG;
	if (e == API_OK && (e = number(root, "fd_step", "", 0, &v, pb)) == API_OK && !isnan(v))
		req->fd_rel = v;
	if (e == API_OK && (e = number(root, "max_iter", "", 0, &v, pb)) == API_OK && !isnan(v)) {
		if (v != floor(v))
			return api_fail_range(pb, "max_iter", 1, FIT_MAX_ITER,
					      "max_iter must be an integer in [1, %d]", FIT_MAX_ITER);
		req->max_iter = (int)fmax(fmin(v, 1e6), -1);
	}
	if (e == API_OK && (e = number(root, "starts", "", 0, &v, pb)) == API_OK && !isnan(v)) {
		if (v != floor(v))
			return api_fail_range(pb, "starts", 1, FIT_MAX_STARTS,
					      "starts must be an integer in [1, %d]", FIT_MAX_STARTS);
		req->starts = (int)fmax(fmin(v, 1e6), -1);
	}
	return e;
}

api_err api_parse_fit(const char *body, size_t len, fit_request *req, fit_point **points,
		      api_problem *pb)
{
	fit_request_init(req);
	*points = NULL;
	cJSON *root = api_parse_body(body, len, api_members_fit, pb);
	if (!root)
		return pb->code;
	api_spec spec;
	memset(&spec, 0, sizeof spec);
	api_err e = api_apply_model(root, &spec, pb);
	if (e == API_OK)
		e = api_validate_spec(&spec, pb);
	if (e == API_OK) {
		req->p = spec.params;
		req->sc = spec.scene;
		req->m = spec.method;
		req->t_end = spec.scene.transient + API_SWEEP_WINDOW;
		e = parse_free(root, req, pb);
	}
	if (e == API_OK)
		e = parse_points(root, req, points, pb);
	if (e == API_OK)
		e = parse_peaks(root, req, pb);
	if (e == API_OK)
		e = parse_options(root, req, pb);
	char field[48], msg[FIT_MSG];
	fit_range range;
	if (e == API_OK &&
	    fit_check_range(req, field, sizeof field, msg, sizeof msg, &range) != SIM_OK)
		e = range.has ? api_fail_range(pb, field, range.min, range.max, "%s", msg)
			      : api_fail(pb, API_INVALID, field, "%s", msg);
	cJSON_Delete(root);
	if (e != API_OK) {
		free(*points);
		*points = NULL;
	}
	return e;
}

static cJSON *fit_object(const api_fit_view *v, int with_result)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "id", v->id);
	cJSON_AddStringToObject(o, "state", v->state);
	if (v->error && v->error[0])
		cJSON_AddStringToObject(o, "error", v->error);
	cJSON_AddStringToObject(o, "phase", v->pr.phase ? v->pr.phase : "queued");
	api_add_number(o, "iteration", v->pr.iteration);
	api_add_number(o, "max_iter", v->req->max_iter);
	api_add_number(o, "evaluations", (double)v->pr.evaluations);
	api_add_number(o, "cost", v->pr.cost);
	cJSON *cur = cJSON_AddObjectToObject(o, "values");
	for (int j = 0; j < v->req->nfree; j++)
		api_add_number(cur, v->req->free[j].name,
			       api_user_of(v->req->free[j].name,
					   v->pr.phase ? v->pr.x[j] : v->req->free[j].start));
	api_add_number(o, "data", v->req->npoints ? (double)v->req->npoints : v->req->npeaks);
	cJSON *res = with_result && v->result ? cJSON_Parse(v->result) : NULL;
	if (res)
		cJSON_AddItemToObject(o, "result", res);
	else
		cJSON_AddNullToObject(o, "result");
	api_add_result_links(o, "fits", v->id);
	return o;
}

char *api_fit_json(const api_fit_view *v)
{
	return api_print_free(fit_object(v, 1));
}

/* A listing's entry. */
static cJSON *fit_entry(const void *view)
{
	return fit_object(view, 0);
}

char *api_fit_list_json(const api_fit_view *v, size_t n)
{
	return api_list_json("fits", v, n, sizeof *v, fit_entry);
}

char *api_fit_list_csv(const api_fit_view *v, size_t n)
{
	api_buf b = {0};
	api_buf_puts(&b, "fit,state,phase,iteration,evaluations,cost\n");
	for (size_t i = 0; i < n; i++) {
		api_buf_printf(&b, "%s,%s,%s,%d,%ld,", v[i].id, v[i].state,
			       v[i].pr.phase ? v[i].pr.phase : "queued", v[i].pr.iteration,
			       v[i].pr.evaluations);
		if (isfinite(v[i].pr.cost))
			api_buf_double(&b, v[i].pr.cost);
		api_buf_put(&b, "\n", 1);
	}
	return api_buf_take(&b);
}
