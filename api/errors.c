/*
 * errors.c - error codes to HTTP statuses and RFC 9457 problem details.
 *
 * Two X-macro lists meet here: the core's SIM_ERRNO_MAP (which already
 * carries an HTTP status per core error) and api.h's API_ERRNO_MAP for the
 * errors of the HTTP layer. A problem names the offending field by its
 * JSON path and, when the field is a setting of the core's table, adds the
 * allowed range or choices so that a client can correct itself.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"

static const struct {
	int status;
	const char *slug, *title;
} api_errors[] = {
#define API_ERR_ROW(name, status, slug, title) {status, slug, title},
	API_ERRNO_MAP(API_ERR_ROW)
#undef API_ERR_ROW
};

int api_status(api_err code)
{
	if ((int)code < 0 || code >= API_NERR)
		return 500;
	return api_errors[code].status;
}

int api_sim_status(int sim_err)
{
	switch (sim_err) {
#define SIM_ERR_CASE(name, status, msg) case SIM_##name: return status;
	SIM_ERRNO_MAP(SIM_ERR_CASE)
#undef SIM_ERR_CASE
	default: return 500;
	}
}

api_err api_from_sim(int sim_err)
{
	switch (sim_err) {
	case SIM_OK: return API_OK;
	case SIM_EPARAM: return API_RANGE;
	case SIM_EUNKNOWN: return API_UNKNOWN;
	case SIM_ENOMEM: return API_UNAVAILABLE;
	default:
		return api_sim_status(sim_err) == 503 ? API_UNAVAILABLE
						      : API_INVALID;
	}
}

const sim_setting *api_setting(const char *group, const char *name)
{
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	for (size_t i = 0; tab && i < n; i++)
		if ((!group || strcmp(tab[i].group, group) == 0) &&
		    strcmp(tab[i].name, name) == 0)
			return &tab[i];
	return NULL;
}

/* The setting a field path names: "params.k_s1" or a bare "beta". */
static const sim_setting *field_setting(const char *field)
{
	const char *dot = strchr(field, '.');
	if (!dot)
		return api_setting(NULL, field);
	char group[32];
	size_t gl = (size_t)(dot - field);
	if (gl >= sizeof group)
		return NULL;
	memcpy(group, field, gl);
	group[gl] = '\0';
	return api_setting(group, dot + 1);
}

api_err api_fail(api_problem *pb, api_err code, const char *field,
		 const char *fmt, ...)
{
	memset(pb, 0, sizeof *pb);
	pb->code = code;
	if (field)
		snprintf(pb->field, sizeof pb->field, "%s", field);
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(pb->detail, sizeof pb->detail, fmt, ap);
	va_end(ap);
	const sim_setting *set = field ? field_setting(field) : NULL;
	if (set && (code == API_RANGE || code == API_TYPE)) {
		if (set->kind == SIM_KIND_ENUM && set->choices) {
			snprintf(pb->choices, sizeof pb->choices, "%s",
				 set->choices);
		} else if (set->kind != SIM_KIND_BOOL) {
			pb->has_range = 1;
			pb->min = set->min;
			pb->max = set->max;
		}
	}
	return code;
}

char *api_problem_json(const api_problem *pb, const char *instance)
{
	cJSON *o = cJSON_CreateObject();
	char type[96];
	api_err code = pb->code < API_NERR ? pb->code : API_INVALID;
	snprintf(type, sizeof type, "/api/v1/problems/%s",
		 api_errors[code].slug);
	cJSON_AddStringToObject(o, "type", type);
	cJSON_AddStringToObject(o, "title", api_errors[code].title);
	cJSON_AddNumberToObject(o, "status", api_errors[code].status);
	cJSON_AddStringToObject(o, "detail", pb->detail);
	if (instance)
		cJSON_AddStringToObject(o, "instance", instance);
	if (pb->field[0])
		cJSON_AddStringToObject(o, "field", pb->field);
	if (pb->has_range) {
		api_add_number(o, "min", pb->min);
		api_add_number(o, "max", pb->max);
	}
	if (pb->choices[0]) {
		cJSON *arr = cJSON_AddArrayToObject(o, "choices");
		char tmp[sizeof pb->choices];
		snprintf(tmp, sizeof tmp, "%s", pb->choices);
		char *save = NULL;
		for (char *tok = strtok_r(tmp, "|", &save); tok;
		     tok = strtok_r(NULL, "|", &save))
			cJSON_AddItemToArray(arr, cJSON_CreateString(tok));
	}
	return api_print_free(o);
}
