/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * conns.c - the open connections and the idle ones closed at the global
 * cap (see conns.h).
 *
 * A connection is idle from its last activity (accepted, a request ended)
 * until a request reaches the access handler, and busy until that request
 * is complete: streams are busy for their whole life and are never
 * closed here; a socket that sends nothing, or only part of a request's
 * headers, is idle, unless bytes of a request wait on its socket. The
 * idlest is the one idle longest. Closing is a
 * shutdown(2) of the socket under the lock: libmicrohttpd notifies the
 * close (srv_conn_close, which takes the lock) before it closes the
 * descriptor, so a descriptor in the list is never another's. The list is
 * a doubly linked list scanned at each eviction (a thousand entries at
 * most, and only beyond the cap).
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdlib.h>
#include <sys/socket.h>

#include "conns.h"
#include "util.h"

struct srv_conn {
	srv_conn *prev, *next;
	int fd;
	int busy;       /* a request in flight */
	int closing;    /* shut down here, not yet closed by libmicrohttpd */
	double last;    /* srv_now() of the last activity */
};

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static srv_conn *head;   /* lock */
static int open_count;   /* lock: in the list and not closing */
static const srv_config *cfg;
static atomic_ullong evicted;

void srv_conns_init(const srv_config *config)
{
	cfg = config;
}

/* The idle connection with the oldest activity other than skip, or NULL
 * (lock held). */
static srv_conn *idlest(const srv_conn *skip)
{
	srv_conn *best = NULL;
	for (srv_conn *c = head; c; c = c->next)
		if (c != skip && !c->busy && !c->closing &&
		    (!best || c->last < best->last))
			best = c;
	return best;
}

/* Bytes are waiting on c's socket: a request on its way that
 * libmicrohttpd has not read yet (a client that connected just before a
 * burst of others), so c is not idle. */
static int request_waiting(const srv_conn *c)
{
	char byte;
	return recv(c->fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT) > 0;
}

/* Close the idlest connection but keep; 0 if none is idle (lock held). */
static int close_idlest(const srv_conn *keep, double now)
{
	srv_conn *victim;
	while ((victim = idlest(keep)) && request_waiting(victim))
		victim->last = now;
	if (!victim)
		return 0;
	victim->closing = 1;
	open_count--;
	shutdown(victim->fd, SHUT_RDWR);
	return 1;
}

srv_conn *srv_conn_open(struct MHD_Connection *conn)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
	srv_conn *c = ci ? calloc(1, sizeof *c) : NULL;
	if (!c)
		return NULL;
	c->fd = ci->connect_fd;
	c->last = srv_now();
	int closed = 0;
	pthread_mutex_lock(&lock);
	c->next = head;
	if (head)
		head->prev = c;
	head = c;
	open_count++;
	while (cfg && open_count > cfg->max_connections &&
	       close_idlest(c, c->last))
		closed++;
	pthread_mutex_unlock(&lock);
	if (closed) {
		atomic_fetch_add(&evicted, (unsigned long long)closed);
		srv_log(SRV_LOG_DEBUG, "at the cap of %d connections: closed "
				       "%d idle", cfg->max_connections, closed);
	}
	return c;
}

void srv_conn_close(srv_conn *c)
{
	if (!c)
		return;
	pthread_mutex_lock(&lock);
	if (c->prev)
		c->prev->next = c->next;
	else
		head = c->next;
	if (c->next)
		c->next->prev = c->prev;
	if (!c->closing)
		open_count--;
	pthread_mutex_unlock(&lock);
	free(c);
}

void srv_conn_busy(srv_conn *c, int busy)
{
	if (!c)
		return;
	pthread_mutex_lock(&lock);
	c->busy = busy;
	c->last = srv_now();
	pthread_mutex_unlock(&lock);
}

unsigned long long srv_conns_evicted(void)
{
	return atomic_load(&evicted);
}

void srv_conns_shutdown(void)
{
	pthread_mutex_lock(&lock);
	while (head) {
		srv_conn *c = head;
		head = c->next;
		free(c);
	}
	open_count = 0;
	pthread_mutex_unlock(&lock);
}
