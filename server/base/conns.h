/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * conns.h - the open connections under deadlines, and room at the global
 * cap: libmicrohttpd admits up to SRV_CONN_HEADROOM connections beyond
 * --max-connections, and each one opened beyond the cap closes the
 * connection that has made the least progress (idle longest, headers or
 * body furthest behind; never one being answered, such as a stream) in
 * O(log n); likewise each one beyond --max-client-connections from one
 * client address closes that address's own connection with the least
 * progress (only when every one of them is busy is the new one over its
 * budget: a 429, and beyond SRV_CLIENT_GRACE of those, closed at once).
 * A request's headers must be complete within --request-timeout
 * of its first line, and its body must keep up with --min-body-rate
 * after a start of --request-timeout; srv_conns_reap closes those that
 * do not. Many idle or trickling sockets, from however many loopback
 * addresses, so never lock out an active client or /api/v1/health.
 */
#ifndef CONVSIM_CONNS_H
#define CONVSIM_CONNS_H

#include <microhttpd.h>

#include "config.h"

/* Connections libmicrohttpd admits beyond --max-connections: room for
 * the new ones while idle ones are being closed. */
#define SRV_CONN_HEADROOM 256

/* Connections a client may open beyond its budget, while every one of
 * its others is being answered, that still get a 429 with a body; any
 * further one is closed at once. */
#define SRV_CLIENT_GRACE 8

typedef struct srv_conn srv_conn;
/* A client address's connections (its own heap by progress, its counts),
 * kept by budget.c one an address; conns.c's lock guards it. */
typedef struct srv_conn_group srv_conn_group;

/* What srv_conn_open says of a new connection. */
enum {
	SRV_CONN_OK,      /* within the caps (room was made) */
	SRV_CONN_OVER,    /* beyond its address's cap, every other one of the
			     address busy: answer 429 and close */
	SRV_CONN_DROPPED  /* that, beyond the grace too: already closed */
};

/* cfg (borrowed for the daemon's life) gives --max-connections,
 * --max-client-connections, --connection-timeout, --request-timeout and
 * --min-body-rate. */
void srv_conns_init(const srv_config *cfg);
/* A new, empty group; NULL when out of memory. Free only an empty one
 * (every connection of it closed). */
srv_conn_group *srv_conn_group_new(void);
void srv_conn_group_free(srv_conn_group *g);
/* Register a connection libmicrohttpd just accepted (its socket must be
 * known) from the address of group g (NULL: none): idle from now; closes
 * the ones with the least progress while --max-connections are open, and
 * g's own while g has --max-client-connections. *over: SRV_CONN_*.
 * Returns the handle (NULL when out of memory: not counted, never closed
 * here). */
/* The connection this thread registers next with srv_conn_open was
 * accepted at t (srv_now()): it is idle since then, not since it was
 * registered (acceptor.c may hold it back a while). */
void srv_conn_opened_at(double t);
srv_conn *srv_conn_open(struct MHD_Connection *conn, srv_conn_group *g, int *over);
/* Forget a connection (at libmicrohttpd's close notice, before its group
 * is let go); NULL is fine. */
void srv_conn_close(srv_conn *c);
/* A request line came on c: its headers are due within --request-timeout. */
void srv_conn_request_line(srv_conn *c);
/* c's headers passed and its body is to be read: it must keep up with
 * --min-body-rate after --request-timeout. */
void srv_conn_body_start(srv_conn *c);
/* n more body bytes read on c: 1 to go on, 0 if c is past its deadline
 * (answered 408 and shut down here, the caller closes it; counted as
 * timed out). NULL: 1. */
int srv_conn_body_read(srv_conn *c, size_t n);
/* A request is being answered on c (busy 1: no deadline) or has ended
 * (busy 0: idle from now). */
void srv_conn_busy(srv_conn *c, int busy);
/* Close every connection past its deadline (called once a second). */
void srv_conns_reap(void);
/* Connections closed to make room at a cap, and at their deadline
 * (by srv_conns_reap or srv_conn_body_read), so far. */
unsigned long long srv_conns_evicted(void);
unsigned long long srv_conns_timed_out(void);
/* Of those timed out, the bodies answered 408 before they were closed. */
unsigned long long srv_conns_answered_late(void);
/* Free the table at exit. */
void srv_conns_shutdown(void);

#endif
