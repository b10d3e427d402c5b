/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * openapi.c - the OpenAPI 3.1 description of the HTTP API, served at
 * /api/v1/openapi.json, generated from the tables the daemon validates
 * with:
 *   - paths, their query parameters, request bodies, success and problem
 *     responses from the route table (api/routes.c), which the server
 *     checks every request against;
 *   - the "params", "scene" and "integrator" schemas from the core's
 *     settings table (names, kinds, units, ranges, defaults);
 *   - each request body's members from the very lists its parser accepts
 *     (closed: additionalProperties false);
 *   - the response and stream-record schemas from api/schemas.json
 *     (embedded at build time), which tests/http/openapi.test.mjs checks
 *     against live responses and stream records.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_routes.h"
#include "json_int.h"
#include "units.h"

static const char schemas_text[] =
#include "schemas.inc"
	;

/* A JSON Schema object for one group of the settings table, with the
 * czubak2016 preset's values as defaults. */
static cJSON *group_schema(const char *group)
{
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	sim_params pp;
	sim_scene ps;
	sim_method pm;
	cJSON *defaults = sim_preset("czubak2016", &pp, &ps, &pm) == SIM_OK
				  ? api_settings_object(&pp, &ps, &pm, group)
				  : NULL;
	cJSON *schema = cJSON_CreateObject();
	cJSON_AddStringToObject(schema, "type", "object");
	cJSON_AddBoolToObject(schema, "additionalProperties", 0);
	cJSON *props = cJSON_AddObjectToObject(schema, "properties");
	for (size_t i = 0; tab && i < n; i++) {
		if (strcmp(tab[i].group, group) != 0)
			continue;
		cJSON *p = cJSON_CreateObject();
		switch (tab[i].kind) {
		case SIM_KIND_BOOL:
			cJSON_AddStringToObject(p, "type", "boolean");
			break;
		case SIM_KIND_ENUM: {
			cJSON *e = cJSON_AddArrayToObject(p, "enum");
			char choices[256];
			snprintf(choices, sizeof choices, "%s",
				 tab[i].choices ? tab[i].choices : "");
			char *save = NULL;
			for (char *t = strtok_r(choices, "|", &save); t;
			     t = strtok_r(NULL, "|", &save))
				cJSON_AddItemToArray(e, cJSON_CreateString(t));
			break;
		}
		default:
			cJSON_AddStringToObject(p, "type",
						tab[i].kind == SIM_KIND_INT
							? "integer"
							: "number");
			api_add_number(p, "minimum", tab[i].min);
			api_add_number(p, "maximum", tab[i].max);
		}
		char desc[320];
		snprintf(desc, sizeof desc, "%s%s%s%s",
			 tab[i].doc ? tab[i].doc : "",
			 tab[i].unit && tab[i].unit[0] ? " [" : "",
			 tab[i].unit ? tab[i].unit : "",
			 tab[i].unit && tab[i].unit[0] ? "]" : "");
		cJSON_AddStringToObject(p, "description", desc);
		const cJSON *dv = cJSON_GetObjectItemCaseSensitive(defaults,
								   tab[i].name);
		if (dv && !cJSON_IsNull(dv))
			cJSON_AddItemToObject(p, "default",
					      cJSON_Duplicate(dv, 1));
		cJSON_AddItemToObject(props, tab[i].name, p);
	}
	cJSON_Delete(defaults);
	if (strcmp(group, "integrator") == 0 &&
	    !cJSON_GetObjectItemCaseSensitive(props, "method")) {
		size_t nm = 0;
		const sim_method_info *const *mi = sim_methods(&nm);
		cJSON *p = cJSON_CreateObject();
		cJSON *e = cJSON_AddArrayToObject(p, "enum");
		for (size_t i = 0; mi && i < nm; i++)
			cJSON_AddItemToArray(e, cJSON_CreateString(mi[i]->name));
		cJSON_AddItemToObject(props, "method", p);
	}
	return schema;
}

/* A request member named after a number setting (a control's beta,
 * beta_rate, omega_ss) takes that setting's range from the settings
 * table, the range the daemon checks it against, so that the document's
 * bounds are the daemon's. */
static void add_setting_bounds(cJSON *member, const char *name)
{
	const sim_setting *st = sim_setting_find(name);
	const cJSON *type = cJSON_GetObjectItemCaseSensitive(member, "type");
	if (!st || (st->kind != SIM_KIND_REAL && st->kind != SIM_KIND_INT) ||
	    !cJSON_IsString(type) ||
	    (strcmp(type->valuestring, "number") != 0 && strcmp(type->valuestring, "integer") != 0) ||
	    cJSON_GetObjectItemCaseSensitive(member, "minimum") ||
	    cJSON_GetObjectItemCaseSensitive(member, "maximum"))
		return;
	api_add_number(member, "minimum", st->min);
	api_add_number(member, "maximum", st->max);
}

/* A request schema: exactly the parser's members, each typed by
 * schemas.json's x-request-members; NULL if the two lists differ. */
static cJSON *request_schema(const cJSON *types, const cJSON *required, const char *name,
			     const char *const *members)
{
	const cJSON *t = cJSON_GetObjectItemCaseSensitive(types, name);
	int n = 0;
	while (members[n])
		n++;
	if (!t || cJSON_GetArraySize(t) != n)
		return NULL;
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "type", "object");
	cJSON *props = cJSON_AddObjectToObject(o, "properties");
	for (int i = 0; i < n; i++) {
		const cJSON *p = cJSON_GetObjectItemCaseSensitive(t, members[i]);
		if (!p) {
			cJSON_Delete(o);
			return NULL;
		}
		cJSON *m = cJSON_Duplicate(p, 1);
		add_setting_bounds(m, members[i]);
		cJSON_AddItemToObject(props, members[i], m);
	}
	const cJSON *req = cJSON_GetObjectItemCaseSensitive(required, name);
	if (req)
		cJSON_AddItemToObject(o, "required", cJSON_Duplicate(req, 1));
	if (strcmp(name, "Control") == 0)
		cJSON_AddNumberToObject(o, "minProperties", 1);
	cJSON_AddBoolToObject(o, "additionalProperties", 0);
	return o;
}

/* A sweep point's varied settings: each number setting of the table as
 * an optional member (a study names its columns by setting), so that the
 * point stays closed. */
static void add_varied_members(cJSON *point)
{
	cJSON *props = cJSON_GetObjectItemCaseSensitive(point, "properties");
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	for (size_t i = 0; props && i < n; i++) {
		if ((tab[i].kind != SIM_KIND_REAL && tab[i].kind != SIM_KIND_INT) ||
		    cJSON_GetObjectItemCaseSensitive(props, tab[i].name))
			continue;
		cJSON *p = cJSON_CreateObject();
		cJSON_AddStringToObject(p, "type", "number");
		char doc[96];
		snprintf(doc, sizeof doc, "%s%s(when %s is varied)", tab[i].unit,
			 *tab[i].unit ? " " : "", tab[i].name);
		cJSON_AddStringToObject(p, "description", doc);
		cJSON_AddItemToObject(props, tab[i].name, p);
	}
}

static cJSON *ref(const char *kind, const char *name)
{
	char r[96];
	snprintf(r, sizeof r, "#/components/%s/%s", kind, name);
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "$ref", r);
	return o;
}

/* content: {media: {schema}} for each media type given (schema may be
 * NULL: none). */
static cJSON *content(const char *media, cJSON *schema)
{
	cJSON *c = cJSON_CreateObject();
	cJSON *m = cJSON_AddObjectToObject(c, media);
	if (schema)
		cJSON_AddItemToObject(m, "schema", schema);
	return c;
}

/* The operation object of route rt. */
/* The route's parameters: the path's id, its query parameters, and
 * Last-Event-ID where it resumes (the schema of ?since=, which it is). */
static void add_parameters(cJSON *op, const api_route *rt)
{
	size_t nq;
	const api_query *q = api_queries(&nq);
	const char *since = NULL;
	cJSON *params = cJSON_AddArrayToObject(op, "parameters");
	if (strchr(rt->pattern, '*'))
		cJSON_AddItemToArray(params, ref("parameters", "Id"));
	for (size_t i = 0; i < nq; i++) {
		if (!(rt->query & q[i].bit))
			continue;
		if (q[i].bit == API_Q_SINCE)
			since = q[i].schema;
		cJSON *p = cJSON_CreateObject();
		cJSON_AddStringToObject(p, "name", q[i].name);
		cJSON_AddStringToObject(p, "in", "query");
		cJSON_AddStringToObject(p, "description", q[i].doc);
		cJSON_AddItemToObject(p, "schema", cJSON_Parse(q[i].schema));
		cJSON_AddItemToArray(params, p);
	}
	if (since) {
		cJSON *p = cJSON_CreateObject();
		cJSON_AddStringToObject(p, "name", "Last-Event-ID");
		cJSON_AddStringToObject(p, "in", "header");
		cJSON_AddItemToObject(p, "schema", cJSON_Parse(since));
		cJSON_AddItemToArray(params, p);
	}
}

/* The success answer of the route and its media types into responses. */
static void add_success(cJSON *responses, const api_route *rt)
{
	char status[8];
	snprintf(status, sizeof status, "%d", rt->status);
	cJSON *ok = cJSON_AddObjectToObject(responses, status);
	cJSON_AddStringToObject(ok, "description", rt->status == 204 ? "done, no body" : "OK");
	if (strcmp(rt->response, "StreamRecord") == 0) {
		/* A stream's body is a sequence of records, not one JSON value:
		 * its schema is text, and each record's schema goes in
		 * x-itemSchema (OpenAPI 3.1 has no keyword for it; 3.2's
		 * itemSchema is the same idea), so validating proxies accept
		 * the stream and tools that know the extension check records. */
		static const char stream_media[] =
			"{\"schema\":{\"type\":\"string\"},"
			"\"x-itemSchema\":{\"$ref\":\"#/components/schemas/StreamRecord\"}}";
		cJSON *c = cJSON_CreateObject();
		cJSON_AddItemToObject(c, "text/event-stream", cJSON_Parse(stream_media));
		cJSON_AddItemToObject(c, "application/x-ndjson", cJSON_Parse(stream_media));
		cJSON_AddItemToObject(ok, "content", c);
	} else if (strchr(rt->response, '/')) {
		cJSON_AddItemToObject(ok, "content", content(rt->response, NULL));
	} else if (rt->response[0]) {
		cJSON *c = content("application/json", ref("schemas", rt->response));
		if (rt->tables)
			cJSON_AddItemToObject(c, "text/csv",
					      cJSON_Parse("{\"schema\":{\"type\":\"string\","
							  "\"description\":\"CSV with a header line\"}}"));
		cJSON_AddItemToObject(ok, "content", c);
	}
}

static cJSON *operation(const api_route *rt)
{
	cJSON *op = cJSON_CreateObject();
	cJSON_AddStringToObject(op, "summary", rt->summary);
	add_parameters(op, rt);
	if (rt->request) {
		cJSON *body = cJSON_AddObjectToObject(op, "requestBody");
		cJSON_AddBoolToObject(body, "required", 1);
		cJSON_AddItemToObject(body, "content",
				      content("application/json", ref("schemas", rt->request)));
	}
	cJSON *responses = cJSON_AddObjectToObject(op, "responses");
	add_success(responses, rt);
	if (strcmp(rt->response, "Health") == 0) {
		cJSON *down = cJSON_AddObjectToObject(responses, "503");
		cJSON_AddStringToObject(down, "description", "shutting down");
		cJSON_AddItemToObject(down, "content", content("application/json", ref("schemas", "Health")));
	}
	char list[64];
	snprintf(list, sizeof list, "%s", rt->problems);
	char *save = NULL;
	for (char *t = strtok_r(list, ",", &save); t; t = strtok_r(NULL, ",", &save))
		cJSON_AddItemToObject(responses, t, ref("responses", "Problem"));
	/* the request gate's answers, the same for every route (docs/operations.md
	 * "Security"): the token (not on health), Origin, Host */
	int open_route = strcmp(rt->pattern, "/api/v1/health") == 0;
	if (open_route)
		cJSON_AddArrayToObject(op, "security");
	else
		cJSON_AddItemToObject(responses, "401", ref("responses", "Problem"));
	cJSON_AddItemToObject(responses, "403", ref("responses", "Problem"));
	cJSON_AddItemToObject(responses, "421", ref("responses", "Problem"));
	return op;
}

/* The paths object from the route table ("*" becomes {id}). */
static cJSON *paths(void)
{
	size_t n;
	const api_route *rt = api_routes(&n);
	cJSON *paths = cJSON_CreateObject();
	for (size_t i = 0; i < n; i++) {
		char path[96], method[8];
		size_t at = 0;
		for (const char *p = rt[i].pattern; *p && at + 5 < sizeof path; p++)
			at += (size_t)snprintf(path + at, sizeof path - at, "%s",
					       *p == '*' ? "{id}" : (char[]){*p, 0});
		snprintf(method, sizeof method, "%s", rt[i].method);
		for (char *m = method; *m; m++)
			*m = (char)(*m - 'A' + 'a');
		cJSON *item = cJSON_GetObjectItemCaseSensitive(paths, path);
		if (!item)
			item = cJSON_AddObjectToObject(paths, path);
		cJSON_AddItemToObject(item, method, operation(&rt[i]));
	}
	return paths;
}

char *api_openapi_json(void)
{
	static const struct {
		const char *name;
		const char *const *members;
	} bodies[] = {
		{"SessionCreate", api_members_session_create},
		{"Control", api_members_control},
		{"ExperimentCreate", api_members_experiment},
		{"ExperimentSession", api_members_experiment_session},
		{"ScheduleSegment", api_members_segment},
		{"Identify", api_members_identify},
		{"ExperimentControl", api_members_exp_control},
		{"Setpoint", api_members_setpoint},
		{"Controller", api_members_controller},
		{"Disturbance", api_members_disturbance},
		{"SweepCreate", api_members_sweep},
		{"BetaRange", api_members_beta_range},
		{"FitCreate", api_members_fit},
		{"FitFree", api_members_fit_free},
		{"FitPrior", api_members_fit_prior},
		{"FitPoint", api_members_fit_point},
		{"FitPeak", api_members_fit_peak},
	};
	cJSON *src = cJSON_Parse(schemas_text);
	cJSON *comps = cJSON_DetachItemFromObjectCaseSensitive(src, "components");
	cJSON *schemas = cJSON_GetObjectItemCaseSensitive(comps, "schemas");
	const cJSON *types = cJSON_GetObjectItemCaseSensitive(src, "x-request-members");
	const cJSON *required = cJSON_GetObjectItemCaseSensitive(src, "x-required");
	cJSON *doc = NULL;
	if (!schemas || !types)
		goto fail;
	for (size_t i = 0; i < sizeof bodies / sizeof *bodies; i++) {
		cJSON *b = request_schema(types, required, bodies[i].name, bodies[i].members);
		if (!b)
			goto fail; /* schemas.json and a parser disagree */
		cJSON_AddItemToObject(schemas, bodies[i].name, b);
	}
	add_varied_members(cJSON_GetObjectItemCaseSensitive(schemas, "SweepPoint"));
	cJSON_AddItemToObject(schemas, "Params", group_schema("params"));
	cJSON_AddItemToObject(schemas, "Scene", group_schema("scene"));
	cJSON_AddItemToObject(schemas, "Integrator", group_schema("integrator"));
	cJSON_AddItemToObject(comps, "parameters",
			      cJSON_Parse("{\"Id\":{\"name\":\"id\",\"in\":\"path\",\"required\":"
					  "true,\"schema\":{\"type\":\"string\"}}}"));
	cJSON_AddItemToObject(comps, "responses",
			      cJSON_Parse("{\"Problem\":{\"description\":\"RFC 9457 problem; its "
					  "type URI serves a page that explains it\",\"content\":{"
					  "\"application/problem+json\":{\"schema\":{\"$ref\":"
					  "\"#/components/schemas/Problem\"}}}}}"));
	cJSON_AddItemToObject(comps, "securitySchemes",
			      cJSON_Parse("{\"bearer\":{\"type\":\"http\",\"scheme\":\"bearer\","
					  "\"description\":\"the token of the daemon's --token-file; "
					  "none when it runs without one\"}}"));
	doc = cJSON_CreateObject();
	cJSON_AddStringToObject(doc, "openapi", "3.1.0");
	cJSON_AddItemToObject(doc, "security",
			      cJSON_Parse("[{\"bearer\":[]},{}]"));
	cJSON *info = cJSON_AddObjectToObject(doc, "info");
	cJSON_AddStringToObject(info, "title", "convsim daemon API");
	cJSON_AddStringToObject(info, "version", "1");
	cJSON_AddStringToObject(info, "description",
				"Simulation sessions of a reversible vibratory conveyor (Czubak 2016): "
				"beta on the fly, streams, experiments, sweeps, fits. Results as JSON or CSV "
				"(Accept or ?format=). Errors are RFC 9457 problem details.");
	cJSON_AddItemToObject(doc, "paths", paths());
	cJSON_AddItemToObject(doc, "components", comps);
	cJSON_Delete(src);
	return api_print_free(doc);
fail:
	cJSON_Delete(comps);
	cJSON_Delete(src);
	return NULL;
}
