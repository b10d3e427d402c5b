/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * routes.c - the API's routes as data: method, path, the query parameters
 * each takes and whether it answers results (JSON or CSV). The server
 * checks every request against this table (unknown query parameters are a
 * 400, an Accept it cannot serve a 406) and openapi.c describes the same
 * table, so the document and the checks cannot drift. The values of the
 * stream's and the trajectory's parameters are parsed here too.
 */
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "api_routes.h"
#include "decimal.h"
#include "json_int.h"
#include "suggest.h"

/* A macro's value as text, for the schemas below. */
#define TEXT_OF(x) #x
#define TEXT(x) TEXT_OF(x)

static const api_query queries[] = {
	{API_Q_FORMAT, "format", "{\"type\":\"string\",\"enum\":[\"json\",\"csv\"]}",
	 "representation; overrides Accept (application/json or text/csv)"},
	{API_Q_FROM, "from", "{\"type\":\"number\"}", "first row's time, s"},
	{API_Q_TO, "to", "{\"type\":\"number\"}", "last row's time, s"},
	{API_Q_STRIDE, "stride", "{\"type\":\"number\",\"exclusiveMinimum\":0}",
	 "rows this far apart, s: a multiple of the recorded spacing (the answer's stride)"},
	{API_Q_STREAM_FORMAT, "format", "{\"type\":\"string\",\"enum\":[\"sse\",\"ndjson\"]}",
	 "Server-Sent Events (default) or NDJSON (also Accept: application/x-ndjson)"},
	{API_Q_FIELDS, "fields", "{\"type\":\"string\"}",
	 "comma list of trough, orbit, rotor, eliminators, feed, energy, elements, all, default"},
	{API_Q_RATE, "rate", "{\"type\":\"number\",\"exclusiveMinimum\":0,\"maximum\":100000}",
	 "samples per simulated second (thins the session's sample_rate; a stream of a running "
	 "paced session holds its records' CPU in --max-paced-cores, fewer cost less)"},
	{API_Q_LIMIT, "limit",
	 "{\"type\":\"integer\",\"minimum\":1,\"maximum\":" TEXT(API_STREAM_LIMIT_MAX) "}",
	 "end after this many records"},
	{API_Q_SINCE, "since",
	 "{\"type\":\"integer\",\"minimum\":0,\"maximum\":" TEXT(API_STREAM_ID_MAX) "}",
	 "resume after this record id (as Last-Event-ID)"},
	{API_Q_SCOPE, "scope", "{\"type\":\"string\",\"enum\":[\"all\",\"local\"]}",
	 "all (default): this replica's entries and those of its --peers; local: this replica's "
	 "only"},
	{API_Q_ONLY, "only", "{\"type\":\"string\",\"enum\":[\"running\"]}",
	 "running: stop it only while it runs; one that has ended answers 409 and is kept"},
};

#define TRAJ (API_Q_FORMAT | API_Q_FROM | API_Q_TO | API_Q_STRIDE)
#define STREAM (API_Q_STREAM_FORMAT | API_Q_FIELDS | API_Q_RATE | API_Q_LIMIT | API_Q_SINCE)
static const api_route routes[API_R_COUNT] = {
	[API_R_SESSIONS_CREATE] = {"POST", "/api/v1/sessions", 0, 0, "Create a session and start its worker",
	 "SessionCreate", 201, "Session", "400,413,415,422,429,503"},
	[API_R_SESSIONS_LIST] = {"GET", "/api/v1/sessions", API_Q_FORMAT | API_Q_SCOPE, 1,
	 "All sessions with live status (CSV: one summary row each)", NULL, 200, "SessionList",
	 "400,406"},
	[API_R_SESSION_GET] = {"GET", "/api/v1/sessions/*", API_Q_FORMAT, 1,
	 "One session: spec and live status (CSV: its summary row)", NULL, 200, "Session",
	 "400,404,406,503"},
	[API_R_SESSION_PATCH] = {"PATCH", "/api/v1/sessions/*", 0, 0,
	 "Change beta, beta_rate, rotation, omega_ss, the feed's m_n or mu, motor_on, running, "
	 "pace or until while it runs; answers the simulated time the change takes effect",
	 "Control", 200, "ControlResult", "400,404,409,413,415,422,503"},
	[API_R_SESSION_DELETE] = {"DELETE", "/api/v1/sessions/*", 0, 0, "Stop and remove the session", NULL, 204, "",
	 "400,404,415"},
	[API_R_SESSION_STREAM] = {"GET", "/api/v1/sessions/*/stream", STREAM, 0,
	 "Server-Sent Events or NDJSON of samples and events (503 budget cpu: the stream's CPU "
	 "would take a running paced session past --max-paced-cores)", NULL, 200, "StreamRecord",
	 "400,404,429,503"},
	[API_R_SESSION_TRAJECTORY] = {"GET", "/api/v1/sessions/*/trajectory", TRAJ, 1,
	 "The recorded, downsampled history (the CLI's trajectory columns)", NULL, 200,
	 "Trajectory", "400,404,406,503"},
	[API_R_EXPERIMENTS_CREATE] = {"POST", "/api/v1/experiments", 0, 0,
	 "Run a beta schedule; per segment the transport velocity and the reversal time",
	 "ExperimentCreate", 201, "Experiment", "400,404,409,413,415,422,429,503"},
	[API_R_EXPERIMENTS_LIST] = {"GET", "/api/v1/experiments", API_Q_FORMAT | API_Q_SCOPE, 1,
	 "All kept experiments (CSV: one row per segment)", NULL, 200, "ExperimentList", "400,406"},
	[API_R_EXPERIMENT_GET] = {"GET", "/api/v1/experiments/*", API_Q_FORMAT, 1,
	 "Progress and results (CSV: one row per segment)", NULL, 200, "Experiment",
	 "400,404,406"},
	[API_R_EXPERIMENT_DELETE] = {"DELETE", "/api/v1/experiments/*", API_Q_ONLY, 0,
	 "Stop it and forget it (a fresh session it created goes with it)", NULL, 204, "",
	 "400,404,409,415"},
	[API_R_SWEEPS_CREATE] = {"POST", "/api/v1/sweeps", 0, 0, "Measure v(beta) for the given rotations on the pool",
	 "SweepCreate", 202, "Sweep", "400,413,415,422,429,503"},
	[API_R_SWEEPS_LIST] = {"GET", "/api/v1/sweeps", API_Q_FORMAT | API_Q_SCOPE, 1,
	 "All kept sweeps (CSV: one row per sweep)", NULL, 200, "SweepList", "400,406"},
	[API_R_SWEEP_GET] = {"GET", "/api/v1/sweeps/*", API_Q_FORMAT, 1,
	 "Progress and results (CSV: one row per point, the CLI's sweep columns)", NULL, 200,
	 "Sweep", "400,404,406"},
	[API_R_SWEEP_DELETE] = {"DELETE", "/api/v1/sweeps/*", API_Q_ONLY, 0, "Cancel and forget", NULL, 204, "",
	 "400,404,409,415"},
	[API_R_FITS_CREATE] = {"POST", "/api/v1/fits", 0, 0,
	 "Fit free parameters to measured v(beta) points or peaks (Levenberg-Marquardt) as a job",
	 "FitCreate", 202, "Fit", "400,413,415,422,429,503"},
	[API_R_FITS_LIST] = {"GET", "/api/v1/fits", API_Q_FORMAT | API_Q_SCOPE, 1, "All kept fits with progress (CSV: one row each)",
	 NULL, 200, "FitList", "400,406"},
	[API_R_FIT_GET] = {"GET", "/api/v1/fits/*", API_Q_FORMAT, 1,
	 "Progress and result (CSV: parameters, data with residuals, curves)", NULL, 200, "Fit",
	 "400,404,406"},
	[API_R_FIT_DELETE] = {"DELETE", "/api/v1/fits/*", API_Q_ONLY, 0, "Cancel (a running fit stops) and forget", NULL,
	 204, "", "400,404,409,415"},
	[API_R_PRESETS] = {"GET", "/api/v1/presets", 0, 0, "Presets, the settings table, integrators", NULL, 200,
	 "Presets", "400"},
	[API_R_HEALTH] = {"GET", "/api/v1/health", 0, 0, "Liveness (503 with the same body while shutting down)",
	 NULL, 200, "Health", "400"},
	[API_R_OPENAPI] = {"GET", "/api/v1/openapi.json", 0, 0, "This document", NULL, 200, "application/json",
	 "400"},
	[API_R_PROBLEM] = {"GET", "/api/v1/problems/*", 0, 0, "What a problem type means", NULL, 200, "text/html",
	 "400,404"},
	[API_R_METRICS] = {"GET", "/metrics", 0, 0, "Prometheus text format", NULL, 200, "text/plain", "400"},
};

const api_route *api_routes(size_t *n)
{
	*n = sizeof routes / sizeof *routes;
	return routes;
}

const api_query *api_queries(size_t *n)
{
	*n = sizeof queries / sizeof *queries;
	return queries;
}

api_err api_check_query(const api_route *rt, const char *name, api_problem *pb)
{
	const char *allowed[sizeof queries / sizeof *queries];
	size_t n = 0;
	char list[160] = "";
	for (size_t i = 0; i < sizeof queries / sizeof *queries; i++) {
		if (!(rt->query & queries[i].bit))
			continue;
		if (strcmp(queries[i].name, name) == 0)
			return API_OK;
		allowed[n++] = queries[i].name;
		size_t at = strlen(list);
		snprintf(list + at, sizeof list - at, "%s%s", at ? ", " : "", queries[i].name);
	}
	const char *near = sim_suggest(name, allowed, n, sizeof *allowed);
	char hint[96] = "";
	if (near)
		snprintf(hint, sizeof hint, " (did you mean \"%s\"?)", near);
	return api_fail(pb, API_QUERY, name, "unknown query parameter \"%.40s\"%s; this route takes %s",
			name, hint, n ? list : "none");
}

api_err api_check_query_value(const char *name, const char *value, int times, api_problem *pb)
{
	if (!value)
		return api_fail(pb, API_QUERY, name, "query parameter \"%.40s\" needs a value "
				"(%.40s=...)", name, name);
	if (times > 1)
		return api_fail(pb, API_QUERY, name, "query parameter \"%.40s\" is given %d "
				"times; give it once", name, times);
	return API_OK;
}

/* The q value Accept gives to type ("text/csv"), 0..1; -1 if not named. */
static double accept_q(const char *accept, const char *type)
{
	double best = -1;
	const char *slash = strchr(type, '/');
	const char *p = accept;
	while (p && *p) {
		while (*p == ' ' || *p == ',')
			p++;
		size_t n = strcspn(p, ";,");
		while (n && p[n - 1] == ' ')
			n--;
		int match = (n == strlen(type) && strncasecmp(p, type, n) == 0) ||
			    (n == 3 && strncmp(p, "*/*", 3) == 0) ||
			    (n == (size_t)(slash - type) + 2 &&
			     strncasecmp(p, type, (size_t)(slash - type) + 1) == 0 && p[n - 1] == '*');
		double q = 1;
		const char *end = strchr(p, ',');
		const char *qs = strstr(p, ";q=");
		if (!qs)
			qs = strstr(p, "; q=");
		if (qs && (!end || qs < end))
			q = atof(strchr(qs, '=') + 1);
		/* an exact type outranks a wildcard of the same q */
		if (match && q > 0) {
			double rank = q + (n == strlen(type) ? 1e-3 : 0);
			if (rank > best)
				best = rank;
		}
		p = end;
	}
	return best;
}

api_err api_negotiate(const api_route *rt, const char *format, const char *accept, int *csv,
		      api_problem *pb)
{
	*csv = 0;
	if (!rt->tables)
		return API_OK;
	if (format) {
		if (strcmp(format, "json") == 0 || strcmp(format, "csv") == 0) {
			*csv = format[0] == 'c';
			return API_OK;
		}
		return api_fail(pb, API_QUERY, "format", "format must be json or csv (got \"%.40s\")",
				format);
	}
	if (!accept || !*accept)
		return API_OK;
	double qj = accept_q(accept, "application/json"), qc = accept_q(accept, "text/csv");
	if (qj < 0 && qc < 0)
		return api_fail(pb, API_NOTACCEPTABLE, NULL,
				"Accept: %.80s names neither application/json nor text/csv "
				"(or use ?format=json|csv)",
				accept);
	*csv = qc > qj;
	return API_OK;
}

/* The decimal digits of text (nothing else: no sign, no space) as a
 * number of at most max; 0 if text is not one. */
static int decimal(const char *text, uint64_t max, uint64_t *out)
{
	uint64_t n = 0;
	if (!*text)
		return 0;
	for (const char *c = text; *c; c++) {
		if (*c < '0' || *c > '9' || n > (max - (uint64_t)(*c - '0')) / 10)
			return 0;
		n = n * 10 + (uint64_t)(*c - '0');
	}
	*out = n;
	return 1;
}

api_err api_parse_stream_query(const char *format, const char *accept, const char *fields,
			       const char *rate, const char *limit, const char *last_event_id,
			       const char *since, api_stream_query *q, api_problem *pb)
{
	memset(q, 0, sizeof *q);
	q->resume = -1;
	if (format) {
		if (strcmp(format, "ndjson") == 0)
			q->ndjson = 1;
		else if (strcmp(format, "sse") != 0)
			return api_fail(pb, API_QUERY, "format", "format must be sse or ndjson");
	} else {
		q->ndjson = accept && strstr(accept, "application/x-ndjson");
	}
	q->fields = fields ? api_parse_fields(fields, pb) : API_F_DEFAULT;
	if (!q->fields)
		return pb->code;
	if (rate) {
		if (!sim_decimal(rate, &q->rate) || !(q->rate > 0 && q->rate <= 100000)) {
			api_fail(pb, API_QUERY, "rate", "rate must be a number of samples per "
				 "simulated second in (0, 100000]");
			pb->has_range = 1, pb->min = 0, pb->max = 100000; /* the open end as its limit */
			return API_QUERY;
		}
	}
	uint64_t n;
	if (limit) {
		if (!decimal(limit, API_STREAM_LIMIT_MAX, &n) || n == 0) {
			api_fail(pb, API_QUERY, "limit",
				 "limit must be a whole number of records from 1 to %" PRIu64
				 " (2^53)", (uint64_t)API_STREAM_LIMIT_MAX);
			pb->has_range = 1, pb->min = 1, pb->max = (double)API_STREAM_LIMIT_MAX;
			return API_QUERY;
		}
		q->limit = n;
	}
	const char *v = last_event_id ? last_event_id : since;
	if (v) {
		if (!decimal(v, API_STREAM_ID_MAX, &n)) {
			api_fail(pb, API_QUERY, last_event_id ? "Last-Event-ID" : "since",
				 "Last-Event-ID (or since) must be a record id, an integer from 0 "
				 "to %" PRIu64 " (2^53)", (uint64_t)API_STREAM_ID_MAX);
			pb->has_range = 1, pb->min = 0, pb->max = (double)API_STREAM_ID_MAX;
			return API_QUERY;
		}
		q->resume = (int64_t)n;
	}
	return API_OK;
}

/* A finite number of seconds from a query value (absent or empty: *out
 * stays). */
static api_err query_seconds(const char *key, const char *v, double *out, api_problem *pb)
{
	if (!v || !*v)
		return API_OK;
	double x;
	if (!sim_decimal(v, &x)) /* decimal.h: not 0x10, inf or nan */
		return api_fail(pb, API_QUERY, key, "%s must be a number of seconds (got \"%.40s\")",
				key, v);
	*out = x;
	return API_OK;
}

api_err api_parse_trajectory_query(const char *from, const char *to, const char *stride,
				   api_trajectory_query *q, api_problem *pb)
{
	q->from = -INFINITY;
	q->to = INFINITY;
	q->stride = 0;
	api_err e = query_seconds("from", from, &q->from, pb);
	if (e == API_OK)
		e = query_seconds("to", to, &q->to, pb);
	if (e == API_OK)
		e = query_seconds("stride", stride, &q->stride, pb);
	if (e != API_OK)
		return e;
	if (q->from > q->to)
		return api_fail(pb, API_QUERY, "from", "from (%g) must not exceed to (%g)", q->from,
				q->to);
	if (stride && *stride && !(q->stride > 0))
		return api_fail(pb, API_QUERY, "stride", "stride must be positive (s)");
	return API_OK;
}

api_err api_trajectory_stride(double asked, double recorded, double *spacing, api_problem *pb)
{
	double k = asked / recorded, whole = floor(k + 0.5);
	if (fabs(k - whole) > 1e-6 || k < 0.5) {
		char rec[40], got[40];
		api_fmt_double(rec, sizeof rec, recorded);
		api_fmt_double(got, sizeof got, asked);
		return api_fail(pb, API_QUERY, "stride",
				"stride must be a whole multiple of the recorded spacing, now %s s "
				"(got %s)", rec, got);
	}
	*spacing = sim_time_ns(whole * recorded);
	return API_OK;
}
