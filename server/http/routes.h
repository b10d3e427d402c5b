/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * routes.h - the route table and the callbacks given to libmicrohttpd.
 */
#ifndef CONVSIM_ROUTES_H
#define CONVSIM_ROUTES_H

#include "config.h"
#include "reply.h"

/* cfg (borrowed for the daemon's life) gives --max-body. Checks that
 * every row of the API's route table has its handler: -1 (each missing
 * one told on stderr) if not, the daemon does not start. */
int srv_routes_init(const srv_config *cfg);
/* The access handler and completion callback given to MHD. */
enum MHD_Result srv_dispatch(void *cls, struct MHD_Connection *conn,
			     const char *url, const char *method,
			     const char *version, const char *upload_data,
			     size_t *upload_data_size, void **con_cls);
/* The URI log callback: makes the request's state before libmicrohttpd
 * splits the query, and cuts a query of more parameters than any route
 * takes (answered 431 by the access handler). */
void *srv_uri_seen(void *cls, const char *uri, struct MHD_Connection *conn);
void srv_request_done(void *cls, struct MHD_Connection *conn,
		      void **con_cls, enum MHD_RequestTerminationCode toe);

/* What a request's method and path come to, decided by the route table
 * alone (no libmicrohttpd, no state: the access handler acts on it, the
 * fuzz harness tests/fuzz/fuzz_route.c checks it). HEAD is GET. */
typedef enum {
	SRV_ROUTE_FOUND,         /* the route's api_route_id, with its path arguments */
	SRV_ROUTE_METHOD,        /* 405: the path exists with the methods in allow */
	SRV_ROUTE_NOT_FOUND,     /* 404: an unknown path under /api */
	SRV_ROUTE_STATIC_METHOD, /* 405: a static file asked for with another method */
	SRV_ROUTE_STATIC,        /* a static file of --web-root */
} srv_route_kind;
typedef struct srv_route_match {
	srv_route_kind kind;
	size_t index;                /* FOUND: the route's api_route_id */
	const char *method, *pattern; /* FOUND: the entry's (static) */
	char arg[2][64];             /* FOUND: the "*" segments */
	char allow[96];              /* METHOD: the Allow header */
} srv_route_match;
void srv_route_resolve(const char *method, const char *url, srv_route_match *m);

#endif
