/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * reply.h - one HTTP request as the handlers see it, and the ways to
 * answer it (libmicrohttpd stays behind these, in server/ only).
 *
 * Every response goes through srv_queue, which counts its status for
 * /metrics. Handlers return what these return.
 */
#ifndef CONVSIM_REPLY_H
#define CONVSIM_REPLY_H

#include <microhttpd.h>
#include <stddef.h>

#include "api.h"

typedef struct srv_req {
	struct MHD_Connection *conn;
	const char *method;
	const char *url;
	char arg[2][64];       /* path parameters ("*" segments) */
	const char *body;      /* NUL-terminated, body_len bytes */
	size_t body_len;
	const char *cors_origin; /* an allowed Origin (gate.c), or NULL */
	int csv;               /* a result route answers CSV (negotiated) */
	const struct srv_job_kind *job; /* a job route's kind (job.h), or NULL */
} srv_req;

typedef enum MHD_Result (*srv_handler)(srv_req *r);

/* Queue a reply. text is malloc'd and taken (freed here); NULL text gives
 * a 503 problem. extra_name/extra_value add one header (may be NULL). */
enum MHD_Result srv_reply(srv_req *r, int status, const char *ctype,
			  char *text, const char *extra_name,
			  const char *extra_value);
enum MHD_Result srv_reply_json(srv_req *r, int status, char *text);
/* 201 or 202 with a JSON body (taken) and Location: prefix/id. */
enum MHD_Result srv_reply_created(srv_req *r, int status, char *text,
				  const char *prefix, const char *id);
/* 204 without a body. */
enum MHD_Result srv_reply_empty(srv_req *r);
/* 404 for r->arg[0], an id no `what` ("session", "sweep") has: the one
 * answer of every route of an object to an unknown id. */
enum MHD_Result srv_reply_not_found(srv_req *r, const char *what);
/* DELETE's answer: 204 when this request unlinked the object (removed
 * nonzero), else srv_reply_not_found's 404: another DELETE unlinked it
 * between this one's lookup and its own unlink, and one deletion has one
 * 204. */
enum MHD_Result srv_reply_deleted(srv_req *r, int removed, const char *what);
/* Queue a static, borrowed buffer (not freed). */
enum MHD_Result srv_reply_static(srv_req *r, int status, const char *ctype,
				 const void *data, size_t len);
/* RFC 9457 problem reply for *pb (405 adds Allow from allow if given). */
enum MHD_Result srv_reply_problem(srv_req *r, const api_problem *pb,
				  const char *allow);
/* The same with one more header name: value (either may be NULL). */
enum MHD_Result srv_reply_problem_with(srv_req *r, const api_problem *pb,
				       const char *name, const char *value);
enum MHD_Result srv_fail(srv_req *r, api_err code, const char *field,
			 const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* Queue a response (taken) and count its status for /metrics; a request
 * from an allowed origin gets Access-Control-Allow-Origin and Vary. */
enum MHD_Result srv_queue(srv_req *r, int status, struct MHD_Response *resp);
/* Query argument or NULL; header value or NULL (borrowed from the
 * connection). */
const char *srv_query(srv_req *r, const char *key);
const char *srv_header(srv_req *r, const char *name);
/* The client's socket (borrowed while the request is handled; -1 if
 * unknown): a request that settles before it answers looks there whether
 * its client left (util.h srv_peer_gone). */
int srv_client_fd(srv_req *r);
/* How many times the header name (any case) was sent. */
int srv_header_count(srv_req *r, const char *name);
/* 200 with a result in the negotiated representation (r->csv): text is
 * JSON or CSV accordingly (taken). */
enum MHD_Result srv_reply_result(srv_req *r, char *text);
/* The same with one more header (name or value NULL: none). */
enum MHD_Result srv_reply_result_with(srv_req *r, char *text,
				      const char *name, const char *value);

#endif
