/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_json.c - the beta-schedule experiment in JSON.
 *
 * An experiment is the paper's remote reversal test: a schedule of beta
 * set-points ("38 deg until 3 s, then 128 deg until 6 s") run on a fresh
 * or an existing session, reporting per segment the steady transport
 * velocity and the reversal time. This file parses the request and
 * writes the progress and results; the server runs it.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "json_int.h"
#include "table.h"

const char *const api_members_segment[] = {"beta", "until", NULL};
const char *const api_members_experiment_session[] = {"preset", "params", "scene", "integrator",
						       "pace", "sample_rate", NULL};
const char *const api_members_experiment[] = {"session",      "schedule", "identify", "control",
					       "disturbances", "beta_rate", "keep_session", NULL};

static api_err parse_segment(const cJSON *it, int i, double prev,
			     const api_spec *spec, api_segment *seg,
			     api_problem *pb)
{
	char prefix[40], field[48];
	snprintf(prefix, sizeof prefix, "schedule[%d].", i);
	api_err e = api_check_object(it, prefix, prefix, "an object {\"beta\": DEG, \"until\": S}",
				     api_members_segment, pb);
	if (e != API_OK)
		return e;
	const cJSON *beta = cJSON_GetObjectItemCaseSensitive(it, "beta");
	const cJSON *until = cJSON_GetObjectItemCaseSensitive(it, "until");
	snprintf(field, sizeof field, "%sbeta", prefix);
	api_value beta_si;
	e = api_parse_user_value(spec, "beta", beta, field, &beta_si, pb);
	if (e != API_OK)
		return e;
	snprintf(field, sizeof field, "%suntil", prefix);
	if (!cJSON_IsNumber(until))
		return api_fail(pb, API_TYPE, field,
				"%s must be a number (s after the experiment "
				"start)", field);
	if (!(until->valuedouble > prev && until->valuedouble <= 1e4)) {
		return api_fail_range(pb, field, prev, 1e4,
				      "%s must exceed the previous segment's end (%g s) "
				      "and be at most 10000 s", field, prev);
	}
	api_segment_reset(seg, beta_si, until->valuedouble);
	return API_OK;
}

/* "session": the id of an existing session, or a create body for a fresh
 * one (none: a fresh czubak2016 session), which runs at pace "max" unless
 * the body sets a pace. */
static api_err parse_session_member(const cJSON *sess, api_experiment_req *req,
				    api_problem *pb)
{
	if (sess && cJSON_IsString(sess)) {
		api_err e = api_copy_id(pb, "session", "a session's", sess->valuestring,
					req->session_id, sizeof req->session_id);
		if (e != API_OK)
			return e;
		if (sim_preset("czubak2016", &req->spec.params,
			       &req->spec.scene, &req->spec.method) != SIM_OK)
			return api_fail(pb, API_UNAVAILABLE, NULL,
					"the default preset is missing");
		return API_OK;
	}
	if (sess && !cJSON_IsObject(sess))
		return api_fail(pb, API_TYPE, "session",
				"session must be a session id or a session "
				"body object");
	req->fresh = 1;
	cJSON *empty = sess ? NULL : cJSON_CreateObject();
	const cJSON *src = sess ? sess : empty;
	api_err e = api_check_members(src, api_members_experiment_session, "session.", pb);
	if (e == API_OK)
		e = api_apply_model(src, &req->spec, pb);
	if (e == API_OK)
		e = api_apply_session_extras(src, &req->spec, pb);
	if (e == API_OK && !cJSON_GetObjectItemCaseSensitive(src, "pace"))
		req->spec.pace = API_PACE_MAX;
	if (e == API_OK)
		e = api_validate_spec(&req->spec, pb);
	cJSON_Delete(empty);
	if (e != API_OK) /* the member's path in this body: session.scene, not scene */
		api_field_within(pb, "session");
	return e;
}

api_err api_parse_experiment(const char *body, size_t len,
			     api_experiment_req *req, api_exp_ext *ext, api_problem *pb)
{
	memset(req, 0, sizeof *req);
	memset(ext, 0, sizeof *ext);
	cJSON *root = api_parse_body(body, len, api_members_experiment, pb);
	if (!root)
		return pb->code;
	const cJSON *sess = cJSON_GetObjectItemCaseSensitive(root, "session");
	const cJSON *sched = cJSON_GetObjectItemCaseSensitive(root, "schedule");
	const cJSON *rate = cJSON_GetObjectItemCaseSensitive(root, "beta_rate");
	const cJSON *keep =
		cJSON_GetObjectItemCaseSensitive(root, "keep_session");
	api_err e = parse_session_member(sess, req, pb);
	if (e == API_OK && keep && !cJSON_IsBool(keep))
		e = api_fail(pb, API_TYPE, "keep_session",
			     "keep_session must be true or false");
	req->keep_session = cJSON_IsTrue(keep);
	if (e == API_OK && rate)
		e = api_parse_user_value(&req->spec, "beta_rate", rate,
					 "beta_rate", &req->beta_rate, pb);
	if (e == API_OK)
		e = api_parse_experiment_kind(root, req, ext, pb);
	if (e == API_OK && ext->kind != API_EXP_SCHEDULE) {
		if (req->fresh)
			req->spec.until = req->seg[req->nseg - 1].until;
		cJSON_Delete(root);
		return API_OK;
	}
	if (e == API_OK && !cJSON_IsArray(sched))
		e = api_fail(pb, sched ? API_TYPE : API_INVALID, "schedule",
			     "schedule must be an array of {\"beta\": DEG, "
			     "\"until\": S}");
	if (e == API_OK) {
		int n = cJSON_GetArraySize(sched);
		if (n < 1 || n > API_EXP_MAX_SEGMENTS) {
			e = api_fail_range(pb, "schedule", 1, API_EXP_MAX_SEGMENTS,
					   "schedule has %d segments; an experiment takes 1 to %d",
					   n, API_EXP_MAX_SEGMENTS);
		} else {
			double prev = 0;
			int i = 0;
			for (const cJSON *it = sched->child; it && e == API_OK;
			     it = it->next, i++) {
				e = parse_segment(it, i, prev, &req->spec,
						  &req->seg[i], pb);
				prev = req->seg[i].until;
			}
			req->nseg = n;
			if (req->fresh)
				req->spec.until = prev;
		}
	}
	cJSON_Delete(root);
	return e;
}

/* The scene's model error at segment s's beta (sim_model_check); 0 where
 * the session's scene is not known. */
static int segment_model(const api_experiment_view *v, const api_segment *s, sim_model_error *me)
{
	if (!v->spec)
		return 0;
	sim_params p = v->spec->params;
	p.beta = s->beta.si;
	sim_model_check(&p, &v->spec->scene, me);
	return 1;
}

const char *api_segment_state(int state)
{
	static const char *const names[API_SEG_NSTATES] = {"pending", "running", "done",
							   "aborted"};
	return names[state >= 0 && state < API_SEG_NSTATES ? state : API_SEG_PENDING];
}

static cJSON *experiment_object(const api_experiment_view *v)
{
	char link[96];
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "id", v->id);
	cJSON_AddStringToObject(o, "session", v->session_id);
	cJSON_AddStringToObject(o, "state", v->state);
	if (v->error[0])
		cJSON_AddStringToObject(o, "error", v->error);
	api_add_number(o, "t_start", sim_time_ns(v->t_start));
	api_add_number(o, "t", sim_time_ns(v->t_now));
	api_add_number(o, "progress", v->progress);
	cJSON *arr = cJSON_AddArrayToObject(o, "segments");
	for (int i = 0; i < v->nseg; i++) {
		const api_segment *s = &v->seg[i];
		cJSON *so = cJSON_CreateObject();
		api_add_number(so, "beta", s->beta.user);
		api_add_number(so, "until", s->until);
		cJSON_AddStringToObject(so, "state", api_segment_state(s->state));
		api_add_number(so, "t_command", sim_time_ns(s->t_command));
		api_add_number(so, "t_end", sim_time_ns(s->t_end));
		api_add_number(so, "start_velocity", s->start_velocity);
		api_add_number(so, "steady_velocity", s->steady_velocity);
		api_add_number(so, "mean_velocity", s->mean_velocity);
		api_add_number(so, "uncertainty", s->uncertainty);
		if (s->state == API_SEG_DONE)
			cJSON_AddBoolToObject(so, "steady", s->steady);
		else
			cJSON_AddNullToObject(so, "steady");
		api_add_number(so, "reversal_time", sim_time_ns(s->reversal_time));
		sim_model_error me;
		if (segment_model(v, s, &me))
			api_add_model_error(so, &me);
		cJSON_AddItemToArray(arr, so);
	}
	api_add_experiment_kind(o, v->ext, v->nseg);
	cJSON *links = cJSON_AddObjectToObject(o, "links");
	snprintf(link, sizeof link, "/api/v1/experiments/%s", v->id);
	cJSON_AddStringToObject(links, "self", link);
	snprintf(link, sizeof link, "/api/v1/sessions/%s", v->session_id);
	cJSON_AddStringToObject(links, "session", link);
	return o;
}

char *api_experiment_json(const api_experiment_view *v)
{
	return api_print_free(experiment_object(v));
}

/* A listing's entry. */
static cJSON *experiment_entry(const void *view)
{
	return experiment_object(view);
}

char *api_experiment_list_json(const api_experiment_view *v, size_t n)
{
	return api_list_json("experiments", v, n, sizeof *v, experiment_entry);
}

/* A CSV cell: the number, or nothing when not finite. */
static void csv_num(api_buf *b, double v)
{
	api_buf_put(b, ",", 1);
	if (isfinite(v))
		api_buf_double(b, v);
}

/* The kind all n views share (API_EXP_SCHEDULE when they differ). */
static int csv_kind(const api_experiment_view *v, size_t n)
{
	int kind = n && v[0].ext ? v[0].ext->kind : API_EXP_SCHEDULE;
	for (size_t i = 1; i < n; i++)
		if (!v[i].ext || v[i].ext->kind != kind)
			return API_EXP_SCHEDULE;
	return kind;
}

/* The kind's columns of segment k (API_EXPERIMENT_CSV_IDENTIFY or
 * _CONTROL; a closed loop's gains in use at the end of a segment done,
 * t_end s after the start). */
static void csv_kind_cells(api_buf *b, const api_exp_ext *ext, int k, int done, double t_end)
{
	if (ext->kind == API_EXP_IDENTIFY) {
		const api_fopdt *m = &ext->model[k / API_EXP_ID_SEGS];
		double cells[] = {m->beta0, m->k, m->k_se, m->t, m->t_se, m->l, m->l_se};
		for (size_t c = 0; c < sizeof cells / sizeof *cells; c++)
			csv_num(b, cells[c]);
	} else if (ext->kind == API_EXP_CONTROL) {
		const api_setpoint *s = &ext->sp[k];
		double kp = NAN, ki = NAN;
		if (done)
			api_loop_gains_at(ext, t_end, &kp, &ki);
		double cells[] = {s->v, s->settling_time, s->overshoot, s->iae, s->steady_error, kp, ki};
		for (size_t c = 0; c < sizeof cells / sizeof *cells; c++)
			csv_num(b, cells[c]);
	}
}

char *api_experiment_csv(const api_experiment_view *v, size_t n)
{
	api_buf b = {0};
	int kind = csv_kind(v, n);
	api_buf_puts(&b, kind == API_EXP_IDENTIFY  ? API_EXPERIMENT_CSV API_EXPERIMENT_CSV_IDENTIFY "\n"
			 : kind == API_EXP_CONTROL ? API_EXPERIMENT_CSV API_EXPERIMENT_CSV_CONTROL "\n"
						   : API_EXPERIMENT_CSV "\n");
	for (size_t i = 0; i < n; i++)
		for (int k = 0; k < v[i].nseg; k++) {
			const api_segment *g = &v[i].seg[k];
			int done = g->state == API_SEG_DONE;
			api_buf_printf(&b, "%s,%s,%d", v[i].id, v[i].session_id, k + 1);
			csv_num(&b, g->beta.user);
			csv_num(&b, g->until);
			api_buf_printf(&b, ",%s", api_segment_state(g->state));
			csv_num(&b, g->state != API_SEG_PENDING ? sim_time_ns(g->t_command) : NAN);
			csv_num(&b, done ? sim_time_ns(g->t_end) : NAN);
			csv_num(&b, g->state != API_SEG_PENDING ? g->start_velocity : NAN);
			csv_num(&b, done ? g->steady_velocity : NAN);
			csv_num(&b, done ? g->mean_velocity : NAN);
			csv_num(&b, done ? g->uncertainty : NAN);
			api_buf_puts(&b, !done ? "," : g->steady ? ",true" : ",false");
			csv_num(&b, done ? sim_time_ns(g->reversal_time) : NAN);
			sim_model_error me;
			api_buf_model_error(&b, segment_model(&v[i], g, &me) ? &me : NULL);
			if (kind != API_EXP_SCHEDULE)
				csv_kind_cells(&b, v[i].ext, k, done, g->t_end - v[i].t_start);
			api_buf_put(&b, "\n", 1);
		}
	return api_buf_take(&b);
}
