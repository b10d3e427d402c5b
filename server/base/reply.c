/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * reply.c - building and queueing HTTP responses.
 *
 * Every response goes through srv_queue, which counts its status for
 * /metrics. Bodies are malloc'd text handed over to libmicrohttpd, which
 * frees them when the response is destroyed. Problems are RFC 9457
 * application/problem+json bodies written by api/.
 */
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>

#include "metrics.h"
#include "reply.h"
#include "util.h"

enum MHD_Result srv_queue(srv_req *r, int status, struct MHD_Response *resp)
{
	if (!resp)
		return MHD_NO;
	if (r->cors_origin) {
		MHD_add_response_header(resp, "Access-Control-Allow-Origin",
					r->cors_origin);
		MHD_add_response_header(resp, "Access-Control-Expose-Headers",
					"Location, Retry-After, "
					"WWW-Authenticate");
		MHD_add_response_header(resp, MHD_HTTP_HEADER_VARY, "Origin");
	}
	srv_metrics_count(status);
	enum MHD_Result rc = MHD_queue_response(r->conn, (unsigned)status,
						resp);
	MHD_destroy_response(resp);
	srv_log(SRV_LOG_DEBUG, "%s %s -> %d", r->method, r->url, status);
	return rc;
}

/* Queue text (taken) with its type, no-store and up to two more headers
 * (name/value pairs; a NULL name or value skips one). */
static enum MHD_Result reply_text(srv_req *r, int status, const char *ctype,
				  char *text, const char *const extra[4])
{
	if (!text)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	struct MHD_Response *resp = MHD_create_response_from_buffer(
		strlen(text), text, MHD_RESPMEM_MUST_FREE);
	if (!resp) {
		free(text);
		return MHD_NO;
	}
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, ctype);
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL,
				"no-store");
	for (int i = 0; i < 4; i += 2)
		if (extra[i] && extra[i + 1])
			MHD_add_response_header(resp, extra[i], extra[i + 1]);
	return srv_queue(r, status, resp);
}

enum MHD_Result srv_reply(srv_req *r, int status, const char *ctype,
			  char *text, const char *extra_name,
			  const char *extra_value)
{
	const char *const extra[4] = {extra_name, extra_value, NULL, NULL};
	return reply_text(r, status, ctype, text, extra);
}

enum MHD_Result srv_reply_json(srv_req *r, int status, char *text)
{
	return srv_reply(r, status, "application/json", text, NULL, NULL);
}

enum MHD_Result srv_reply_created(srv_req *r, int status, char *text,
				  const char *prefix, const char *id)
{
	char location[96];
	snprintf(location, sizeof location, "%s/%s", prefix, id);
	return srv_reply(r, status, "application/json", text,
			 MHD_HTTP_HEADER_LOCATION, location);
}

enum MHD_Result srv_reply_empty(srv_req *r)
{
	struct MHD_Response *resp =
		MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT);
	return srv_queue(r, 204, resp);
}

enum MHD_Result srv_reply_not_found(srv_req *r, const char *what)
{
	return srv_fail(r, API_NOTFOUND, NULL, "no %s with id \"%.40s\"", what, r->arg[0]);
}

enum MHD_Result srv_reply_deleted(srv_req *r, int removed, const char *what)
{
	return removed ? srv_reply_empty(r) : srv_reply_not_found(r, what);
}

enum MHD_Result srv_reply_static(srv_req *r, int status, const char *ctype,
				 const void *data, size_t len)
{
	struct MHD_Response *resp = MHD_create_response_from_buffer(
		len, (void *)data, MHD_RESPMEM_PERSISTENT);
	if (!resp)
		return MHD_NO;
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE, ctype);
	return srv_queue(r, status, resp);
}

enum MHD_Result srv_reply_problem(srv_req *r, const api_problem *pb,
				  const char *allow)
{
	return srv_reply_problem_with(r, pb, MHD_HTTP_HEADER_ALLOW, allow);
}

enum MHD_Result srv_reply_problem_with(srv_req *r, const api_problem *pb,
				       const char *name, const char *value)
{
	char *text = api_problem_json(pb, r->url);
	int status = api_status(pb->code);
	if (!text)
		return MHD_NO;
	struct MHD_Response *resp = MHD_create_response_from_buffer(
		strlen(text), text, MHD_RESPMEM_MUST_FREE);
	if (!resp) {
		free(text);
		return MHD_NO;
	}
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE,
				"application/problem+json");
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL,
				"no-store");
	if (name && value)
		MHD_add_response_header(resp, name, value);
	if (status == 429 || status == 503) {
		char after[24];
		snprintf(after, sizeof after, "%d",
			 pb->retry_after > 0 ? pb->retry_after : 1);
		MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, after);
	}
	if (pb->close)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_CONNECTION, "close");
	return srv_queue(r, status, resp);
}

enum MHD_Result srv_fail(srv_req *r, api_err code, const char *field,
			 const char *fmt, ...)
{
	api_problem pb;
	char detail[sizeof pb.detail];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(detail, sizeof detail, fmt, ap);
	va_end(ap);
	api_fail(&pb, code, field, "%s", detail);
	return srv_reply_problem(r, &pb, NULL);
}

const char *srv_query(srv_req *r, const char *key)
{
	return MHD_lookup_connection_value(r->conn, MHD_GET_ARGUMENT_KIND, key);
}

int srv_client_fd(srv_req *r)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(r->conn, MHD_CONNECTION_INFO_CONNECTION_FD);
	return ci ? ci->connect_fd : -1;
}

const char *srv_header(srv_req *r, const char *name)
{
	return MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, name);
}

typedef struct header_count {
	const char *name;
	int n;
} header_count;

static enum MHD_Result count_one(void *cls, enum MHD_ValueKind kind,
				 const char *key, const char *value)
{
	(void)kind;
	(void)value;
	header_count *hc = cls;
	hc->n += key && strcasecmp(key, hc->name) == 0;
	return MHD_YES;
}

int srv_header_count(srv_req *r, const char *name)
{
	header_count hc = {name, 0};
	MHD_get_connection_values(r->conn, MHD_HEADER_KIND, count_one, &hc);
	return hc.n;
}

enum MHD_Result srv_reply_result(srv_req *r, char *text)
{
	return srv_reply_result_with(r, text, NULL, NULL);
}

enum MHD_Result srv_reply_result_with(srv_req *r, char *text,
				      const char *name, const char *value)
{
	const char *const extra[4] = {MHD_HTTP_HEADER_VARY, "Accept", name,
				      value};
	return reply_text(r, 200, r->csv ? "text/csv" : "application/json",
			  text, extra);
}
