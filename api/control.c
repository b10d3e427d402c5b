/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * control.c - the PATCH controls of a session as one table: each row a
 * body member, its API_C_* bit, how it is parsed and how it is echoed.
 * The parser (api_parse_control), its "no change given" message, the
 * members api_parse_body admits (and the OpenAPI document's Control
 * schema, api_members_control), the control event and the worker's apply
 * table (server/session/worker.c, by api_control_id) all read it.
 *
 * Controls are validated against the session's own settings with sim_set
 * on a scratch copy, so the messages and ranges are the core's; a control
 * is all or nothing. Angles are converted to SI once, where they are
 * parsed (api_parse_user_value), and leave here in degrees, as users type
 * them: the "applied" echo shows what was sent, and the end the worker
 * gives a session left at pace "max" without one (worker_control.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"
#include "table.h"

/* One control: parse sets its fields of *c from member it (present);
 * put adds it to an echo object. */
typedef struct control_row {
	const char *member;
	unsigned bit;
	api_err (*parse)(const cJSON *it, const api_spec *spec, const char *name, api_control *c,
			 api_problem *pb);
	void (*put)(cJSON *o, const char *name, const api_control *c);
} control_row;

/* ---- parse ----------------------------------------------------------------- */

static api_err parse_beta(const cJSON *it, const api_spec *spec, const char *name,
			  api_control *c, api_problem *pb)
{
	return api_parse_user_value(spec, name, it, name, &c->beta, pb);
}

static api_err parse_beta_rate(const cJSON *it, const api_spec *spec, const char *name,
			       api_control *c, api_problem *pb)
{
	return api_parse_user_value(spec, name, it, name, &c->beta_rate, pb);
}

static api_err parse_omega_ss(const cJSON *it, const api_spec *spec, const char *name,
			      api_control *c, api_problem *pb)
{
	api_value v = {0, 0};
	api_err e = api_parse_user_value(spec, name, it, name, &v, pb);
	c->omega_ss = v.si;
	return e;
}

/* A disturbance of the column feed (m_n, mu): only a session whose feed is
 * the column model takes one (a LIGGGHTS bed's grains are set at its
 * start; without a feed there is none to change). */
static api_err feed_disturbable(const api_spec *spec, const char *name, api_problem *pb)
{
	if (!spec->scene.feed)
		return api_fail(pb, API_INVALID, name,
				"%s changes the feed of a running session; this session has "
				"no feed (feed = false)", name);
	if (spec->scene.feed_model != SIM_FEED_COLUMN)
		return api_fail(pb, API_INVALID, name,
				"%s changes the column model's feed of a running session; this "
				"session's feed_model is liggghts, whose bed keeps the grains it "
				"started with", name);
	return API_OK;
}

/* A feed control's value (into v) and whether the session's feed takes
 * it. */
static api_err feed_value(const cJSON *it, const api_spec *spec, const char *name, api_value *v,
			  api_problem *pb)
{
	api_err e = api_parse_user_value(spec, name, it, name, v, pb);
	return e == API_OK ? feed_disturbable(spec, name, pb) : e;
}

static api_err parse_m_n(const cJSON *it, const api_spec *spec, const char *name,
			 api_control *c, api_problem *pb)
{
	api_value v = {0, 0};
	api_err e = feed_value(it, spec, name, &v, pb);
	if (e != API_OK)
		return e;
	double lo, hi;
	sim_feed_mass_range(&spec->params, &spec->scene, &spec->method, &lo, &hi);
	if (v.si < lo || v.si > hi) {
		/* narrowed from the table's range: the coupling's side; the
		 * range stated as the detail prints it, within the exact one */
		int light = hi < sim_setting_find(name)->max;
		double lo_shown = api_round_inward(lo, 1, 6), hi_shown = api_round_inward(hi, 0, 6);
		return api_fail_range(pb, name, lo_shown, hi_shown,
				      "m_n must lie in [%.6g, %.6g] kg in this session; got %g: its "
				      "integrator (dem with sub-steps) couples a feed of %s 0.2 of "
				      "the machine's mass %s, and keeps it so", lo_shown, hi_shown,
				      v.si, light ? "at most" : "more than",
				      light ? "with its corrector" : "without it");
	}
	/* and the column's weight on its contacts (sim_m_n_most) */
	double most = sim_m_n_most(&spec->params, &spec->scene);
	if (!(v.si < most)) {
		double hi_shown = api_round_inward(nextafter(most, 0.0), 0, 6);
		return api_fail_range(pb, name, api_round_inward(lo, 1, 6), hi_shown,
				      "m_n must be below %.6g kg in this session; got %g: its column "
				      "of %d layers would rest 5 cm or more into the deck on k_c = "
				      "%g, where the feed model ends", most, v.si, spec->scene.layers,
				      spec->params.k_c);
	}
	c->m_n = v.si;
	return API_OK;
}

static api_err parse_mu(const cJSON *it, const api_spec *spec, const char *name,
			api_control *c, api_problem *pb)
{
	api_value v = {0, 0};
	api_err e = feed_value(it, spec, name, &v, pb);
	c->mu = v.si;
	return e;
}

static api_err parse_rotation(const cJSON *it, const api_spec *spec, const char *name,
			      api_control *c, api_problem *pb)
{
	(void)spec;
	if (!cJSON_IsString(it))
		return api_fail(pb, API_TYPE, name, "rotation must be \"cw\" or \"ccw\"");
	if (strcmp(it->valuestring, "cw") == 0 || strcmp(it->valuestring, "ccw") == 0) {
		c->rotation = it->valuestring[1] == 'w' ? SIM_CW : SIM_CCW;
		return API_OK;
	}
	api_fail(pb, API_RANGE, name, "rotation must be \"cw\" or \"ccw\"");
	snprintf(pb->choices, sizeof pb->choices, "cw|ccw");
	return pb->code;
}

/* A boolean member into *out, or a type error. */
static api_err parse_bool(const cJSON *it, const char *name, int *out, api_problem *pb)
{
	if (!cJSON_IsBool(it))
		return api_fail(pb, API_TYPE, name, "%s must be true or false", name);
	*out = cJSON_IsTrue(it);
	return API_OK;
}

static api_err parse_running(const cJSON *it, const api_spec *spec, const char *name,
			     api_control *c, api_problem *pb)
{
	(void)spec;
	return parse_bool(it, name, &c->running, pb);
}

static api_err parse_motor(const cJSON *it, const api_spec *spec, const char *name,
			   api_control *c, api_problem *pb)
{
	(void)spec;
	return parse_bool(it, name, &c->motor_on, pb);
}

static api_err parse_pace(const cJSON *it, const api_spec *spec, const char *name,
			  api_control *c, api_problem *pb)
{
	(void)spec;
	return api_parse_pace(it, name, &c->pace, pb);
}

static api_err parse_until(const cJSON *it, const api_spec *spec, const char *name,
			   api_control *c, api_problem *pb)
{
	(void)spec;
	return api_parse_real(it, name, 1e-6, 1e6, 1, &c->until, pb);
}

static api_err parse_cpu(const cJSON *it, const api_spec *spec, const char *name,
			 api_control *c, api_problem *pb)
{
	(void)spec;
	/* any number: its range, [API_CPU_BUDGET_MIN, --max-cpu-seconds],
	 * is the daemon's option, checked where the session is admitted */
	return api_parse_real(it, name, -INFINITY, INFINITY, 0, &c->cpu_budget, pb);
}

/* ---- echo (angles as the user sent them) ------------------------------------ */

static void put_beta(cJSON *o, const char *name, const api_control *c)
{
	api_add_number(o, name, c->beta.user);
}

static void put_beta_rate(cJSON *o, const char *name, const api_control *c)
{
	api_add_number(o, name, c->beta_rate.user);
}

static void put_rotation(cJSON *o, const char *name, const api_control *c)
{
	cJSON_AddStringToObject(o, name, c->rotation == SIM_CW ? "cw" : "ccw");
}

static void put_omega_ss(cJSON *o, const char *name, const api_control *c)
{
	api_add_number(o, name, c->omega_ss);
}

static void put_m_n(cJSON *o, const char *name, const api_control *c)
{
	api_add_number(o, name, c->m_n);
}

static void put_mu(cJSON *o, const char *name, const api_control *c)
{
	api_add_number(o, name, c->mu);
}

static void put_running(cJSON *o, const char *name, const api_control *c)
{
	cJSON_AddBoolToObject(o, name, c->running);
}

static void put_motor(cJSON *o, const char *name, const api_control *c)
{
	cJSON_AddBoolToObject(o, name, c->motor_on);
}

static void put_pace(cJSON *o, const char *name, const api_control *c)
{
	if (c->pace == API_PACE_MAX)
		cJSON_AddStringToObject(o, name, "max");
	else
		api_add_number(o, name, c->pace);
}

static void put_until(cJSON *o, const char *name, const api_control *c)
{
	if (c->until > 0)
		api_add_number(o, name, c->until);
	else
		cJSON_AddNullToObject(o, name);
}

static void put_cpu(cJSON *o, const char *name, const api_control *c)
{
	api_add_number(o, name, c->cpu_budget);
}

/* ---- the table ----------------------------------------------------------- */

/* The rows of API_CONTROLS (api.h), in the order the members are parsed,
 * echoed and listed; each id's parse_ and put_ functions are above. */
#define ROW(id, member, bit, fn) [API_CTL_##id] = {member, bit, parse_##fn, put_##fn},
static const control_row controls[API_CTL_COUNT] = {API_CONTROLS(ROW)};
#undef ROW

#define MEMBER(id, member, bit, fn) member,
const char *const api_members_control[API_CTL_COUNT + 1] = {API_CONTROLS(MEMBER) NULL};
#undef MEMBER

api_err api_parse_control(const char *body, size_t len, const api_spec *spec, api_control *c,
			  api_problem *pb)
{
	memset(c, 0, sizeof *c);
	cJSON *root = api_parse_body(body, len, api_members_control, pb);
	if (!root)
		return pb->code;
	api_err e = API_OK;
	if (!root->child) {
		char list[160] = "";
		for (size_t i = 0; i < API_CTL_COUNT; i++) {
			size_t at = strlen(list);
			snprintf(list + at, sizeof list - at, "%s%s", i ? ", " : "",
				 controls[i].member);
		}
		e = api_fail(pb, API_INVALID, NULL, "no change given; expected any of %s", list);
	}
	for (size_t i = 0; i < API_CTL_COUNT && e == API_OK; i++) {
		const cJSON *it = cJSON_GetObjectItemCaseSensitive(root, controls[i].member);
		if (it && (e = controls[i].parse(it, spec, controls[i].member, c, pb)) == API_OK)
			c->set |= controls[i].bit;
	}
	cJSON_Delete(root);
	return e;
}

api_err api_parse_control_event(const char *line, size_t len, const api_spec *spec,
				api_control *c, double *t_effective, char *experiment,
				size_t explen, api_problem *pb)
{
	cJSON *o = cJSON_ParseWithLength(line, len);
	cJSON *te = o ? cJSON_DetachItemFromObjectCaseSensitive(o, "t_effective") : NULL;
	cJSON *ex = o ? cJSON_DetachItemFromObjectCaseSensitive(o, "experiment") : NULL;
	int ok = cJSON_IsObject(o) && cJSON_IsNumber(te) && isfinite(te->valuedouble) &&
		 (!ex || cJSON_IsString(ex));
	*t_effective = ok ? te->valuedouble : 0;
	if (experiment && explen)
		snprintf(experiment, explen, "%s", ok && ex ? ex->valuestring : "");
	cJSON_Delete(te);
	cJSON_Delete(ex);
	char *body = ok ? api_print(o) : NULL;
	cJSON_Delete(o);
	if (!body)
		return api_fail(pb, API_MALFORMED, NULL,
				"a control log line is not a control event "
				"with t_effective");
	api_err e = api_parse_control(body, strlen(body), spec, c, pb);
	free(body);
	return e;
}

cJSON *api_control_object(const api_control *c)
{
	cJSON *o = cJSON_CreateObject();
	for (size_t i = 0; i < API_CTL_COUNT; i++)
		if (c->set & controls[i].bit)
			controls[i].put(o, controls[i].member, c);
	return o;
}

int api_control_event(char *buf, size_t len, const api_control *c, double t_effective)
{
	return api_control_log_line(buf, len, c, t_effective, NULL);
}

int api_control_event_model(char *buf, size_t len, const api_control *c,
			    double t_effective, const sim_model_error *me)
{
	cJSON *o = api_control_object(c);
	api_add_number(o, "t_effective", sim_time_ns(t_effective));
	if (me)
		api_add_model_error(o, me);
	char *text = api_print(o);
	if (me && text && strlen(text) >= len) {
		/* the note goes before the event is cut (a ring slot's size) */
		cJSON_DeleteItemFromObjectCaseSensitive(o, "model_check_note");
		free(text);
		text = api_print(o);
	}
	cJSON_Delete(o);
	int n = snprintf(buf, len, "%s", text ? text : "{}");
	free(text);
	return n < 0 ? 0 : n >= (int)len ? (int)len - 1 : n;
}

int api_control_log_line(char *buf, size_t len, const api_control *c, double t_effective,
			 const char *experiment)
{
	cJSON *o = api_control_object(c);
	api_add_number(o, "t_effective", sim_time_ns(t_effective));
	if (experiment && experiment[0])
		cJSON_AddStringToObject(o, "experiment", experiment);
	char *text = api_print_free(o);
	int n = snprintf(buf, len, "%s", text ? text : "{}");
	free(text);
	return n < 0 ? 0 : n >= (int)len ? (int)len - 1 : n;
}
