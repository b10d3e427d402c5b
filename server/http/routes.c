/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * routes.c - the route table and the libmicrohttpd access handler.
 *
 * Routes are one static table: the API's rows {method, pattern, query
 * parameters, ...} (api/routes.c) and, by the same id, this file's
 * {handler, job kind}; "*" in a pattern matches one path segment and
 * becomes a path argument. The access
 * handler first passes the request's headers through the gate (gate.c:
 * Host, Origin, token, the JSON media type of mutating requests) and
 * answers, before any byte of a body is read, a body too large for
 * --max-body (413) and one that would not be read: an unknown route or
 * method (404, 405) or GET, HEAD, DELETE with a body (400). It then
 * collects the body under its deadline (conns.h: closed when slower than
 * --min-body-rate; 413 while it is read for chunked bodies), then calls
 * the one handler. A path that exists with another method gets 405 with
 * Allow; unknown paths under /api/ get 404; everything else is a static
 * file of web/. Query
 * parameters and the representation are checked against the API's route
 * table (api/routes.c) before the handler runs.
 * Per-request state is freed in the completion callback.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "api_routes.h"
#include "budget.h"
#include "catalog.h"
#include "conns.h"
#include "gate.h"
#include "job.h"
#include "routes.h"
#include "session_http.h"
#include "static.h"
#include "stream.h"
#include "util.h"

/* The server's half of the one route table: the handler (and a job
 * route's kind, job.h) of each row of the API's table (api/routes.c), by
 * its id. Method, path, query parameters and representations are the
 * API's; a row without a handler stops the daemon at start-up. */
typedef struct route {
	srv_handler handler;
	const srv_job_kind *job;
} route;

static const route routes[API_R_COUNT] = {
	[API_R_SESSIONS_CREATE] = {srv_h_sessions_create, NULL},
	[API_R_SESSIONS_LIST] = {srv_h_sessions_list, NULL},
	[API_R_SESSION_GET] = {srv_h_session_get, NULL},
	[API_R_SESSION_PATCH] = {srv_h_session_patch, NULL},
	[API_R_SESSION_DELETE] = {srv_h_session_delete, NULL},
	[API_R_SESSION_STREAM] = {srv_h_stream, NULL},
	[API_R_SESSION_TRAJECTORY] = {srv_h_trajectory, NULL},
	[API_R_EXPERIMENTS_CREATE] = {srv_h_job_create, &srv_experiment_job},
	[API_R_EXPERIMENTS_LIST] = {srv_h_job_list, &srv_experiment_job},
	[API_R_EXPERIMENT_GET] = {srv_h_job_get, &srv_experiment_job},
	[API_R_EXPERIMENT_DELETE] = {srv_h_job_delete, &srv_experiment_job},
	[API_R_SWEEPS_CREATE] = {srv_h_job_create, &srv_sweep_job},
	[API_R_SWEEPS_LIST] = {srv_h_job_list, &srv_sweep_job},
	[API_R_SWEEP_GET] = {srv_h_job_get, &srv_sweep_job},
	[API_R_SWEEP_DELETE] = {srv_h_job_delete, &srv_sweep_job},
	[API_R_FITS_CREATE] = {srv_h_job_create, &srv_fit_job},
	[API_R_FITS_LIST] = {srv_h_job_list, &srv_fit_job},
	[API_R_FIT_GET] = {srv_h_job_get, &srv_fit_job},
	[API_R_FIT_DELETE] = {srv_h_job_delete, &srv_fit_job},
	[API_R_PRESETS] = {srv_h_presets, NULL},
	[API_R_HEALTH] = {srv_h_health, NULL},
	[API_R_OPENAPI] = {srv_h_openapi, NULL},
	[API_R_PROBLEM] = {srv_h_problem, NULL},
	[API_R_METRICS] = {srv_h_metrics, NULL},
};

static const srv_config *cfg;

int srv_routes_init(const srv_config *config)
{
	cfg = config;
	size_t n;
	const api_route *rt = api_routes(&n);
	int bad = n != API_R_COUNT;
	for (size_t i = 0; i < n && i < API_R_COUNT; i++)
		if (!rt[i].method || !routes[i].handler) {
			fprintf(stderr, "convsimd: route %zu (%s %s) has no %s\n", i, rt[i].method ? rt[i].method : "?",
				rt[i].pattern ? rt[i].pattern : "?",
				rt[i].method ? "handler" : "row in the API's route table");
			bad = 1;
		}
	return bad ? -1 : 0;
}

typedef struct req_state {
	srv_req r;
	char *body;
	size_t len, cap;
	int too_large;
	size_t query_params; /* over SRV_MAX_QUERY_PARAMS: the query was cut */
	srv_conn *live;      /* the connection's deadlines (conns.h) */
	size_t nul_at;       /* 1 + where the target has %00; 0: nowhere */
	int nul_in_query;    /* that %00 is in the query */
} req_state;

/* More query parameters than any route takes (the most is a handful). */
#define SRV_MAX_QUERY_PARAMS 64

void *srv_uri_seen(void *cls, const char *uri, struct MHD_Connection *conn)
{
	(void)cls;
	srv_conn_request_line(srv_budget_live(conn));
	req_state *st = calloc(1, sizeof *st);
	char *query = strchr(uri, '?');
	if (!st)
		return st;
	/* libmicrohttpd decodes %00 into a NUL that ends the path or value
	 * there (/api/v1/health%00x would be /api/v1/health): such a target
	 * names nothing, and first_look refuses it */
	const char *nul = strstr(uri, "%00");
	if (nul) {
		st->nul_at = (size_t)(nul - uri) + 1;
		st->nul_in_query = query && nul > query;
	}
	if (!query)
		return st;
	size_t n = 1;
	for (const char *c = query + 1; *c; c++)
		n += *c == '&' || *c == ';';
	if (n > SRV_MAX_QUERY_PARAMS) {
		/* libmicrohttpd splits the query into one record per
		 * parameter in the connection's memory pool once this
		 * returns; hundreds of them exhaust the pool and it closes
		 * the connection without an answer. The text is the
		 * connection's own read buffer: end it after the '?', so
		 * that nothing is split and first_look can answer 431. */
		st->query_params = n;
		query[1] = '\0';
	}
	return st;
}

/* Match url against pattern; path arguments go to arg. */
static int match(const char *pattern, const char *url, char arg[2][64])
{
	int nargs = 0;
	const char *p = pattern, *u = url;
	while (*p && *u) {
		if (*p == '*') {
			const char *end = strchr(u, '/');
			size_t n = end ? (size_t)(end - u) : strlen(u);
			if (n == 0 || n >= 64 || nargs >= 2)
				return 0;
			memcpy(arg[nargs], u, n);
			arg[nargs++][n] = '\0';
			u += n;
			p++;
		} else if (*p++ != *u++) {
			return 0;
		}
	}
	return *p == '\0' && *u == '\0';
}

typedef struct query_check {
	const api_route *rt;
	api_problem *pb;
	int bad;
	srv_req *r;
	const char *key; /* count_key: the name counted, and how often */
	int times;
} query_check;

static enum MHD_Result count_key(void *cls, enum MHD_ValueKind kind, const char *key,
				 const char *value)
{
	(void)kind;
	(void)value;
	query_check *qc = cls;
	qc->times += strcmp(key, qc->key) == 0;
	return MHD_YES;
}

/* A parameter the route takes, with a value, once (the query holds at most
 * SRV_MAX_QUERY_PARAMS: counting each is cheap). */
static enum MHD_Result check_one_query(void *cls, enum MHD_ValueKind kind, const char *key,
				       const char *value)
{
	query_check *qc = cls;
	if (qc->bad)
		return MHD_NO;
	api_err e = api_check_query(qc->rt, key, qc->pb);
	if (e == API_OK) {
		query_check count = {.key = key};
		MHD_get_connection_values(qc->r->conn, kind, count_key, &count);
		e = api_check_query_value(key, value, count.times, qc->pb);
	}
	if (e == API_OK)
		return MHD_YES;
	qc->bad = 1;
	return MHD_NO;
}

/* The checks the API's route table asks for before a handler runs: every
 * query parameter known to the route, the representation (r->csv) of a
 * result route. */
static enum MHD_Result call_route(srv_req *r, size_t id)
{
	size_t n;
	const api_route *rt = &api_routes(&n)[id];
	api_problem pb;
	query_check qc = {.rt = rt, .pb = &pb, .r = r};
	MHD_get_connection_values(r->conn, MHD_GET_ARGUMENT_KIND, check_one_query, &qc);
	if (qc.bad || api_negotiate(rt, rt->tables ? srv_query(r, "format") : NULL,
				    srv_header(r, MHD_HTTP_HEADER_ACCEPT), &r->csv, &pb) != API_OK)
		return srv_reply_problem(r, &pb, NULL);
	r->job = routes[id].job;
	return routes[id].handler(r);
}

void srv_route_resolve(const char *method, const char *url, srv_route_match *m)
{
	memset(m, 0, sizeof *m);
	if (strcmp(method, "HEAD") == 0)
		method = "GET";
	int path_known = 0;
	size_t n;
	const api_route *routes = api_routes(&n);
	for (size_t i = 0; i < n; i++) {
		char arg[2][64];
		if (!match(routes[i].pattern, url, arg))
			continue;
		path_known = 1;
		if (strcmp(routes[i].method, method) == 0) {
			m->kind = SRV_ROUTE_FOUND;
			m->index = i;
			m->method = routes[i].method;
			m->pattern = routes[i].pattern;
			memcpy(m->arg, arg, sizeof arg);
			return;
		}
		char *allow = m->allow;
		if (!strstr(allow, routes[i].method)) {
			size_t at = strlen(allow);
			snprintf(allow + at, sizeof m->allow - at, "%s%s",
				 at ? ", " : "", routes[i].method);
			if (strcmp(routes[i].method, "GET") == 0) {
				at = strlen(allow);
				snprintf(allow + at, sizeof m->allow - at,
					 ", HEAD");
			}
		}
	}
	if (path_known)
		m->kind = SRV_ROUTE_METHOD;
	else if (strncmp(url, "/api/", 5) == 0 || strcmp(url, "/api") == 0)
		m->kind = SRV_ROUTE_NOT_FOUND;
	else if (strcmp(method, "GET") != 0)
		m->kind = SRV_ROUTE_STATIC_METHOD;
	else
		m->kind = SRV_ROUTE_STATIC;
}

static enum MHD_Result route_request(srv_req *r)
{
	srv_route_match m;
	srv_route_resolve(r->method, r->url, &m);
	api_problem pb;
	switch (m.kind) {
	case SRV_ROUTE_FOUND:
		memcpy(r->arg, m.arg, sizeof m.arg);
		return call_route(r, m.index);
	case SRV_ROUTE_METHOD:
		api_fail(&pb, API_METHOD, NULL,
			 "%s is not allowed on %s; allowed: %s", r->method,
			 r->url, m.allow);
		return srv_reply_problem(r, &pb, m.allow);
	case SRV_ROUTE_NOT_FOUND:
		api_fail(&pb, API_NOTFOUND, NULL, "no such resource: %s",
			 r->url);
		return srv_reply_problem(r, &pb, NULL);
	case SRV_ROUTE_STATIC_METHOD:
		api_fail(&pb, API_METHOD, NULL,
			 "static files allow GET and HEAD only");
		return srv_reply_problem(r, &pb, "GET, HEAD");
	default:
		return srv_h_static(r);
	}
}

/* Does the request announce a body (Content-Length above 0, or
 * Transfer-Encoding)? The header that says so goes to *field. */
static int body_declared(srv_req *r, const char **field)
{
	const char *cl = srv_header(r, MHD_HTTP_HEADER_CONTENT_LENGTH);
	if (cl && strtoull(cl, NULL, 10) > 0) {
		*field = MHD_HTTP_HEADER_CONTENT_LENGTH;
		return 1;
	}
	*field = MHD_HTTP_HEADER_TRANSFER_ENCODING;
	return srv_header(r, MHD_HTTP_HEADER_TRANSFER_ENCODING) != NULL;
}

/* A request with a body that will not be read is answered now, before
 * any of its bytes: a route or method that does not exist (404, 405), or
 * a method that takes none (GET, HEAD, DELETE: 400). libmicrohttpd then
 * discards the body and closes the connection. 1 if answered. */
static int refuse_body(srv_req *r, enum MHD_Result *result)
{
	const char *field;
	if (!body_declared(r, &field))
		return 0;
	srv_route_match m;
	srv_route_resolve(r->method, r->url, &m);
	if (m.kind != SRV_ROUTE_FOUND && m.kind != SRV_ROUTE_STATIC) {
		*result = route_request(r);
		return 1;
	}
	if (strcmp(r->method, "POST") == 0 || strcmp(r->method, "PATCH") == 0)
		return 0;
	*result = srv_fail(r, API_BADREQUEST, field,
			   "%s takes no body, and this request announces one "
			   "(%s); nothing of it was read: send the request "
			   "without it", r->method, field);
	return 1;
}

/* A 413 (*pb, its detail given) with --max-body as the limit that refused
 * it: no field is at fault. */
static enum MHD_Result too_large(srv_req *r, api_problem *pb)
{
	api_budget(pb, "body-bytes", (double)cfg->max_body, 0);
	return srv_reply_problem(r, pb, NULL);
}

/* The request as first seen, headers only: the client's budget, the
 * gate, the declared body (its size, whether the route reads one), all
 * answered before a byte of the body is read. 1 if answered (*result). */
static int first_look(srv_req *r, enum MHD_Result *result)
{
	api_problem pb;
	if (srv_budget_client_over(r->conn, &pb)) { /* before anything else */
		*result = srv_reply_problem(r, &pb, NULL);
		return 1;
	}
	const req_state *st = (const req_state *)r;
	if (st->nul_at) {
		*result = srv_fail(r, st->nul_in_query ? API_QUERY : API_BADREQUEST,
				   st->nul_in_query ? "query" : "path",
				   "the request target has %%00 (a NUL byte) at "
				   "byte %zu; no path or query value holds one",
				   st->nul_at - 1);
		return 1;
	}
	if (st->query_params) {
		api_fail(&pb, API_HEADERS, NULL, "the query has %zu parameters; no route takes more "
			 "than %d", st->query_params, SRV_MAX_QUERY_PARAMS);
		api_budget(&pb, "query-parameters", SRV_MAX_QUERY_PARAMS, 0);
		*result = srv_reply_problem(r, &pb, NULL);
		return 1;
	}
	if (!srv_gate_check(r, result))
		return 1;
	if (srv_header_count(r, MHD_HTTP_HEADER_CONTENT_LENGTH) > 1) {
		api_fail(&pb, API_BADREQUEST, "Content-Length",
			 "Content-Length is given more than once (RFC 9112 "
			 "section 6.3)");
		*result = srv_reply_problem_with(r, &pb,
						 MHD_HTTP_HEADER_CONNECTION,
						 "close");
		return 1;
	}
	const char *cl = srv_header(r, MHD_HTTP_HEADER_CONTENT_LENGTH);
	if (cl && strtoull(cl, NULL, 10) > cfg->max_body) {
		api_fail(&pb, API_TOOLARGE, NULL, "the body has %.30s bytes; the limit is %zu "
			 "(--max-body)", cl, cfg->max_body);
		*result = too_large(r, &pb);
		return 1;
	}
	return refuse_body(r, result);
}

enum MHD_Result srv_dispatch(void *cls, struct MHD_Connection *conn,
			     const char *url, const char *method,
			     const char *version, const char *upload_data,
			     size_t *upload_data_size, void **con_cls)
{
	(void)cls;
	(void)version;
	req_state *st = *con_cls;
	if (!st || !st->r.conn) { /* the first call (srv_uri_seen made st) */
		if (!st)
			st = calloc(1, sizeof *st);
		if (!st)
			return MHD_NO;
		*con_cls = st;
		st->r.conn = conn;
		st->r.method = method;
		st->r.url = url;
		st->r.body = "";
		st->live = srv_budget_live(conn);
		enum MHD_Result result = MHD_YES;
		const char *field;
		if (!first_look(&st->r, &result) &&
		    body_declared(&st->r, &field))
			srv_conn_body_start(st->live); /* under its deadline */
		else
			srv_conn_busy(st->live, 1); /* answered now or next */
		return result;
	}
	if (*upload_data_size) {
		size_t n = *upload_data_size;
		*upload_data_size = 0;
		if (!srv_conn_body_read(st->live, n))
			return MHD_NO; /* slower than --min-body-rate: closed */
		if (st->too_large || st->len + n > cfg->max_body) {
			st->too_large = 1;
			return MHD_YES;
		}
		if (st->len + n + 1 > st->cap) {
			size_t cap = st->cap ? st->cap : 1024;
			while (cap < st->len + n + 1)
				cap *= 2;
			char *b = realloc(st->body, cap);
			if (!b)
				return MHD_NO;
			st->body = b;
			st->cap = cap;
		}
		memcpy(st->body + st->len, upload_data, n);
		st->len += n;
		st->body[st->len] = '\0';
		return MHD_YES;
	}
	srv_conn_busy(st->live, 1); /* the body is in: answered now */
	st->r.body = st->body ? st->body : "";
	st->r.body_len = st->len;
	if (st->too_large) {
		api_problem pb;
		api_fail(&pb, API_TOOLARGE, NULL, "the body exceeds the limit of %zu byte%s "
			 "(--max-body)", cfg->max_body, api_plural((double)cfg->max_body, "", "s"));
		return too_large(&st->r, &pb);
	}
	if (srv_stopping() && strncmp(url, "/api/", 5) == 0)
		return srv_fail(&st->r, API_UNAVAILABLE, NULL,
				"the daemon is shutting down");
	return route_request(&st->r);
}

void srv_request_done(void *cls, struct MHD_Connection *conn,
		      void **con_cls, enum MHD_RequestTerminationCode toe)
{
	(void)cls;
	(void)toe;
	req_state *st = *con_cls;
	(void)conn;
	if (st && st->r.conn)
		srv_conn_busy(st->live, 0);
	if (!st)
		return;
	free(st->body);
	free(st);
	*con_cls = NULL;
}
