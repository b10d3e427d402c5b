/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_query.c - libFuzzer harness of the query strings and the headers
 * the API reads: which parameters a route takes (api_check_query), the
 * representation (api_negotiate: ?format= and Accept with q-values), the
 * stream's options (api_parse_stream_query: format, fields, rate, limit,
 * Last-Event-ID / since) and the trajectory's range
 * (api_parse_trajectory_query: from, to, stride).
 *
 * Input: byte 0 picks the route of the API's table; then the query string
 * (as after '?'), a newline, the Accept header, a newline, Last-Event-ID
 * (absent when the input ends before it). The query string is split at
 * '&' and '=' and each part decoded with libmicrohttpd's own
 * MHD_http_unescape; as libmicrohttpd does, the first of a repeated
 * parameter is the one handlers see and a parameter without '=' has no
 * value. Oracles: refusals are well-formed problems (400 or 406); an
 * accepted stream or trajectory query, written back as a query string
 * (numbers with 17 digits, fields by name), parses to the same options.
 */
#include <inttypes.h>
#include <math.h>
#include <microhttpd.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_routes.h"
#include "fuzz_util.h"

#define MAX_PARAMS 32

typedef struct query {
	int n;
	char *key[MAX_PARAMS];
	char *value[MAX_PARAMS]; /* NULL: no '=' */
} query;

static void split(char *text, query *q)
{
	q->n = 0;
	for (char *p = text; p && *p && q->n < MAX_PARAMS;) {
		char *amp = strchr(p, '&');
		if (amp)
			*amp = '\0';
		char *eq = strchr(p, '=');
		if (eq)
			*eq = '\0';
		MHD_http_unescape(p);
		if (eq)
			MHD_http_unescape(eq + 1);
		q->key[q->n] = p;
		q->value[q->n++] = eq ? eq + 1 : NULL;
		p = amp ? amp + 1 : NULL;
	}
}

/* The first value of key, NULL when absent or without '='. */
static const char *get(const query *q, const char *key)
{
	for (int i = 0; i < q->n; i++)
		if (strcmp(q->key[i], key) == 0)
			return q->value[i];
	return NULL;
}

static const struct {
	unsigned bit;
	const char *name;
} groups[] = {
	{API_F_TROUGH, "trough"}, {API_F_ORBIT, "orbit"}, {API_F_ROTOR, "rotor"},
	{API_F_ELIMINATORS, "eliminators"}, {API_F_FEED, "feed"}, {API_F_ENERGY, "energy"},
	{API_F_ELEMENTS, "elements"},
};

static void stream_query(const query *q, const char *accept, const char *last_event_id)
{
	api_stream_query s, again;
	api_problem pb;
	api_err e = api_parse_stream_query(get(q, "format"), accept, get(q, "fields"),
					   get(q, "rate"), get(q, "limit"), last_event_id,
					   get(q, "since"), &s, &pb);
	if (e != API_OK) {
		FUZZ_CHECK(api_status(e) == 400, "stream query refused with %d", api_status(e));
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(s.fields && !(s.fields & ~(unsigned)API_F_ALL), "fields mask %#x", s.fields);
	FUZZ_CHECK(s.rate == 0 || (s.rate > 0 && s.rate <= 100000), "rate %g", s.rate);
	FUZZ_CHECK(s.resume >= -1 && s.resume <= API_STREAM_ID_MAX, "resume %" PRId64, s.resume);
	FUZZ_CHECK(s.limit <= API_STREAM_LIMIT_MAX, "limit %" PRIu64, s.limit);
	char fields[128] = "", rate[40] = "", limit[24] = "", since[24] = "";
	for (size_t i = 0; i < sizeof groups / sizeof *groups; i++)
		if (s.fields & groups[i].bit)
			snprintf(fields + strlen(fields), sizeof fields - strlen(fields), "%s%s",
				 fields[0] ? "," : "", groups[i].name);
	snprintf(rate, sizeof rate, "%.17g", s.rate);
	snprintf(limit, sizeof limit, "%" PRIu64, s.limit);
	snprintf(since, sizeof since, "%" PRId64, s.resume);
	e = api_parse_stream_query(s.ndjson ? "ndjson" : "sse", NULL, fields,
				   s.rate > 0 ? rate : NULL, s.limit ? limit : NULL, NULL,
				   s.resume >= 0 ? since : NULL, &again, &pb);
	FUZZ_CHECK(e == API_OK, "stream query written back is refused: %s", pb.detail);
	FUZZ_CHECK(memcmp(&s, &again, sizeof s) == 0,
		   "stream query differs after the round trip (fields=%s rate=%s)", fields, rate);
}

static void trajectory_query(const query *q)
{
	api_trajectory_query t, again;
	api_problem pb;
	api_err e = api_parse_trajectory_query(get(q, "from"), get(q, "to"), get(q, "stride"), &t,
					       &pb);
	if (e != API_OK) {
		FUZZ_CHECK(api_status(e) == 400, "trajectory query refused with %d", api_status(e));
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(t.from <= t.to && t.stride >= 0 && isfinite(t.stride),
		   "from %g, to %g, stride %g", t.from, t.to, t.stride);
	char from[40], to[40], stride[40];
	snprintf(from, sizeof from, "%.17g", t.from);
	snprintf(to, sizeof to, "%.17g", t.to);
	snprintf(stride, sizeof stride, "%.17g", t.stride);
	/* no stride is 0, and a stride given is > 0 */
	e = api_parse_trajectory_query(isfinite(t.from) ? from : NULL, isfinite(t.to) ? to : NULL,
				       t.stride > 0 ? stride : NULL, &again, &pb);
	FUZZ_CHECK(e == API_OK, "trajectory query written back is refused: %s", pb.detail);
	FUZZ_CHECK(t.from == again.from && t.to == again.to && t.stride == again.stride,
		   "trajectory query differs after the round trip");
}

static void check(const api_route *rt, const query *q, const char *accept,
		  const char *last_event_id)
{
	api_problem pb;
	for (int i = 0; i < q->n; i++) {
		api_err e = api_check_query(rt, q->key[i], &pb);
		if (e != API_OK) {
			FUZZ_CHECK(e == API_QUERY, "check_query gave %d", (int)e);
			fuzz_check_problem(e, &pb);
			return;
		}
	}
	int csv = -1;
	api_err e = api_negotiate(rt, rt->tables ? get(q, "format") : NULL, accept, &csv, &pb);
	if (e != API_OK) {
		FUZZ_CHECK(rt->tables && (e == API_QUERY || e == API_NOTACCEPTABLE),
			   "negotiate gave %d on %s", (int)e, rt->pattern);
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(csv == 0 || (csv == 1 && rt->tables), "csv %d on %s", csv, rt->pattern);
	if (rt->query & API_Q_STREAM_FORMAT)
		stream_query(q, accept, last_event_id);
	if (rt->query & API_Q_STRIDE)
		trajectory_query(q);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1)
		return 0;
	size_t n;
	const api_route *routes = api_routes(&n);
	const api_route *rt = &routes[data[0] % n];
	char *text = fuzz_string(data + 1, size - 1);
	char *accept = strchr(text, '\n'), *last_event_id = NULL;
	if (accept) {
		*accept++ = '\0';
		last_event_id = strchr(accept, '\n');
		if (last_event_id)
			*last_event_id++ = '\0';
	}
	query q;
	split(text, &q);
	check(rt, &q, accept, last_event_id);
	free(text);
	return 0;
}
