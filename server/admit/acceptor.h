/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * acceptor.h - the daemon's own listening socket and accept loop.
 *
 * libmicrohttpd accepted one connection per turn of its loop and started
 * its thread before the next, so during a flood of connections an active
 * client's waited in the kernel's accept queue behind every one of the
 * flood's. Here one thread drains the accept queue at once (accept4 until
 * it is empty), keeps what it took in a priority queue, the connections of
 * an address with fewer open or waiting first, and hands them to
 * libmicrohttpd (MHD_add_connection) a few at a time: only as fast as
 * libmicrohttpd takes them up, so a newcomer passes the flood's backlog.
 * The caps (conns.h) apply as before, when libmicrohttpd takes a
 * connection up.
 */
#ifndef CONVSIM_ACCEPTOR_H
#define CONVSIM_ACCEPTOR_H

#include <microhttpd.h>

#include "config.h"

/* Connections handed to libmicrohttpd and not yet taken up (its
 * notification of their start): the few ahead of a newcomer. */
#define SRV_ACCEPT_INFLIGHT 4
/* Accepted connections waiting to be handed over, at most; beyond, the
 * rest wait in the kernel's accept queue. */
#define SRV_ACCEPT_QUEUE 4096
/* Seconds the waiting connections may wait while libmicrohttpd is at its
 * limit of connections; then they are closed (counted as closed at
 * accept), as libmicrohttpd did itself. */
#define SRV_ACCEPT_WAIT 1.0

/* Bind and listen on cfg->listen, cfg->port (0: any free port); *port the
 * port bound. -1 with a message on stderr if it cannot. */
int srv_acceptor_open(const srv_config *cfg, int *port);
/* Start the accept loop for daemon d (started with
 * MHD_USE_NO_LISTEN_SOCKET and srv_acceptor_notify); -1 if it cannot. */
int srv_acceptor_start(struct MHD_Daemon *d, const srv_config *cfg);
/* Stop accepting: the loop ends, the waiting connections and the
 * listening socket are closed. Safe to call when not started. */
void srv_acceptor_stop(void);
/* After libmicrohttpd has stopped (no notification can come any more):
 * free the rest (the wake-up pipe, the tables). */
void srv_acceptor_free(void);
/* libmicrohttpd's connection notification (MHD_OPTION_NOTIFY_CONNECTION):
 * counts the connections taken up and closed, then
 * srv_budget_connection. */
void srv_acceptor_notify(void *cls, struct MHD_Connection *conn,
			 void **socket_context,
			 enum MHD_ConnectionNotificationCode code);
/* Connections accepted so far, and the most that waited at once. */
unsigned long long srv_acceptor_accepted(void);
unsigned long long srv_acceptor_queued_max(void);

#endif
