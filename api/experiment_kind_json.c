/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_kind_json.c - the kinds of experiment beyond a beta schedule
 * (docs/control.md): "identify" (steps of beta around operating points, a
 * first-order-plus-dead-time model per point) and "control" (a PI
 * controller on beta holding transport-velocity setpoints) with its
 * "disturbances" (PATCH bodies applied at given times). Each is parsed
 * into api_exp_ext and the segments it runs; the results go back into the
 * experiment's JSON. Checks that need the machine (a setpoint within its
 * reachable range) are the server's, once it has the v(beta) curve.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "json_int.h"
#include "table.h"

const char *const api_members_identify[] = {"beta", "step", "hold", NULL};
const char *const api_members_exp_control[] = {"setpoint", "controller", "tau_c", NULL};
const char *const api_members_setpoint[] = {"v", "until", NULL};
const char *const api_members_controller[] = {"kp", "ki", NULL};
const char *const api_members_disturbance[] = {"at", "set", NULL};

/* The controls a disturbance may not set: beta is the controller's, the
 * rest the session's (its run, not the machine). */
#define DIST_REFUSED (API_C_BETA | API_C_BETA_RATE | API_C_RUNNING | API_C_PACE | API_C_UNTIL | API_C_CPU)

/* The least identify.step, deg. */
#define ID_STEP_MIN 0.1

/* A number member within [lo, hi] (def when absent); 400 for a type, 422
 * for a range naming field. */
static api_err number_in(const cJSON *obj, const char *name, const char *field, double lo,
			 double hi, double def, const char *unit, double *out, api_problem *pb)
{
	const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, name);
	if (!it) {
		*out = def;
		return isnan(def) ? api_fail(pb, API_INVALID, field, "%s is required (%s)", field, unit)
				  : API_OK;
	}
	if (!cJSON_IsNumber(it))
		return api_fail(pb, API_TYPE, field, "%s must be a number (%s)", field, unit);
	double v = it->valuedouble;
	if (!(v >= lo && v <= hi)) {
		return api_fail_range(pb, field, lo, hi, "%s must lie within [%g, %g] %s", field,
				      lo, hi, unit);
	}
	*out = v;
	return API_OK;
}

void api_segment_reset(api_segment *seg, api_value beta, double until)
{
	memset(seg, 0, sizeof *seg);
	seg->beta = beta;
	seg->until = until;
	seg->steady_velocity = seg->mean_velocity = seg->uncertainty = NAN;
	seg->reversal_time = seg->start_velocity = NAN;
	seg->t_command = seg->t_end = NAN;
}

/* Append a segment (beta in SI and as sent, until) to req. */
static void add_segment(api_experiment_req *req, api_value beta, double until)
{
	api_segment_reset(&req->seg[req->nseg++], beta, until);
}

/* An operating point b0 (field) whose step d leaves beta's range: the
 * points this step allows as the range, rounded inward as printed (both
 * taken), and the steps this point allows in the detail when there are. */
static api_err identify_off_range(const char *field, double b0, double d, api_problem *pb)
{
	const sim_setting *b = sim_setting_find("beta");
	double lo = api_round_inward(b->min + d, 1, 6), hi = api_round_inward(b->max - d, 0, 6);
	double out = b0 + d > b->max ? b0 + d : b0 - d;
	double most = fmin(b0 - b->min, b->max - b0);
	char steps[96] = "";
	if (most >= ID_STEP_MIN)
		snprintf(steps, sizeof steps, " (or, at %g deg, a step of %g to %g deg)", b0,
			 ID_STEP_MIN, api_round_inward(most, 0, 6));
	return api_fail_range(pb, field, lo, hi,
			      "%s = %g deg steps to %g deg with identify.step = %g deg, outside "
			      "beta's [%g, %g] deg: with this step an operating point lies in [%g, %g] "
			      "deg%s",
			      field, b0, out, d, b->min, b->max, lo, hi, steps);
}

/* One operating point's segments: settle at beta0, +step, back, -step,
 * back, each hold long. The point's field is identify.beta[i], or
 * identify.beta for a single number (i < 0). */
static api_err identify_point(const cJSON *it, int i, api_experiment_req *req, api_exp_ext *ext,
			      api_problem *pb)
{
	char field[48];
	if (i < 0)
		snprintf(field, sizeof field, "identify.beta");
	else
		snprintf(field, sizeof field, "identify.beta[%d]", i);
	i = i < 0 ? 0 : i;
	if (!cJSON_IsNumber(it))
		return api_fail(pb, API_TYPE, field, "%s must be a number (deg)", field);
	api_value b0, up, down;
	api_err e = api_user_value(&req->spec, "beta", it->valuedouble, field, &b0, pb);
	if (e != API_OK)
		return e;
	double d = ext->id_step;
	if (api_user_value(&req->spec, "beta", b0.user + d, field, &up, pb) != API_OK ||
	    api_user_value(&req->spec, "beta", b0.user - d, field, &down, pb) != API_OK)
		return identify_off_range(field, b0.user, d, pb);
	double t = req->nseg ? req->seg[req->nseg - 1].until : 0, h = ext->id_hold;
	api_fopdt *m = &ext->model[i];
	m->beta0 = b0.user;
	m->step = d;
	m->k = m->k_se = m->t = m->t_se = m->l = m->l_se = m->v0 = m->rms = NAN;
	m->slope = m->t_from = NAN;
	add_segment(req, b0, t + h);
	add_segment(req, up, t + 2 * h);
	add_segment(req, b0, t + 3 * h);
	add_segment(req, down, t + 4 * h);
	add_segment(req, b0, t + 5 * h);
	return API_OK;
}

static api_err parse_identify(const cJSON *id, api_experiment_req *req, api_exp_ext *ext,
			      api_problem *pb)
{
	api_err e = api_check_object(id, "identify", "identify.",
				     "an object {\"beta\": DEG or [DEG, ...], \"step\": DEG, "
				     "\"hold\": S}", api_members_identify, pb);
	if (e == API_OK)
		e = number_in(id, "step", "identify.step", ID_STEP_MIN, 30, 4, "deg",
			      &ext->id_step, pb);
	if (e == API_OK)
		e = number_in(id, "hold", "identify.hold", 0.2, 600, 2, "s", &ext->id_hold, pb);
	if (e != API_OK)
		return e;
	const cJSON *beta = cJSON_GetObjectItemCaseSensitive(id, "beta");
	int n = cJSON_IsArray(beta) ? cJSON_GetArraySize(beta) : 1;
	if (!beta)
		return api_fail(pb, API_INVALID, "identify.beta",
				"identify.beta is required: the operating point(s), deg");
	if (n < 1 || n > API_EXP_MAX_POINTS)
		return api_fail_range(pb, "identify.beta", 1, API_EXP_MAX_POINTS,
				      "identify.beta has %d operating points; an identification takes 1 "
				      "to %d", n, API_EXP_MAX_POINTS);
	ext->kind = API_EXP_IDENTIFY;
	ext->npoints = n;
	const cJSON *it = cJSON_IsArray(beta) ? beta->child : beta;
	for (int i = 0; i < n && e == API_OK; i++, it = it->next)
		e = identify_point(it, cJSON_IsArray(beta) ? i : -1, req, ext, pb);
	return e;
}

/* "controller": "auto" or {"kp": .., "ki": ..}, gains >= 0, not both 0. */
static api_err parse_controller(const cJSON *c, api_exp_ext *ext, api_problem *pb)
{
	if (!c || (cJSON_IsString(c) && strcmp(c->valuestring, "auto") == 0)) {
		ext->auto_gains = 1;
		return API_OK;
	}
	api_err e = api_check_object(c, "control.controller", "control.controller.",
				     "\"auto\" or {\"kp\": DEG_PER_M_S, \"ki\": DEG_PER_M}",
				     api_members_controller, pb);
	if (e == API_OK)
		e = number_in(c, "kp", "control.controller.kp", 0, 1e4, NAN, "deg per m/s",
			      &ext->kp, pb);
	if (e == API_OK)
		e = number_in(c, "ki", "control.controller.ki", 0, 1e5, NAN, "deg per m", &ext->ki,
			      pb);
	if (e == API_OK && ext->kp == 0 && ext->ki == 0)
		e = api_fail(pb, API_INVALID, "control.controller",
			     "control.controller: kp = ki = 0 leaves only the feedforward; give a "
			     "positive kp or ki, or \"auto\"");
	return e;
}

static api_err parse_setpoint(const cJSON *it, int i, api_experiment_req *req, api_exp_ext *ext,
			      api_problem *pb)
{
	char prefix[40], field[48];
	snprintf(prefix, sizeof prefix, "control.setpoint[%d].", i);
	api_err e = api_check_object(it, prefix, prefix, "an object {\"v\": M_S, \"until\": S}",
				     api_members_setpoint, pb);
	double prev = req->nseg ? req->seg[req->nseg - 1].until : 0, v, until;
	snprintf(field, sizeof field, "%sv", prefix);
	if (e == API_OK)
		e = number_in(it, "v", field, -10, 10, NAN, "m/s", &v, pb);
	snprintf(field, sizeof field, "%suntil", prefix);
	if (e == API_OK)
		e = number_in(it, "until", field, 0, 1e4, NAN, "s", &until, pb);
	if (e == API_OK && !(until > prev)) {
		e = api_fail_range(pb, field, prev, 1e4,
				   "%s must exceed the previous setpoint's end (%g s) and be at "
				   "most 10000 s", field, prev);
	}
	if (e != API_OK)
		return e;
	memset(&ext->sp[i], 0, sizeof ext->sp[i]);
	ext->sp[i].v = v;
	ext->sp[i].settling_time = ext->sp[i].overshoot = NAN;
	ext->sp[i].iae = ext->sp[i].steady_error = NAN;
	/* beta: the scene's until the server puts the feedforward's */
	add_segment(req, (api_value){req->spec.params.beta, api_user_of("beta", req->spec.params.beta)},
		    until);
	return API_OK;
}

static api_err parse_control(const cJSON *c, api_experiment_req *req, api_exp_ext *ext,
			     api_problem *pb)
{
	api_err e = api_check_object(c, "control", "control.",
				     "an object {\"setpoint\": [{\"v\": M_S, \"until\": S}, ...], "
				     "\"controller\": \"auto\" or {\"kp\", \"ki\"}}",
				     api_members_exp_control, pb);
	if (e == API_OK)
		e = number_in(c, "tau_c", "control.tau_c", 0, 100, 0, "s", &ext->tau_c, pb);
	if (e == API_OK)
		e = parse_controller(cJSON_GetObjectItemCaseSensitive(c, "controller"), ext, pb);
	if (e != API_OK)
		return e;
	const cJSON *sp = cJSON_GetObjectItemCaseSensitive(c, "setpoint");
	int n = cJSON_GetArraySize(sp);
	if (!cJSON_IsArray(sp))
		return api_fail(pb, sp ? API_TYPE : API_INVALID, "control.setpoint",
				"control.setpoint must be an array of {\"v\": M_S, \"until\": S}");
	if (n < 1 || n > API_EXP_MAX_SEGMENTS)
		return api_fail_range(pb, "control.setpoint", 1, API_EXP_MAX_SEGMENTS,
				      "control.setpoint has %d setpoints; a closed loop takes 1 to %d",
				      n, API_EXP_MAX_SEGMENTS);
	ext->kind = API_EXP_CONTROL;
	int i = 0;
	for (const cJSON *it = sp->child; it && e == API_OK; it = it->next, i++)
		e = parse_setpoint(it, i, req, ext, pb);
	return e;
}

/* The first member of the table that bits holds. */
static const char *control_member(unsigned bits)
{
#define MEMBER_OF(id, member, bit, fn) if (bits & (bit)) return member;
	API_CONTROLS(MEMBER_OF)
#undef MEMBER_OF
	return "";
}

/* One disturbance: its "set" checked as a PATCH body is (the controls'
 * table, so every control there is one), kept as text. */
static api_err parse_disturbance(const cJSON *it, int i, const api_experiment_req *req,
				 api_disturbance *d, api_problem *pb)
{
	char prefix[40], field[64];
	snprintf(prefix, sizeof prefix, "disturbances[%d].", i);
	api_err e = api_check_object(it, prefix, prefix,
				     "an object {\"at\": S, \"set\": {CONTROL: VALUE}}",
				     api_members_disturbance, pb);
	double end = req->seg[req->nseg - 1].until;
	snprintf(field, sizeof field, "%sat", prefix);
	if (e == API_OK)
		e = number_in(it, "at", field, 0, end, NAN, "s (within the experiment)", &d->at, pb);
	if (e != API_OK)
		return e;
	const cJSON *set = cJSON_GetObjectItemCaseSensitive(it, "set");
	snprintf(field, sizeof field, "%sset", prefix);
	char *text = cJSON_IsObject(set) ? cJSON_PrintUnformatted(set) : NULL;
	size_t len = text ? strlen(text) : 0;
	if (cJSON_IsObject(set) && !text)
		return api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
	if (!text || len >= sizeof d->set) {
		cJSON_free(text);
		if (text) /* "{}" is the shortest; it is refused below as no change */
			return api_fail_range(pb, field, 2, API_EXP_DIST_LEN - 1,
					      "%s is %zu bytes as JSON; a disturbance's set takes 2 to "
					      "%d", field, len, API_EXP_DIST_LEN - 1);
		return api_fail(pb, set ? API_TYPE : API_INVALID, field,
				"%s must be an object of session controls (as a PATCH body, at most "
				"%d bytes as JSON)", field, API_EXP_DIST_LEN - 1);
	}
	snprintf(d->set, sizeof d->set, "%s", text);
	cJSON_free(text);
	api_control c;
	api_problem sub;
	if (api_parse_control(d->set, strlen(d->set), &req->spec, &c, &sub) != API_OK) {
		*pb = sub;
		/* the member at fault, or the set itself ({}: no change) */
		snprintf(pb->field, sizeof pb->field, "%.22s%s%.40s", field,
			 sub.field[0] ? "." : "", sub.field);
		snprintf(pb->detail, sizeof pb->detail, "%.24s: %.280s", field, sub.detail);
		return pb->code;
	}
	if (c.set & DIST_REFUSED) {
		snprintf(field, sizeof field, "%sset.%s", prefix, control_member(c.set & DIST_REFUSED));
		return api_fail(pb, API_INVALID, field,
				"%s: a disturbance changes the machine, not beta (the controller's) "
				"nor the session's run", field);
	}
	d->t_applied = d->recovery_time = d->max_deviation = NAN;
	return API_OK;
}

static api_err parse_disturbances(const cJSON *arr, const api_experiment_req *req,
				  api_exp_ext *ext, api_problem *pb)
{
	if (!arr)
		return API_OK;
	if (ext->kind != API_EXP_CONTROL)
		return api_fail(pb, API_INVALID, "disturbances",
				"disturbances belong to a closed-loop experiment (\"control\")");
	int n = cJSON_GetArraySize(arr);
	if (!cJSON_IsArray(arr))
		return api_fail(pb, API_TYPE, "disturbances",
				"disturbances must be an array of {\"at\": S, \"set\": {...}}");
	if (n > API_EXP_MAX_DIST)
		return api_fail_range(pb, "disturbances", 0, API_EXP_MAX_DIST,
				      "disturbances has %d entries; a closed loop takes 0 to %d", n,
				      API_EXP_MAX_DIST);
	api_err e = API_OK;
	int i = 0;
	for (const cJSON *it = arr->child; it && e == API_OK; it = it->next, i++) {
		e = parse_disturbance(it, i, req, &ext->dist[i], pb);
		if (e == API_OK && i > 0 && ext->dist[i].at < ext->dist[i - 1].at)
			e = api_fail(pb, API_INVALID, "disturbances",
				     "disturbances must be in the order of their \"at\"");
	}
	ext->ndist = n;
	return e;
}

api_err api_parse_experiment_kind(const cJSON *root, api_experiment_req *req,
				  api_exp_ext *ext, api_problem *pb)
{
	memset(ext, 0, sizeof *ext);
	const cJSON *id = cJSON_GetObjectItemCaseSensitive(root, "identify");
	const cJSON *ctl = cJSON_GetObjectItemCaseSensitive(root, "control");
	const cJSON *sched = cJSON_GetObjectItemCaseSensitive(root, "schedule");
	/* a kind given as something else than an object (null too) is its
	 * type error, before the choice between the kinds */
	if (id && !cJSON_IsObject(id))
		return parse_identify(id, req, ext, pb);
	if (ctl && !cJSON_IsObject(ctl))
		return parse_control(ctl, req, ext, pb);
	if (!!id + !!ctl + !!sched > 1)
		return api_fail(pb, API_INVALID, id && ctl ? "control" : "schedule",
				"an experiment is one of schedule, identify or control");
	api_err e = API_OK;
	if (id)
		e = parse_identify(id, req, ext, pb);
	else if (ctl)
		e = parse_control(ctl, req, ext, pb);
	if (e == API_OK)
		e = parse_disturbances(cJSON_GetObjectItemCaseSensitive(root, "disturbances"), req,
				       ext, pb);
	return e;
}

void api_loop_gains_at(const api_exp_ext *x, double t, double *kp, double *ki)
{
	*kp = x->kp, *ki = x->ki;
	for (int i = 0; i < x->gains.n && i < API_EXP_MAX_CURVES; i++)
		if (x->gains.curves[i].t <= t)
			*kp = x->gains.curves[i].kp, *ki = x->gains.curves[i].ki;
}

/* ---- the results ----------------------------------------------------------- */

static cJSON *model_object(const api_fopdt *m)
{
	cJSON *o = cJSON_CreateObject();
	api_add_number(o, "beta0", m->beta0);
	api_add_number(o, "step", m->step);
	api_add_number(o, "gain", m->k);
	api_add_number(o, "gain_se", m->k_se);
	api_add_number(o, "time_constant", m->t);
	api_add_number(o, "time_constant_se", m->t_se);
	api_add_number(o, "dead_time", m->l);
	api_add_number(o, "dead_time_se", m->l_se);
	api_add_number(o, "v0", m->v0);
	api_add_number(o, "rms", m->rms);
	api_add_number(o, "slope", m->slope);
	api_add_number(o, "t_from", m->t_from);
	cJSON_AddNumberToObject(o, "samples", m->n);
	return o;
}

static void add_control(cJSON *o, const api_exp_ext *ext, int nseg)
{
	cJSON *c = cJSON_AddObjectToObject(o, "control");
	cJSON *g = cJSON_AddObjectToObject(c, "controller");
	cJSON_AddStringToObject(g, "tuning", ext->auto_gains ? "simc" : "given");
	api_add_number(g, "kp", ext->kp);
	api_add_number(g, "ki", ext->ki);
	if (ext->auto_gains) {
		api_add_number(g, "tau_c", ext->tau_c);
		cJSON_AddItemToObject(g, "identification", model_object(&ext->tuned));
	}
	api_add_number(c, "period", ext->period);
	cJSON *r = cJSON_AddObjectToObject(c, "reachable");
	api_add_number(r, "v_min", ext->v_lo);
	api_add_number(r, "v_max", ext->v_hi);
	api_add_number(r, "beta_min", ext->nff ? api_user_of("beta", ext->beta_lo) : NAN);
	api_add_number(r, "beta_max", ext->nff ? api_user_of("beta", ext->beta_hi) : NAN);
	cJSON_AddNumberToObject(c, "curve_changes", ext->curve_changes);
	cJSON *cv = cJSON_AddArrayToObject(c, "curves");
	for (int i = 0; i < ext->gains.n && i < API_EXP_MAX_CURVES; i++) {
		const api_curve_change *k = &ext->gains.curves[i];
		cJSON *ko = cJSON_CreateObject();
		api_add_number(ko, "t", k->t);
		cJSON_AddStringToObject(ko, "rotation", k->rotation == SIM_CCW ? "ccw" : "cw");
		api_add_number(ko, "omega_ss", k->omega_ss);
		api_add_number(ko, "beta0", k->beta0);
		api_add_number(ko, "slope", k->slope);
		cJSON_AddBoolToObject(ko, "retuned", k->retuned);
		api_add_number(ko, "kp", k->kp);
		api_add_number(ko, "ki", k->ki);
		cJSON_AddItemToArray(cv, ko);
	}
	cJSON *arr = cJSON_AddArrayToObject(c, "setpoints");
	for (int i = 0; i < nseg; i++) {
		const api_setpoint *s = &ext->sp[i];
		cJSON *so = cJSON_CreateObject();
		api_add_number(so, "v", s->v);
		api_add_number(so, "settling_time", s->settling_time);
		api_add_number(so, "overshoot", s->overshoot);
		api_add_number(so, "iae", s->iae);
		api_add_number(so, "steady_error", s->steady_error);
		cJSON_AddItemToArray(arr, so);
	}
	arr = cJSON_AddArrayToObject(c, "disturbances");
	for (int i = 0; i < ext->ndist; i++) {
		const api_disturbance *d = &ext->dist[i];
		cJSON *dobj = cJSON_CreateObject();
		api_add_number(dobj, "at", d->at);
		cJSON *set = cJSON_Parse(d->set);
		cJSON_AddItemToObject(dobj, "set", set ? set : cJSON_CreateObject());
		api_add_number(dobj, "t_applied", sim_time_ns(d->t_applied));
		api_add_number(dobj, "recovery_time", d->recovery_time);
		api_add_number(dobj, "max_deviation", d->max_deviation);
		cJSON_AddItemToArray(arr, dobj);
	}
}

void api_add_experiment_kind(cJSON *o, const api_exp_ext *ext, int nseg)
{
	if (!ext || ext->kind == API_EXP_SCHEDULE)
		return;
	if (ext->kind == API_EXP_IDENTIFY) {
		cJSON_AddStringToObject(o, "kind", "identify");
		cJSON *id = cJSON_AddObjectToObject(o, "identify");
		api_add_number(id, "step", ext->id_step);
		api_add_number(id, "hold", ext->id_hold);
		cJSON *arr = cJSON_AddArrayToObject(id, "models");
		for (int i = 0; i < ext->npoints; i++)
			cJSON_AddItemToArray(arr, model_object(&ext->model[i]));
		return;
	}
	cJSON_AddStringToObject(o, "kind", "control");
	add_control(o, ext, nseg);
}
