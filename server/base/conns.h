/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * conns.h - the open connections, so that idle ones make room at the
 * global cap: libmicrohttpd admits up to SRV_CONN_HEADROOM connections
 * beyond --max-connections, and each one opened beyond the cap closes the
 * idlest connection with no request in flight (its socket is shut down;
 * libmicrohttpd then closes it as a peer that left). Many idle sockets,
 * from however many loopback addresses, so never lock out an active
 * client or /api/v1/health.
 */
#ifndef CONVSIM_CONNS_H
#define CONVSIM_CONNS_H

#include <microhttpd.h>

#include "config.h"

/* Connections libmicrohttpd admits beyond --max-connections: room for
 * the new ones while idle ones are being closed. */
#define SRV_CONN_HEADROOM 256

typedef struct srv_conn srv_conn;

/* cfg (borrowed for the daemon's life) gives --max-connections. */
void srv_conns_init(const srv_config *cfg);
/* Register a connection libmicrohttpd just accepted (its socket must be
 * known); closes the idlest idle ones while more than --max-connections
 * are open. Returns the handle (NULL when out of memory: not counted). */
srv_conn *srv_conn_open(struct MHD_Connection *conn);
/* Forget a connection (at libmicrohttpd's close notice); NULL is fine. */
void srv_conn_close(srv_conn *c);
/* A request starts (busy 1) or ends (busy 0) on c; either is activity. */
void srv_conn_busy(srv_conn *c, int busy);
/* Idle connections closed to make room so far. */
unsigned long long srv_conns_evicted(void);
/* Free the table at exit. */
void srv_conns_shutdown(void);

#endif
