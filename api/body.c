/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * body.c - the one way a request body is read: parse the bytes as one JSON
 * object, check that every member is a known one, and answer the common
 * problems (400 empty or malformed body, strictly by RFC 8259 and
 * I-JSON (json_check.c), 400 not an object, 422 unknown
 * member) the same way for sessions, controls, sweeps and experiments.
 */
#include <stdio.h>
#include <string.h>

#include "json_int.h"

/* Parse len bytes as one JSON object. Empty or blank text is no JSON
 * (RFC 8259) and refused as such on every route; {} is the body that takes
 * every default. Returns the tree or NULL with *pb set (400). */
static cJSON *parse_object(const char *body, size_t len, api_problem *pb)
{
	size_t i = 0;
	while (i < len && (body[i] == ' ' || body[i] == '\t' ||
			   body[i] == '\n' || body[i] == '\r'))
		i++;
	if (i == len) {
		api_fail(pb, API_MALFORMED, NULL, "the request body is %s; a JSON "
			 "object is expected ({} for no members)",
			 len ? "only whitespace" : "empty");
		return NULL;
	}
	if (api_json_check(body, len, pb) != API_OK)
		return NULL;
	const char *end = NULL;
	cJSON *root = cJSON_ParseWithLengthOpts(body, len, &end, 0);
	if (!root) {
		size_t at = end && end >= body ? (size_t)(end - body) : 0;
		api_fail(pb, API_MALFORMED, NULL,
			 "the request body is not valid JSON (error near byte "
			 "%zu)", at);
		return NULL;
	}
	/* trailing garbage after the value */
	size_t used = (size_t)(end - body);
	while (used < len && (body[used] == ' ' || body[used] == '\t' ||
			      body[used] == '\n' || body[used] == '\r'))
		used++;
	if (used < len) {
		cJSON_Delete(root);
		api_fail(pb, API_MALFORMED, NULL,
			 "unexpected text after the JSON value at byte %zu",
			 used);
		return NULL;
	}
	if (!cJSON_IsObject(root)) {
		cJSON_Delete(root);
		api_fail(pb, API_TYPE, NULL,
			 "the request body must be a JSON object");
		return NULL;
	}
	return root;
}

/* Every member of obj must be one of the NULL-terminated names. */
api_err api_check_members(const cJSON *obj, const char *const *names,
			  const char *prefix, api_problem *pb)
{
	for (const cJSON *it = obj->child; it; it = it->next) {
		int known = 0;
		for (size_t i = 0; names[i] && !known; i++)
			known = strcmp(it->string, names[i]) == 0;
		if (!known) {
			char field[64], list[256] = "";
			snprintf(field, sizeof field, "%s%s", prefix,
				 it->string);
			size_t at = 0;
			for (size_t i = 0; names[i] && at < sizeof list; i++)
				at += (size_t)snprintf(list + at,
						       sizeof list - at, "%s%s",
						       i ? ", " : "", names[i]);
			return api_fail(pb, API_UNKNOWN, field,
					"unknown member \"%.40s\"; expected "
					"any of: %s", it->string, list);
		}
	}
	return API_OK;
}

cJSON *api_parse_body(const char *body, size_t len, const char *const *members,
		      api_problem *pb)
{
	cJSON *root = parse_object(body, len, pb);
	if (root && api_check_members(root, members, "", pb) != API_OK) {
		cJSON_Delete(root);
		return NULL;
	}
	return root;
}

api_err api_check_object(const cJSON *obj, const char *field, const char *prefix,
			 const char *expected, const char *const *names, api_problem *pb)
{
	if (!cJSON_IsObject(obj))
		return api_fail(pb, API_TYPE, field, "%.*s must be %s", (int)strlen(prefix) - 1,
				prefix, expected);
	return api_check_members(obj, names, prefix, pb);
}
