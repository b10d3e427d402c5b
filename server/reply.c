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
	srv_metrics_count(status);
	enum MHD_Result rc = MHD_queue_response(r->conn, (unsigned)status,
						resp);
	MHD_destroy_response(resp);
	srv_log(SRV_LOG_DEBUG, "%s %s -> %d", r->method, r->url, status);
	return rc;
}

enum MHD_Result srv_reply(srv_req *r, int status, const char *ctype,
			  char *text, const char *extra_name,
			  const char *extra_value)
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
	if (extra_name && extra_value)
		MHD_add_response_header(resp, extra_name, extra_value);
	return srv_queue(r, status, resp);
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
	if (allow)
		MHD_add_response_header(resp, MHD_HTTP_HEADER_ALLOW, allow);
	if (status == 429 || status == 503) {
		char after[24];
		snprintf(after, sizeof after, "%d",
			 pb->retry_after > 0 ? pb->retry_after : 1);
		MHD_add_response_header(resp, MHD_HTTP_HEADER_RETRY_AFTER, after);
	}
	if (strcmp(pb->budget, "connections") == 0) /* one too many: close it */
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

const char *srv_header(srv_req *r, const char *name)
{
	return MHD_lookup_connection_value(r->conn, MHD_HEADER_KIND, name);
}

int srv_need_json(srv_req *r, int empty_ok, enum MHD_Result *result)
{
	if (r->json_body || (empty_ok && r->body_len == 0 &&
			     !r->has_content_type))
		return 1;
	const char *ct = srv_header(r, MHD_HTTP_HEADER_CONTENT_TYPE);
	*result = srv_fail(r, API_MEDIATYPE, NULL,
			   "the body must be sent as Content-Type: "
			   "application/json (got \"%.60s\")",
			   ct ? ct : "none");
	return 0;
}

enum MHD_Result srv_reply_result(srv_req *r, char *text)
{
	return srv_reply(r, 200, r->csv ? "text/csv" : "application/json", text,
			 MHD_HTTP_HEADER_VARY, "Accept");
}
