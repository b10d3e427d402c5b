/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * conns.h - the open connections under deadlines, and room at the global
 * cap: libmicrohttpd admits up to SRV_CONN_HEADROOM connections beyond
 * --max-connections, and each one opened beyond the cap closes the
 * connection that has made the least progress (idle longest, headers or
 * body furthest behind; never one being answered, such as a stream) in
 * O(log n). A request's headers must be complete within --request-timeout
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

typedef struct srv_conn srv_conn;

/* cfg (borrowed for the daemon's life) gives --max-connections,
 * --connection-timeout, --request-timeout and --min-body-rate. */
void srv_conns_init(const srv_config *cfg);
/* Register a connection libmicrohttpd just accepted (its socket must be
 * known): idle from now; closes the ones with the least progress while
 * --max-connections are open. Returns the handle (NULL when out of
 * memory: not counted, never closed here). */
srv_conn *srv_conn_open(struct MHD_Connection *conn);
/* Forget a connection (at libmicrohttpd's close notice); NULL is fine. */
void srv_conn_close(srv_conn *c);
/* A request line came on c: its headers are due within --request-timeout. */
void srv_conn_request_line(srv_conn *c);
/* c's headers passed and its body is to be read: it must keep up with
 * --min-body-rate after --request-timeout. */
void srv_conn_body_start(srv_conn *c);
/* n more body bytes read on c: 1 to go on, 0 if c is past its deadline
 * (the caller closes it; counted as timed out). NULL: 1. */
int srv_conn_body_read(srv_conn *c, size_t n);
/* A request is being answered on c (busy 1: no deadline) or has ended
 * (busy 0: idle from now). */
void srv_conn_busy(srv_conn *c, int busy);
/* Close every connection past its deadline (called once a second). */
void srv_conns_reap(void);
/* Connections closed to make room at the cap, and at their deadline
 * (by srv_conns_reap or srv_conn_body_read), so far. */
unsigned long long srv_conns_evicted(void);
unsigned long long srv_conns_timed_out(void);
/* Free the table at exit. */
void srv_conns_shutdown(void);

#endif
