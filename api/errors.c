/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * errors.c - error codes to HTTP statuses and RFC 9457 problem details.
 *
 * api.h's API_ERRNO_MAP lists the errors of the HTTP layer with their
 * statuses and problem types; SIM_TO_API below is the one table that maps
 * the core's return codes (SIM_ERRNO_MAP, names and messages only) onto
 * them, and so to HTTP statuses. A problem names the offending field by its
 * JSON path and, when the field is a setting of the core's table, adds the
 * allowed range or choices so that a client can correct itself.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"

static const struct {
	int status;
	const char *slug, *title, *explanation;
} api_errors[] = {
#define API_ERR_ROW(name, status, slug, title, explanation) {status, slug, title, explanation},
	API_ERRNO_MAP(API_ERR_ROW)
#undef API_ERR_ROW
};

int api_status(api_err code)
{
	if ((int)code < 0 || code >= API_NERR)
		return 500;
	return api_errors[code].status;
}

/* X(core code, api code): every SIM_ERRNO_MAP entry once. */
#define SIM_TO_API(X)                                                         \
	X(OK, OK)                                                             \
	X(EPARAM, RANGE)                                                      \
	X(EUNKNOWN, UNKNOWN)                                                  \
	X(ENOMEM, UNAVAILABLE)                                                \
	X(EDIVERGED, INVALID)                                                 \
	X(ESTEP, INVALID)                                                     \
	X(ETIME, INVALID)                                                     \
	X(ECHECKPOINT, INVALID)                                               \
	X(ECPU, RANGE)

static const api_err sim_to_api[SIM_NERR] = {
#define SIM_TO_API_ROW(sim, api) [SIM_##sim] = API_##api,
	SIM_TO_API(SIM_TO_API_ROW)
#undef SIM_TO_API_ROW
};
#define SIM_TO_API_COUNT(sim, api) +1
_Static_assert(0 SIM_TO_API(SIM_TO_API_COUNT) == SIM_NERR,
	       "SIM_TO_API maps every core return code");
#undef SIM_TO_API_COUNT

int api_sim_status(int sim_err)
{
	if (sim_err < 0 || sim_err >= SIM_NERR)
		return 500;
	return api_status(sim_to_api[sim_err]);
}

api_err api_from_sim(int sim_err)
{
	if (sim_err < 0 || sim_err >= SIM_NERR)
		return API_INVALID;
	return sim_to_api[sim_err];
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

static void vfail(api_problem *pb, api_err code, const char *field, const char *fmt,
		  va_list ap)
{
	memset(pb, 0, sizeof *pb);
	pb->code = code;
	if (field)
		snprintf(pb->field, sizeof pb->field, "%s", field);
	vsnprintf(pb->detail, sizeof pb->detail, fmt, ap);
}

double api_round_inward(double v, int up, int digits)
{
	char text[40];
	snprintf(text, sizeof text, "%.*e", digits - 1, v);
	double r = strtod(text, NULL);
	if (!isfinite(v) || (up ? r >= v : r <= v))
		return r;
	int exp10 = atoi(strchr(text, 'e') + 1);
	double q = pow(10, digits - 1 - exp10), k = round(r * q) + (up ? 1 : -1);
	return q >= 1 ? k / q : k * pow(10, exp10 - digits + 1);
}

api_err api_fail_range(api_problem *pb, const char *field, double min, double max,
		       const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vfail(pb, API_RANGE, field, fmt, ap);
	va_end(ap);
	pb->has_range = 1;
	pb->min = min;
	pb->max = max;
	return API_RANGE;
}

api_err api_copy_id(api_problem *pb, const char *field, const char *what,
		    const char *text, char *buf, size_t size)
{
	size_t n = strlen(text);
	if (n < 1 || n >= size)
		return api_fail_range(pb, field, 1, (double)size - 1,
				      "%s has %zu bytes; %s id has 1 to %zu", field, n, what,
				      size - 1);
	memcpy(buf, text, n + 1);
	return API_OK;
}

const char *api_plural(double n, const char *one, const char *many)
{
	return n == 1 ? one : many;
}

const char *api_plural_g(double n, int digits, const char *one, const char *many)
{
	char printed[32];
	snprintf(printed, sizeof printed, "%.*g", digits, n);
	return strcmp(printed, "1") == 0 ? one : many;
}

void api_field_within(api_problem *pb, const char *member)
{
	size_t m = strlen(member), n = strlen(pb->field);
	if (!n || (strncmp(pb->field, member, m) == 0 && pb->field[m] == '.') ||
	    m + 1 + n >= sizeof pb->field)
		return;
	memmove(pb->field + m + 1, pb->field, n + 1);
	memcpy(pb->field, member, m);
	pb->field[m] = '.';
}

api_err api_fail_choices(api_problem *pb, api_err code, const char *field, const char *choices,
			 const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vfail(pb, code, field, fmt, ap);
	va_end(ap);
	snprintf(pb->choices, sizeof pb->choices, "%s", choices);
	return code;
}

const char *api_choices_of(const char *name, unsigned mask, char *out, size_t n)
{
	const sim_setting *set = api_setting(NULL, name);
	size_t at = 0;
	if (n)
		out[0] = '\0';
	if (!set || set->kind != SIM_KIND_ENUM || !set->choices)
		return out;
	const char *c = set->choices;
	for (unsigned v = 0; *c; v++) {
		size_t len = strcspn(c, "|");
		if (v < 32 && (mask >> v & 1u) && at < n)
			at += (size_t)snprintf(out + at, n - at, "%s%.*s", at ? "|" : "", (int)len,
					       c);
		c += len + (c[len] == '|');
	}
	return out;
}

api_err api_fail(api_problem *pb, api_err code, const char *field,
		 const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	vfail(pb, code, field, fmt, ap);
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

size_t api_utf8_seq(const unsigned char *s, size_t avail)
{
	if (avail == 0)
		return 0;
	if (s[0] < 0x80)
		return 1;
	size_t n = s[0] >= 0xc2 && s[0] <= 0xdf   ? 2
		   : s[0] >= 0xe0 && s[0] <= 0xef ? 3
		   : s[0] >= 0xf0 && s[0] <= 0xf4 ? 4
						  : 0;
	if (n > avail)
		return 0;
	unsigned lo = 0x80, hi = 0xbf; /* the second byte's range */
	if (s[0] == 0xe0)
		lo = 0xa0;
	else if (s[0] == 0xed)
		hi = 0x9f;
	else if (s[0] == 0xf0)
		lo = 0x90;
	else if (s[0] == 0xf4)
		hi = 0x8f;
	if (n == 0 || s[1] < lo || s[1] > hi)
		return 0;
	for (size_t i = 2; i < n; i++)
		if (s[i] < 0x80 || s[i] > 0xbf)
			return 0;
	return n;
}

/* A copy of text in valid UTF-8: each byte that does not start a valid
 * sequence becomes U+FFFD. Requests may hold any bytes (a path, a
 * member's name, a header echoed in a detail, a detail cut mid-character),
 * and a problem must still parse as JSON. NULL when out of memory. */
static char *utf8_valid(const char *text)
{
	const unsigned char *s = (const unsigned char *)text;
	size_t len = strlen(text);
	char *out = malloc(3 * len + 1), *o = out;
	if (!out)
		return NULL;
	const unsigned char *end = s + len;
	while (*s) {
		size_t n = api_utf8_seq(s, (size_t)(end - s));
		if (n == 0) {
			memcpy(o, "\xef\xbf\xbd", 3);
			o += 3;
			s++;
			continue;
		}
		memcpy(o, s, n);
		o += n;
		s += n;
	}
	*o = '\0';
	return out;
}

static void add_valid_string(cJSON *o, const char *name, const char *text)
{
	char *valid = utf8_valid(text);
	if (valid)
		cJSON_AddStringToObject(o, name, valid);
	free(valid);
}

api_err api_budget(api_problem *pb, const char *budget, double limit, int retry_after)
{
	snprintf(pb->budget, sizeof pb->budget, "%s", budget);
	pb->limit = limit;
	pb->retry_after = retry_after;
	return pb->code;
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
	add_valid_string(o, "detail", pb->detail);
	if (instance)
		add_valid_string(o, "instance", instance);
	if (pb->field[0])
		add_valid_string(o, "field", pb->field);
	if (pb->has_position)
		cJSON_AddNumberToObject(o, "position", (double)pb->position);
	if (pb->has_range) {
		api_add_number(o, "min", pb->min);
		api_add_number(o, "max", pb->max);
	}
	if (pb->budget[0]) {
		cJSON_AddStringToObject(o, "budget", pb->budget);
		api_add_number(o, "limit", pb->limit);
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

/* Text of the error table as HTML: `code` spans become <code>, and the
 * characters HTML gives a meaning are escaped. */
static void put_html(api_buf *b, const char *text)
{
	int code = 0;
	for (const char *c = text; *c; c++) {
		switch (*c) {
		case '`': api_buf_puts(b, code ? "</code>" : "<code>"); code = !code; break;
		case '<': api_buf_puts(b, "&lt;"); break;
		case '>': api_buf_puts(b, "&gt;"); break;
		case '&': api_buf_puts(b, "&amp;"); break;
		default: api_buf_printf(b, "%c", *c); break;
		}
	}
	if (code)
		api_buf_puts(b, "</code>");
}

char *api_problem_page(const char *slug)
{
	int at = -1;
	for (int i = 1; i < API_NERR; i++)
		if (strcmp(api_errors[i].slug, slug) == 0)
			at = i;
	if (at < 0)
		return NULL;
	api_buf b = {0};
	api_buf_printf(&b,
		       "<!doctype html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
		       "<title>%d %s - convsim problem</title>"
		       "<style>body{font:16px/1.5 system-ui,sans-serif;max-width:46em;margin:2em "
		       "auto;padding:0 1em}code{background:#eee;padding:0 .2em}td,th{padding:.2em "
		       ".6em;text-align:left;vertical-align:top}</style></head><body>\n"
		       "<h1>%s</h1>\n<p><code>/api/v1/problems/%s</code> &middot; HTTP %d</p>\n<p>",
		       api_errors[at].status, api_errors[at].title, api_errors[at].title,
		       api_errors[at].slug, api_errors[at].status);
	put_html(&b, api_errors[at].explanation);
	api_buf_printf(&b,
		       "</p>\n"
		       "<p>The problem's <code>detail</code> says what exactly was wrong; "
		       "<code>instance</code> is the request's path. A refused request changed "
		       "nothing.</p>\n<h2>Every problem type of this API</h2>\n<table>"
		       "<tr><th>status</th><th>type</th><th>title</th></tr>\n");
	for (int i = 1; i < API_NERR; i++)
		api_buf_printf(&b, "<tr><td>%d</td><td><a href=\"%s\">%s</a></td><td>%s</td></tr>\n",
			       api_errors[i].status, api_errors[i].slug, api_errors[i].slug,
			       api_errors[i].title);
	api_buf_puts(&b, "</table>\n<p>The API: <a href=\"../openapi.json\">openapi.json</a>.</p>"
			 "\n</body></html>\n");
	return api_buf_take(&b);
}
