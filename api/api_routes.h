/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * api_routes.h - the API's routes and query parameters (routes.c): which
 * handler a method and path reach, the queries each accepts and their
 * parsed values, and the problem types' pages.
 */
#ifndef CONVSIM_API_ROUTES_H
#define CONVSIM_API_ROUTES_H

#include "api.h"

/* Query parameters, by bit; two share the name "format" (tables, streams). */
enum {
	API_Q_FORMAT = 1 << 0, API_Q_FROM = 1 << 1, API_Q_TO = 1 << 2, API_Q_STRIDE = 1 << 3,
	API_Q_STREAM_FORMAT = 1 << 4, API_Q_FIELDS = 1 << 5, API_Q_RATE = 1 << 6,
	API_Q_LIMIT = 1 << 7, API_Q_SINCE = 1 << 8, API_Q_SCOPE = 1 << 9, API_Q_ONLY = 1 << 10,
};
typedef struct api_query {
	unsigned bit;
	const char *name;
	const char *schema; /* JSON Schema text */
	const char *doc;
} api_query;
/* The routes, by their row in the one route table (api/routes.c); the
 * server's handlers are indexed by the same ids (server/http/routes.c). */
typedef enum {
	API_R_SESSIONS_CREATE, API_R_SESSIONS_LIST, API_R_SESSION_GET, API_R_SESSION_PATCH,
	API_R_SESSION_DELETE, API_R_SESSION_STREAM, API_R_SESSION_TRAJECTORY,
	API_R_EXPERIMENTS_CREATE, API_R_EXPERIMENTS_LIST, API_R_EXPERIMENT_GET, API_R_EXPERIMENT_DELETE,
	API_R_SWEEPS_CREATE, API_R_SWEEPS_LIST, API_R_SWEEP_GET, API_R_SWEEP_DELETE,
	API_R_FITS_CREATE, API_R_FITS_LIST, API_R_FIT_GET, API_R_FIT_DELETE,
	API_R_PRESETS, API_R_HEALTH, API_R_OPENAPI, API_R_PROBLEM, API_R_METRICS,
	API_R_COUNT
} api_route_id;
/* One route: "*" in the pattern is one path segment ({id}). */
typedef struct api_route {
	const char *method, *pattern;
	unsigned query;  /* API_Q_* bits it takes */
	int tables;      /* a result route: JSON or CSV by Accept or ?format= */
	const char *summary;
	const char *request;  /* body schema (components/schemas), or NULL */
	int status;           /* the success status */
	const char *response; /* its JSON schema, or "" (no body), or a media
				 type ("text/html", ...) for other bodies */
	const char *problems; /* the problem statuses it may answer, "400,404" */
} api_route;
/* The route table (API_R_COUNT rows, in api_route_id order) and the query
 * parameters (static). */
const api_route *api_routes(size_t *n);
const api_query *api_queries(size_t *n);
/* API_OK if route rt takes query parameter name, else a 400 bad-query
 * problem naming the parameters it takes (and the nearest one). */
api_err api_check_query(const api_route *rt, const char *name, api_problem *pb);
/* API_OK if a parameter the route takes has a value (value NULL: the name
 * came without '=') and came once (times: how often the query names it),
 * else a 400 bad-query problem naming it. */
api_err api_check_query_value(const char *name, const char *value, int times, api_problem *pb);
/* The representation of a result route from ?format= (may be NULL) and
 * Accept (may be NULL): *csv 0 (JSON) or 1 (CSV); 400 for another format,
 * 406 when Accept names neither. Other routes: JSON, API_OK. */
api_err api_negotiate(const api_route *rt, const char *format, const char *accept, int *csv,
		      api_problem *pb);
/* The options of GET /sessions/{id}/stream from its query parameters and
 * headers (each NULL when absent): ?format= sse or ndjson (without it,
 * an Accept naming application/x-ndjson), ?fields= (api_parse_fields),
 * ?rate= in (0, 100000], ?limit= an integer from 1 to API_STREAM_LIMIT_MAX
 * and the record to resume after, Last-Event-ID or else ?since=, an
 * integer from 0 to API_STREAM_ID_MAX (each refusal with its range as min
 * and max). API_OK or a 400 bad-query problem naming the parameter. */
/* The most records ?limit= takes: 2^53, the largest count a JSON number
 * (a double) holds exactly, so that a refusal's max is the number itself
 * (a stream of a million records a second would take 285 years). */
#define API_STREAM_LIMIT_MAX 9007199254740992
/* The largest record id Last-Event-ID and ?since= take: 2^53 too, for the
 * same reason (ids count a session's records from 0; 2^63 - 1, the end
 * before, is no number JSON states exactly). */
#define API_STREAM_ID_MAX 9007199254740992
typedef struct api_stream_query {
	int ndjson;
	unsigned fields;   /* API_F_* */
	double rate;       /* samples per simulated second, 0: all */
	uint64_t limit;    /* records, 0: no limit */
	int64_t resume;    /* record id to resume after, -1: from now */
} api_stream_query;
api_err api_parse_stream_query(const char *format, const char *accept, const char *fields,
			       const char *rate, const char *limit, const char *last_event_id,
			       const char *since, api_stream_query *q, api_problem *pb);
/* ?from=, ?to=, ?stride= of GET /sessions/{id}/trajectory (NULL or empty
 * when absent): finite numbers of seconds, from <= to, a stride given
 * > 0. Defaults -inf, +inf, 0 (0: as recorded). API_OK or a 400 bad-query. */
typedef struct api_trajectory_query {
	double from, to, stride;
} api_trajectory_query;
api_err api_parse_trajectory_query(const char *from, const char *to, const char *stride,
				   api_trajectory_query *q, api_problem *pb);
/* The spacing of the rows a ?stride= of `asked` s gives on a history
 * recorded every `recorded` s: a whole multiple k of it (within 1e-6 of
 * one, so 0.036000000000000004 is 3 x 0.012) gives k x recorded, to the
 * nanosecond as times are, in *spacing (never the asked value when that
 * is off the grid: rows would drop out where the two drift apart). Else
 * a 400 bad-query naming stride and the recorded spacing. */
api_err api_trajectory_stride(double asked, double recorded, double *spacing, api_problem *pb);
/* The page a problem type URI serves (/api/v1/problems/SLUG): malloc'd
 * HTML, or NULL for an unknown slug. */
char *api_problem_page(const char *slug);

#endif
