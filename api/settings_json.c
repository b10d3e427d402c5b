/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * settings_json.c - JSON members to the core's named settings and back.
 *
 * The core's sim_settings() table is the single source of names, groups,
 * kinds, units and ranges. A member {"k_s1": 444132} of "params" is looked
 * up there, type-checked against the setting's kind (400 on a wrong JSON
 * type) and handed to sim_set/sim_set_str, whose message names the field
 * and its range (422). Also parses the whole POST /sessions body.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"
#include "table.h"

const char *const api_members_session_create[] = {"preset", "params", "scene", "integrator",
						   "pace", "until", "sample_rate", NULL};
#include "units.h"

/* The ranges of a session's pace (a real-time factor; or "max"), until
 * (s; or none) and sample_rate (1/s): the parsers and api_check_spec. */
#define PACE_MIN API_PACE_MIN
#define PACE_MAX 1000.0
#define UNTIL_MIN 1e-6
#define UNTIL_MAX 1e6
#define RATE_MIN 1.0
#define RATE_MAX API_SAMPLE_RATE_MAX

/* The name of choice idx in "a|b|c" into out; 0 if there is none. */
static int choice_name(const char *choices, int idx, char *out, size_t len)
{
	const char *p = choices;
	for (int i = 0; p && *p; i++) {
		const char *bar = strchr(p, '|');
		size_t n = bar ? (size_t)(bar - p) : strlen(p);
		if (i == idx && n < len) {
			memcpy(out, p, n);
			out[n] = '\0';
			return 1;
		}
		p = bar ? bar + 1 : NULL;
	}
	return 0;
}

/* " (unit)" for a "must be a number" message, or "" for a setting
 * without a unit (scene.columns): no empty brackets. */
static const char *unit_note(const sim_setting *set, char *out, size_t len)
{
	if (!set || !set->unit || !set->unit[0])
		return "";
	snprintf(out, len, " (%s)", set->unit);
	return out;
}

static api_err from_sim_set(int rc, const char *field, const char *msg,
			    api_problem *pb)
{
	if (rc == SIM_OK)
		return API_OK;
	return api_fail(pb, api_from_sim(rc), field, "%s",
			msg[0] ? msg : sim_strerror(rc));
}

api_err api_apply_setting(sim_params *p, sim_scene *s, sim_method *m,
			  const char *group, const cJSON *item,
			  api_problem *pb)
{
	char field[64], msg[256] = "", unit[32];
	const char *name = item->string ? item->string : "";
	snprintf(field, sizeof field, "%s.%s", group, name);
	const sim_setting *set = api_setting(group, name);
	if (!set) {
		if (strcmp(group, "integrator") == 0 &&
		    strcmp(name, "method") == 0 && cJSON_IsString(item))
			return from_sim_set(sim_set_str(p, s, m, name,
							item->valuestring,
							msg, sizeof msg),
					    field, msg, pb);
		const sim_setting *other = api_setting(NULL, name);
		if (other)
			return api_fail(pb, API_UNKNOWN, field,
					"%s is not a %s setting; it belongs "
					"to \"%s\"", name, group, other->group);
		return api_fail(pb, API_UNKNOWN, field,
				"unknown %s setting \"%s\"", group, name);
	}
	int rc;
	switch (set->kind) {
	case SIM_KIND_REAL:
	case SIM_KIND_INT:
		if (!cJSON_IsNumber(item))
			return api_fail(pb, API_TYPE, field,
					"%s must be a number%s", field,
					unit_note(set, unit, sizeof unit));
		if (set->kind == SIM_KIND_INT &&
		    item->valuedouble != floor(item->valuedouble))
			return api_fail(pb, API_RANGE, field,
					"%s must be an integer in [%g, %g]",
					field, set->min, set->max);
		rc = sim_set_user(p, s, m, name, item->valuedouble, msg, sizeof msg);
		break;
	case SIM_KIND_BOOL:
		if (cJSON_IsBool(item))
			rc = sim_set(p, s, m, name, cJSON_IsTrue(item) ? 1 : 0,
				     msg, sizeof msg);
		else
			return api_fail(pb, API_TYPE, field,
					"%s must be true or false", field);
		break;
	case SIM_KIND_ENUM:
		if (cJSON_IsString(item))
			rc = sim_set_str(p, s, m, name, item->valuestring, msg,
					 sizeof msg);
		else
			return api_fail(pb, API_TYPE, field,
					"%s must be one of the strings %s",
					field, set->choices ? set->choices : "");
		break;
	default:
		return api_fail(pb, API_INVALID, field, "%s cannot be set",
				field);
	}
	return from_sim_set(rc, field, msg, pb);
}

api_err api_user_value(const api_spec *spec, const char *name, double user,
		       const char *field, api_value *out, api_problem *pb)
{
	const sim_setting *set = sim_setting_find(name);
	if (!set)
		return api_fail(pb, API_UNKNOWN, field, "unknown setting \"%s\"",
				name);
	double si = sim_setting_to_si(set, user);
	sim_params p = spec->params;
	sim_scene s = spec->scene;
	sim_method m = spec->method;
	char msg[256] = "";
	int rc = sim_set(&p, &s, &m, name, si, msg, sizeof msg);
	if (rc != SIM_OK) {
		/* the range comes with the setting's name; the field is the
		 * member's path */
		if (!msg[0])
			snprintf(msg, sizeof msg, "%s", sim_strerror(rc));
		if (strcmp(field, name) == 0)
			api_fail(pb, api_from_sim(rc), name, "%s", msg);
		else
			api_fail(pb, api_from_sim(rc), name, "%s: %s", field, msg);
		snprintf(pb->field, sizeof pb->field, "%s", field);
		return pb->code;
	}
	out->si = si;
	out->user = user;
	return API_OK;
}

api_err api_parse_user_value(const api_spec *spec, const char *name,
			     const cJSON *it, const char *field,
			     api_value *out, api_problem *pb)
{
	if (!cJSON_IsNumber(it)) {
		char unit[32];
		return api_fail(pb, API_TYPE, field, "%s must be a number%s", field,
				unit_note(sim_setting_find(name), unit, sizeof unit));
	}
	return api_user_value(spec, name, it->valuedouble, field, out, pb);
}

double api_user_of(const char *name, double si)
{
	return sim_table_user(name, si); /* rounded as the trajectories are */
}

api_err api_apply_model(const cJSON *obj, api_spec *spec, api_problem *pb)
{
	static const char *const groups[] = {"params", "scene", "integrator"};
	const char *preset = "czubak2016";
	const cJSON *pr = cJSON_GetObjectItemCaseSensitive(obj, "preset");
	/* null is no value of these members (a wrong type, as 5 is), not
	 * their absence: leaving a member out is how a default is asked for */
	if (pr) {
		if (!cJSON_IsString(pr))
			return api_fail(pb, API_TYPE, "preset",
					"preset must be a string, a preset's name (%s "
					"when left out)", preset);
		preset = pr->valuestring;
	}
	if (sim_preset(preset, &spec->params, &spec->scene, &spec->method) !=
	    SIM_OK) {
		api_fail(pb, API_RANGE, "preset", "unknown preset \"%.60s\"",
			 preset);
		size_t at = 0;
		for (int i = 0; sim_preset_names[i]; i++)
			at += (size_t)snprintf(pb->choices + at,
					       at < sizeof pb->choices
						       ? sizeof pb->choices - at
						       : 0,
					       "%s%s", i ? "|" : "",
					       sim_preset_names[i]);
		return API_RANGE;
	}
	snprintf(spec->preset, sizeof spec->preset, "%s", preset);
	for (size_t g = 0; g < 3; g++) {
		const cJSON *grp =
			cJSON_GetObjectItemCaseSensitive(obj, groups[g]);
		if (!grp)
			continue;
		if (!cJSON_IsObject(grp))
			return api_fail(pb, API_TYPE, groups[g],
					"%s must be an object of NAME: VALUE",
					groups[g]);
		for (const cJSON *it = grp->child; it; it = it->next) {
			api_err e = api_apply_setting(&spec->params,
						      &spec->scene,
						      &spec->method, groups[g],
						      it, pb);
			if (e != API_OK)
				return e;
		}
	}
	return API_OK;
}

cJSON *api_settings_object(const sim_params *p, const sim_scene *s,
			   const sim_method *m, const char *group)
{
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	cJSON *o = cJSON_CreateObject();
	int has_method = 0;
	for (size_t i = 0; tab && i < n; i++) {
		if (strcmp(tab[i].group, group) != 0)
			continue;
		double v = NAN;
		if (sim_get_user(p, s, m, tab[i].name, &v) != SIM_OK)
			continue;
		if (strcmp(tab[i].name, "method") == 0)
			has_method = 1;
		char name[48];
		if (tab[i].kind == SIM_KIND_BOOL)
			cJSON_AddBoolToObject(o, tab[i].name, v != 0);
		else if (tab[i].kind == SIM_KIND_ENUM && tab[i].choices &&
			 choice_name(tab[i].choices, (int)v, name, sizeof name))
			cJSON_AddStringToObject(o, tab[i].name, name);
		else
			api_add_number(o, tab[i].name, v);
	}
	if (strcmp(group, "integrator") == 0 && !has_method)
		cJSON_AddStringToObject(o, "method", m->name);
	return o;
}

/* pace: a positive real-time factor or "max". */
api_err api_parse_pace(const cJSON *it, const char *field, double *pace,
			  api_problem *pb)
{
	if (cJSON_IsString(it)) {
		if (strcmp(it->valuestring, "max") == 0) {
			*pace = API_PACE_MAX;
			return API_OK;
		}
		return api_fail_range(pb, field, 0.001, 1000,
				      "%s must be a real-time factor in [0.001, 1000] or "
				      "\"max\"", field);
	}
	if (!cJSON_IsNumber(it))
		return api_fail(pb, API_TYPE, field,
				"%s must be a number or \"max\"", field);
	double v = it->valuedouble;
	if (!(v >= PACE_MIN && v <= PACE_MAX)) {
		return api_fail_range(pb, field, 0.001, 1000,
				      "%s must be a real-time factor in [0.001, 1000] or "
				      "\"max\"", field);
	}
	*pace = v;
	return API_OK;
}

/* A positive number within [lo, hi] (null allowed when null_ok: 0). */
api_err api_parse_real(const cJSON *it, const char *field, double lo,
			  double hi, int null_ok, double *out,
			  api_problem *pb)
{
	if (null_ok && cJSON_IsNull(it)) {
		*out = 0;
		return API_OK;
	}
	if (!cJSON_IsNumber(it))
		return api_fail(pb, API_TYPE, field, "%s must be a number",
				field);
	if (!(it->valuedouble >= lo && it->valuedouble <= hi)) {
		return api_fail_range(pb, field, lo, hi, "%s must lie in [%g, %g]", field,
				      lo, hi);
	}
	*out = it->valuedouble;
	return API_OK;
}

/* Members of a session body besides the model settings. */
api_err api_apply_session_extras(const cJSON *root, api_spec *spec,
				 api_problem *pb)
{
	const cJSON *it;
	api_err e;
	spec->pace = 1.0;
	spec->until = 0;
	spec->sample_rate = API_DEFAULT_SAMPLE_RATE;
	if ((it = cJSON_GetObjectItemCaseSensitive(root, "pace")) &&
	    (e = api_parse_pace(it, "pace", &spec->pace, pb)) != API_OK)
		return e;
	if ((it = cJSON_GetObjectItemCaseSensitive(root, "until")) &&
	    (e = api_parse_real(it, "until", UNTIL_MIN, UNTIL_MAX, 1, &spec->until, pb)) !=
		    API_OK)
		return e;
	if ((it = cJSON_GetObjectItemCaseSensitive(root, "sample_rate")) &&
	    (e = api_parse_real(it, "sample_rate", RATE_MIN, RATE_MAX, 0,
			    &spec->sample_rate, pb)) != API_OK)
		return e;
	if (spec->pace == API_PACE_MAX && spec->until == 0)
		spec->until = API_DEFAULT_MAX_UNTIL;
	return API_OK;
}

/* The model's settings together (sim_validate), for a session or a job. */
static api_err validate_model(api_spec *spec, api_problem *pb)
{
	char msg[256] = "";
	int rc = sim_validate(&spec->params, &spec->scene, &spec->method, msg,
			      sizeof msg);
	if (rc == SIM_OK)
		return API_OK;
	/* the one check that depends on other settings: dt against the
	 * method's stability bound, which the problem gives as the range
	 * (when nothing else is wrong: the default step always passes) */
	sim_method m0 = spec->method;
	m0.dt = 0.0;
	double bound = sim_max_dt(&spec->params, &spec->scene, &spec->method);
	if (spec->method.dt > bound &&
	    sim_validate(&spec->params, &spec->scene, &m0, NULL, 0) == SIM_OK) {
		return api_fail_range(pb, "integrator.dt", 0.0, bound, "%s", msg);
	}
	/* and the springs the weights ask for: the eliminators' (sim_k_s_least)
	 * and the column's contacts (sim_k_c_least), each range from that
	 * least stiffness to the setting's maximum (N/m: SI and the user's) */
	const struct {
		const char *name, *field;
		double least;
	} soft[] = {
		{"k_s1", "params.k_s1", sim_k_s_least(&spec->params, 1)},
		{"k_s2", "params.k_s2", sim_k_s_least(&spec->params, 2)},
		{"k_c", "params.k_c", sim_k_c_least(&spec->params, &spec->scene)},
	};
	for (size_t k = 0; k < sizeof soft / sizeof soft[0]; k++) {
		const sim_setting *t = sim_setting_find(soft[k].name);
		double given = NAN;
		sim_get(&spec->params, &spec->scene, &spec->method, soft[k].name, &given);
		if (!(soft[k].least >= given) || !(soft[k].least < t->max))
			continue;
		api_spec stiff = *spec;
		if (sim_set(&stiff.params, &stiff.scene, &stiff.method, soft[k].name, t->max, NULL,
			    0) == SIM_OK &&
		    sim_validate(&stiff.params, &stiff.scene, &stiff.method, NULL, 0) == SIM_OK)
			return api_fail_range(pb, soft[k].field, fmax(soft[k].least, t->min), t->max,
					      "%s", msg);
	}
	return api_fail(pb, api_from_sim(rc), NULL, "%s", msg[0] ? msg : sim_strerror(rc));
}

api_err api_validate_spec(api_spec *spec, api_problem *pb)
{
	/* a LIGGGHTS bed is a process of its own per session (the daemon's
	 * bed process, docs/dem.md): sweeps, fits and experiments, which run
	 * many scenes at once, take the column model only */
	if (spec->scene.feed_model != SIM_FEED_COLUMN) {
		char column[16];
		return api_fail_choices(pb, API_RANGE, "scene.feed_model",
					api_choices_of("feed_model", 1u << SIM_FEED_COLUMN, column,
						       sizeof column),
					"scene.feed_model must be column in sweeps, fits and "
					"experiments; liggghts and auto run as a session (POST "
					"/api/v1/sessions) or in `convsim run` (docs/dem.md, "
					"docs/feed-models.md)");
	}
	return validate_model(spec, pb);
}

api_err api_parse_session(const char *body, size_t len, api_spec *spec,
			  api_problem *pb)
{
	memset(spec, 0, sizeof *spec);
	cJSON *root = api_parse_body(body, len, api_members_session_create, pb);
	if (!root)
		return pb->code;
	api_err e = api_apply_model(root, spec, pb);
	if (e == API_OK)
		e = api_apply_session_extras(root, spec, pb);
	/* a session may take feed_model liggghts: the daemon says whether it
	 * can run its bed (server/session/session_dem.c) */
	if (e == API_OK)
		e = validate_model(spec, pb);
	cJSON_Delete(root);
	return e;
}

/* api_check_spec's first part: the names are strings, the preset known. */
static api_err check_names(const api_spec *spec, api_problem *pb)
{
	if (!memchr(spec->preset, '\0', sizeof spec->preset) ||
	    !memchr(spec->method.name, '\0', sizeof spec->method.name))
		return api_fail(pb, API_INVALID, NULL, "the preset or method name is not a string");
	sim_params p;
	sim_scene sc;
	sim_method m;
	if (sim_preset(spec->preset, &p, &sc, &m) != SIM_OK)
		return api_fail(pb, API_RANGE, "preset", "unknown preset \"%.31s\"", spec->preset);
	return API_OK;
}

/* api_check_spec's last part: every setting in its range, the set valid. */
static api_err check_settings(const api_spec *spec, api_problem *pb)
{
	/* every setting in its range (sim_validate leaves some unused ones,
	 * such as atol for a fixed step, unchecked; a request cannot set them
	 * out of range either) */
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	api_spec scratch = *spec, copy = *spec;
	for (size_t i = 0; i < n; i++) {
		double v = NAN;
		char msg[256] = "";
		if (strcmp(tab[i].name, "method") != 0 && /* a name: sim_validate checks it */
		    sim_get(&spec->params, &spec->scene, &spec->method, tab[i].name, &v) == SIM_OK &&
		    sim_set(&scratch.params, &scratch.scene, &scratch.method, tab[i].name, v, msg,
			    sizeof msg) != SIM_OK)
			return api_fail(pb, API_RANGE, tab[i].name, "%s", msg);
	}
	return validate_model(&copy, pb);
}

api_err api_check_model(const api_spec *spec, api_problem *pb)
{
	api_err e = check_names(spec, pb);
	return e != API_OK ? e : check_settings(spec, pb);
}

api_err api_check_spec(const api_spec *spec, api_problem *pb)
{
	api_err e = check_names(spec, pb);
	if (e != API_OK)
		return e;
	if (!(spec->pace == API_PACE_MAX || (spec->pace >= PACE_MIN && spec->pace <= PACE_MAX)))
		return api_fail(pb, API_RANGE, "pace", "pace %g is no real-time factor in [%g, %g]",
				spec->pace, PACE_MIN, PACE_MAX);
	if (!(spec->until == 0 || (spec->until >= UNTIL_MIN && spec->until <= UNTIL_MAX)))
		return api_fail(pb, API_RANGE, "until", "until %g lies outside [%g, %g] s",
				spec->until, UNTIL_MIN, UNTIL_MAX);
	if (spec->pace == API_PACE_MAX && spec->until == 0)
		return api_fail(pb, API_INVALID, "until", "pace \"max\" without until (the parser "
				"gives it %g s)", API_DEFAULT_MAX_UNTIL);
	if (!(spec->sample_rate >= RATE_MIN && spec->sample_rate <= RATE_MAX))
		return api_fail(pb, API_RANGE, "sample_rate", "sample_rate %g lies outside [%g, %g]",
				spec->sample_rate, RATE_MIN, RATE_MAX);
	return check_settings(spec, pb);
}
