/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_json.c - the v(beta) sweep in JSON and CSV.
 *
 * A sweep measures the steady transport velocity for a list of beta
 * values and rotation directions (the paper's Figs. 9 and 11), or a study
 * over any number settings (study_json.c), one fresh instance per point.
 * This file parses the request (the model members as for sessions, plus
 * the beta grid, the rotations and the simulated time per point) and
 * writes progress and results, the varied settings' columns first.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"

const char *const api_members_beta_range[] = {"from", "to", "step", NULL};
const char *const api_members_sweep[] = {"preset", "params", "scene", "integrator",
					  "beta", "rotations", "t_end", "vary", "lhs",
					  "seed", "band_from_fit", NULL};

/* beta as an array of angles (deg) into req->betas. */
static api_err parse_beta_list(const cJSON *it, api_sweep_req *req, api_problem *pb)
{
	char field[32];
	int n = cJSON_GetArraySize(it);
	if (n < 1 || n > API_SWEEP_MAX_POINTS / 2)
		return api_fail_range(pb, "beta", 1, API_SWEEP_MAX_POINTS / 2,
				      "beta has %d angles; a sweep takes 1 to %d", n,
				      API_SWEEP_MAX_POINTS / 2);
	req->betas = malloc((size_t)n * sizeof *req->betas);
	if (!req->betas)
		return api_fail(pb, API_UNAVAILABLE, NULL,
				"out of memory");
	int i = 0;
	for (const cJSON *b = it->child; b; b = b->next, i++) {
		snprintf(field, sizeof field, "beta[%d]", i);
		api_err e = api_parse_user_value(&req->spec, "beta", b,
						 field, &req->betas[i],
						 pb);
		if (e != API_OK)
			return e;
	}
	req->nbeta = n;
	return API_OK;
}

static api_err parse_grid(const cJSON *it, api_sweep_req *req,
			  api_problem *pb)
{
	char field[32];
	if (!it) {
		/* default: 0..180 deg every 10 deg */
		req->nbeta = 19;
		req->betas = malloc(19 * sizeof *req->betas);
		if (!req->betas)
			return api_fail(pb, API_UNAVAILABLE, NULL,
					"out of memory");
		for (int i = 0; i < 19; i++) {
			api_err e = api_user_value(&req->spec, "beta", 10.0 * i,
						   "beta", &req->betas[i], pb);
			if (e != API_OK)
				return e;
		}
		return API_OK;
	}
	if (cJSON_IsArray(it))
		return parse_beta_list(it, req, pb);
	if (!cJSON_IsObject(it))
		return api_fail(pb, API_TYPE, "beta",
				"beta must be {\"from\",\"to\",\"step\"} or an "
				"array of angles");
	const char *const *members = api_members_beta_range;
	api_err e = api_check_members(it, members, "beta.", pb);
	double g[3];
	for (int k = 0; k < 3 && e == API_OK; k++) {
		const cJSON *v = cJSON_GetObjectItemCaseSensitive(it,
								  members[k]);
		snprintf(field, sizeof field, "beta.%s", members[k]);
		if (!cJSON_IsNumber(v))
			return api_fail(pb, API_TYPE, field,
					"%s must be a number (deg)", field);
		g[k] = v->valuedouble;
		api_value checked;
		if (k < 2)
			e = api_user_value(&req->spec, "beta", g[k], field,
					   &checked, pb);
	}
	if (e != API_OK)
		return e;
	/* the step in (0, the span of beta]: a longer one gives beta.from
	 * alone, as the span does */
	const sim_setting *b = sim_setting_find("beta");
	double span = b->max - b->min;
	if (!(g[2] > 0 && g[2] <= span))
		return api_fail_range(pb, "beta.step", 0, span, "beta.step must lie in (0, %g] deg",
				      span);
	if (g[1] < g[0])
		return api_fail_range(pb, "beta.to", g[0], b->max,
				      "beta.to must lie in [%g, %g] deg, not below beta.from", g[0],
				      b->max);
	int most = API_SWEEP_MAX_POINTS / 2;
	double count = sim_study_range_count(g[0], g[1], g[2]);
	if (count > most) {
		/* the least step of at most `most` angles, as %g states it */
		double least = api_round_inward((g[1] - g[0]) / (most - 1), 1, 6);
		return api_fail_range(pb, "beta.step", least, span,
				      "beta.step %g gives %.0f angles from %g to %g deg; a sweep "
				      "takes 1 to %d: beta.step must lie in [%g, %g] deg",
				      g[2], count, g[0], g[1], most, least, span);
	}
	req->nbeta = (int)count;
	req->betas = malloc((size_t)req->nbeta * sizeof *req->betas);
	if (!req->betas)
		return api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
	for (int i = 0; i < req->nbeta && e == API_OK; i++)
		e = api_user_value(&req->spec, "beta", g[0] + i * g[2], "beta",
				   &req->betas[i], pb);
	return e;
}

static api_err parse_rotations(const cJSON *it, api_sweep_req *req,
			       api_problem *pb)
{
	if (!it) {
		req->nrot = 2;
		req->rotations[0] = SIM_CW;
		req->rotations[1] = SIM_CCW;
		return API_OK;
	}
	int n = cJSON_IsArray(it) ? cJSON_GetArraySize(it) : -1;
	if (n < 0)
		return api_fail(pb, API_TYPE, "rotations",
				"rotations must be an array of one or two of "
				"\"cw\", \"ccw\"");
	if (n < 1 || n > 2)
		return api_fail_range(pb, "rotations", 1, 2,
				      "rotations has %d entries; a sweep takes 1 to 2 (\"cw\", "
				      "\"ccw\")", n);
	int i = 0;
	for (const cJSON *r = it->child; r; r = r->next, i++) {
		int rot;
		char field[24];
		snprintf(field, sizeof field, "rotations[%d]", i);
		if (cJSON_IsString(r) && strcmp(r->valuestring, "cw") == 0)
			rot = SIM_CW;
		else if (cJSON_IsString(r) && strcmp(r->valuestring, "ccw") == 0)
			rot = SIM_CCW;
		else
			return api_fail_choices(pb, cJSON_IsString(r) ? API_RANGE : API_TYPE, field,
						sim_setting_find("rotation")->choices,
						"%s must be \"cw\" or \"ccw\"", field);
		if (req->nrot == 1 && req->rotations[0] == rot)
			return api_fail(pb, API_INVALID, "rotations",
					"rotations lists a direction twice");
		req->rotations[req->nrot++] = rot;
	}
	return API_OK;
}

/* t_end: simulated seconds per point, past scene.transient (the estimate
 * starts there), default API_SWEEP_WINDOW after it. */
static api_err parse_t_end(const cJSON *te, const sim_scene *scene,
			   double *t_end, api_problem *pb)
{
	const double lo = scene->transient, hi = API_SWEEP_T_END_MAX;
	*t_end = fmin(scene->transient + API_SWEEP_WINDOW, hi);
	if (!(lo < hi)) {
		api_fail(pb, API_RANGE, "scene.transient",
			 "scene.transient = %g s leaves no time to measure: a "
			 "sweep runs at most %g s per point", lo, hi);
		pb->has_range = 1, pb->min = 0, pb->max = hi;
		return API_RANGE;
	}
	if (!te)
		return API_OK;
	if (!cJSON_IsNumber(te))
		return api_fail(pb, API_TYPE, "t_end",
				"t_end must be a number (s)");
	if (!(te->valuedouble > lo && te->valuedouble <= hi)) {
		api_fail(pb, API_RANGE, "t_end",
			 "t_end must exceed scene.transient = %g s (the "
			 "transport velocity is measured after it) and be at "
			 "most %g s", lo, hi);
		pb->has_range = 1, pb->min = lo, pb->max = hi;
		return API_RANGE;
	}
	*t_end = te->valuedouble;
	return API_OK;
}

/* "band_from_fit": a fit's id, a string of 1 to API_SWEEP_NAME_LEN - 1
 * characters (whether such a fit exists is the daemon's to say). */
static api_err parse_band_from(const cJSON *it, api_sweep_req *req, api_problem *pb)
{
	if (!it)
		return API_OK;
	if (!cJSON_IsString(it))
		return api_fail(pb, API_TYPE, "band_from_fit",
				"band_from_fit must be a fit's id (a string, GET /api/v1/fits)");
	return api_copy_id(pb, "band_from_fit", "a fit's", it->valuestring, req->band_fit,
			   sizeof req->band_fit);
}

api_err api_parse_sweep(const char *body, size_t len, api_sweep_req *req,
			api_problem *pb)
{
	memset(req, 0, sizeof *req);
	cJSON *root = api_parse_body(body, len, api_members_sweep, pb);
	if (!root)
		return pb->code;
	api_err e = api_apply_model(root, &req->spec, pb);
	if (e == API_OK)
		e = api_validate_spec(&req->spec, pb);
	const cJSON *te = cJSON_GetObjectItemCaseSensitive(root, "t_end");
	if (e == API_OK)
		e = parse_t_end(te, &req->spec.scene, &req->t_end, pb);
	const cJSON *beta = cJSON_GetObjectItemCaseSensitive(root, "beta");
	const cJSON *vary = cJSON_GetObjectItemCaseSensitive(root, "vary");
	/* a study that does not vary beta keeps the model's */
	if (e == API_OK && (beta || !vary))
		e = parse_grid(beta, req, pb);
	if (e == API_OK)
		e = parse_rotations(
			cJSON_GetObjectItemCaseSensitive(root, "rotations"),
			req, pb);
	if (e == API_OK)
		e = api_parse_study(vary, cJSON_GetObjectItemCaseSensitive(root, "lhs"),
				    cJSON_GetObjectItemCaseSensitive(root, "seed"), req, pb);
	if (e == API_OK)
		e = parse_band_from(cJSON_GetObjectItemCaseSensitive(root, "band_from_fit"), req,
				    pb);
	cJSON_Delete(root);
	if (e != API_OK) {
		free(req->betas);
		free(req->values);
		req->betas = NULL;
		req->values = NULL;
	}
	return e;
}

/* The table's leading columns: the varied settings (beta alone where the
 * view has no request: a damaged sweep's). */
static int vary_count(const api_sweep_view *v)
{
	return v->req && v->req->nvary > 0 ? v->req->nvary : 1;
}

static const char *vary_name(const api_sweep_view *v, int a)
{
	return v->req && v->req->nvary > 0 ? v->req->vary[a] : "beta";
}

static double vary_value(const api_sweep_view *v, const api_sweep_point *p, int a)
{
	return v->req && v->req->nvary > 0 ? p->vary[a] : p->beta.user;
}

/* A point's model error (sim_model_check): the sweep's scene with the
 * point's varied settings and sense. 0 where the sweep's request is not
 * known. */
static int point_model(const api_sweep_view *v, const api_sweep_point *p, sim_model_error *me)
{
	if (!v->req)
		return 0;
	sim_params pr = v->req->spec.params;
	sim_scene sc = v->req->spec.scene;
	sim_method m = v->req->spec.method;
	pr.beta = p->beta.si;
	for (int a = 0; a < v->req->nvary; a++)
		sim_set_user(&pr, &sc, &m, v->req->vary[a], p->vary[a], NULL, 0);
	pr.rotation = p->rotation;
	sim_model_check(&pr, &sc, me);
	return 1;
}

static void add_point_model(cJSON *po, const api_sweep_view *v, const api_sweep_point *p)
{
	sim_model_error me;
	if (point_model(v, p, &me))
		api_add_model_error(po, &me);
}

static const char *point_state(int s)
{
	static const char *const names[] = {"pending", "running", "done",
					    "failed"};
	return s >= 0 && s <= 3 ? names[s] : "pending";
}

/* The band's head: its level, the fit, the fit's parameters in the band
 * and those the study varies (which leave it). */
static void add_band_head(cJSON *o, const api_sweep_req *req)
{
	cJSON *band = cJSON_AddObjectToObject(o, "band");
	api_add_number(band, "level", 0.95);
	cJSON_AddStringToObject(band, "fit", req->band_fit);
	cJSON *in = cJSON_AddArrayToObject(band, "parameters");
	cJSON *out = cJSON_AddArrayToObject(band, "varied");
	for (int j = 0; j < req->band_src.nfree; j++)
		cJSON_AddItemToArray(req->band_skip[j] ? out : in,
				     cJSON_CreateString(req->band_src.free[j].name));
}

/* One point of sweep v as its object: the varied settings, the rotation,
 * the state and, once measured, v with its bar, steps and band. */
static cJSON *point_object(const api_sweep_view *v, const api_sweep_point *p, int nvary)
{
	cJSON *po = cJSON_CreateObject();
	for (int a = 0; a < nvary; a++)
		api_add_number(po, vary_name(v, a), vary_value(v, p, a));
	cJSON_AddStringToObject(po, "rotation",
				p->rotation == SIM_CW ? "cw" : "ccw");
	cJSON_AddStringToObject(po, "state", point_state(p->state));
	if (p->state == 2) {
		api_add_number(po, "velocity", p->m.transport_velocity);
		api_add_number(po, "uncertainty", p->m.uncertainty);
		cJSON_AddBoolToObject(po, "steady", p->m.steady);
		api_add_number(po, "dt", p->m.dt);
		cJSON_AddNumberToObject(po, "substeps", p->m.substeps);
		api_add_number(po, "step_error", p->m.step_error);
		cJSON_AddBoolToObject(po, "tol_met", p->m.tol_met);
		if (v->req && v->req->band) {
			cJSON *band = cJSON_AddObjectToObject(po, "band");
			api_add_number(band, "lower", p->band[0]);
			api_add_number(band, "upper", p->band[1]);
		}
	} else {
		cJSON_AddNullToObject(po, "velocity");
		cJSON_AddNullToObject(po, "uncertainty");
		cJSON_AddNullToObject(po, "steady");
	}
	cJSON_AddBoolToObject(po, "mirrored", p->mirrored);
	add_point_model(po, v, p);
	if (p->error[0])
		cJSON_AddStringToObject(po, "error", p->error);
	return po;
}

static cJSON *sweep_object(const api_sweep_view *v, int points)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "id", v->id);
	cJSON_AddStringToObject(o, "state", v->state);
	if (v->error && v->error[0])
		cJSON_AddStringToObject(o, "error", v->error);
	api_add_number(o, "total", (double)v->total);
	api_add_number(o, "done", (double)v->done);
	api_add_number(o, "progress",
		       v->total ? (double)v->done / (double)v->total : 1.0);
	api_add_number(o, "t_end", v->t_end);
	int nvary = vary_count(v);
	cJSON *vary = cJSON_AddArrayToObject(o, "vary");
	for (int a = 0; a < nvary; a++) {
		const sim_setting *t = sim_setting_find(vary_name(v, a));
		cJSON *ax = cJSON_CreateObject();
		cJSON_AddStringToObject(ax, "name", vary_name(v, a));
		cJSON_AddStringToObject(ax, "unit", t ? t->unit : "");
		cJSON_AddItemToArray(vary, ax);
	}
	if (v->req && v->req->lhs) {
		api_add_number(o, "lhs", v->req->lhs);
		api_add_number(o, "seed", v->req->seed);
	}
	if (v->req && v->req->band)
		add_band_head(o, v->req);
	if (points) {
		/* the sweep-level reductions: the mirror reduction when it
		 * derived any point (every point's own model reductions are a
		 * session's business) */
		cJSON *red = cJSON_AddArrayToObject(o, "reductions");
		int mirrored = 0;
		for (size_t i = 0; i < v->total; i++)
			mirrored |= v->pt[i].mirrored;
		for (int b = 0; mirrored && sim_reduction_name(b); b++)
			if ((1u << b) == SIM_RED_MIRROR)
				cJSON_AddItemToArray(red, cJSON_CreateString(sim_reduction_name(b)));
	}
	cJSON *pts = points ? cJSON_AddArrayToObject(o, "points") : NULL;
	cJSON *series = points ? cJSON_AddObjectToObject(o, "series") : NULL;
	cJSON *cw = points ? cJSON_AddArrayToObject(series, "cw") : NULL;
	cJSON *ccw = points ? cJSON_AddArrayToObject(series, "ccw") : NULL;
	for (size_t i = 0; points && i < v->total; i++) {
		const api_sweep_point *p = &v->pt[i];
		cJSON *po = point_object(v, p, nvary);
		cJSON_AddItemToArray(pts, po);
		if (p->state == 2) {
			cJSON *pair = cJSON_CreateArray();
			/* [the first varied setting, v] */
			cJSON_AddItemToArray(pair, cJSON_CreateNumber(vary_value(v, p, 0)));
			cJSON_AddItemToArray(
				pair, isfinite(p->m.transport_velocity)
					      ? cJSON_CreateNumber(p->m.transport_velocity)
					      : cJSON_CreateNull());
			cJSON_AddItemToArray(p->rotation == SIM_CW ? cw : ccw,
					     pair);
		}
	}
	api_add_result_links(o, "sweeps", v->id);
	return o;
}

char *api_sweep_json(const api_sweep_view *v)
{
	return api_print_free(sweep_object(v, 1));
}

/* A listing's entry. */
static cJSON *sweep_entry(const void *view)
{
	return sweep_object(view, 0);
}

char *api_sweep_list_json(const api_sweep_view *v, size_t n)
{
	return api_list_json("sweeps", v, n, sizeof *v, sweep_entry);
}

char *api_sweep_csv(const api_sweep_view *v)
{
	api_buf b = {0};
	int nvary = vary_count(v);
	for (int a = 0; a < nvary; a++)
		api_buf_printf(&b, "%s,", vary_name(v, a));
	int band = v->req && v->req->band;
	api_buf_puts(&b, band ? SIM_SWEEP_POINT_COLUMNS ",band_lower,band_upper\n"
			      : SIM_SWEEP_POINT_COLUMNS "\n");
	for (size_t i = 0; i < v->total; i++) {
		const api_sweep_point *p = &v->pt[i];
		int done = p->state == 2;
		for (int a = 0; a < nvary; a++) {
			api_buf_double(&b, vary_value(v, p, a));
			api_buf_put(&b, ",", 1);
		}
		api_buf_puts(&b, p->rotation == SIM_CW ? "cw," : "ccw,");
		if (done && isfinite(p->m.transport_velocity))
			api_buf_double(&b, p->m.transport_velocity);
		api_buf_put(&b, ",", 1);
		if (done && isfinite(p->m.uncertainty))
			api_buf_double(&b, p->m.uncertainty);
		api_buf_puts(&b, !done ? "," : p->m.steady ? ",true" : ",false");
		api_buf_printf(&b, ",%s,", point_state(p->state));
		if (done) {
			api_buf_double(&b, p->m.dt);
			api_buf_printf(&b, ",%d,", p->m.substeps);
			if (isfinite(p->m.step_error))
				api_buf_double(&b, p->m.step_error);
			api_buf_puts(&b, p->m.tol_met ? ",true" : ",false");
		} else {
			api_buf_puts(&b, ",,,");
		}
		sim_model_error me;
		api_buf_model_error(&b, point_model(v, p, &me) ? &me : NULL);
		for (int k = 0; band && k < 2; k++) {
			api_buf_put(&b, ",", 1);
			if (done && isfinite(p->band[k]))
				api_buf_double(&b, p->band[k]);
		}
		api_buf_put(&b, "\n", 1);
	}
	return api_buf_take(&b);
}

char *api_sweep_list_csv(const api_sweep_view *v, size_t n)
{
	api_buf b = {0};
	api_buf_puts(&b, "sweep,state,done,total,t_end\n");
	for (size_t i = 0; i < n; i++) {
		api_buf_printf(&b, "%s,%s,%zu,%zu,", v[i].id, v[i].state, v[i].done, v[i].total);
		api_buf_double(&b, v[i].t_end);
		api_buf_put(&b, "\n", 1);
	}
	return api_buf_take(&b);
}
