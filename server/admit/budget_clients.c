/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget_clients.c - connections counted per client address, in a small
 * table sized by --max-connections (libmicrohttpd never holds more): the
 * budget of --max-client-connections, what libmicrohttpd itself refused,
 * and each connection's deadlines and room at the global cap (conns.c).
 */
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "conns.h"
#include "util.h"

static const srv_config *cfg;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;

void srv_budget_clients_init(const srv_config *config)
{
	cfg = config;
}

typedef struct client {
	unsigned char addr[16]; /* IPv4 in the first 4 bytes */
	int family;
	int count;              /* lock; 0: a free entry */
	srv_conn_group *group;  /* its connections (conns.c), kept for the
				   next address the entry serves */
} client;

/* What a connection's socket context holds. */
typedef struct client_conn {
	client *c;
	int over;
	srv_conn *live; /* conns.c: deadlines, room at the global cap */
} client_conn;

static client *clients;  /* lock; cfg->max_connections + 1 entries */
static atomic_ullong client_refused, connections_dropped;

/* The address bytes of a connection's peer; 0 if it has none. */
static int peer(struct MHD_Connection *conn, unsigned char addr[16],
		int *family)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
	if (!ci || !ci->client_addr)
		return 0;
	*family = ci->client_addr->sa_family;
	return srv_addr_bytes(ci->client_addr, addr);
}

/* The entry of addr, or a free one for it; NULL when full (lock held). */
static client *find_client(const unsigned char addr[16], int family)
{
	size_t n = (size_t)cfg->max_connections + SRV_CONN_HEADROOM + 1;
	client *free_one = NULL;
	if (!clients && !(clients = calloc(n, sizeof *clients)))
		return NULL;
	for (size_t i = 0; i < n; i++) {
		client *c = &clients[i];
		if (c->count && c->family == family && memcmp(c->addr, addr, 16) == 0)
			return c;
		if (!c->count && !free_one)
			free_one = c;
	}
	if (free_one && !free_one->group)
		free_one->group = srv_conn_group_new();
	if (free_one && !free_one->group)
		return NULL;
	if (free_one) {
		memcpy(free_one->addr, addr, 16);
		free_one->family = family;
	}
	return free_one;
}

int srv_budget_open_from(const struct sockaddr *sa)
{
	unsigned char addr[16];
	if (!srv_addr_bytes(sa, addr))
		return 0;
	size_t n = (size_t)cfg->max_connections + SRV_CONN_HEADROOM + 1;
	int count = 0;
	pthread_mutex_lock(&lock);
	for (size_t i = 0; clients && i < n && !count; i++)
		if (clients[i].count && clients[i].family == sa->sa_family &&
		    memcmp(clients[i].addr, addr, 16) == 0)
			count = clients[i].count;
	pthread_mutex_unlock(&lock);
	return count;
}

void srv_budget_count_dropped(void)
{
	atomic_fetch_add(&connections_dropped, 1);
}

void srv_budget_connection(void *cls, struct MHD_Connection *conn,
			   void **socket_context,
			   enum MHD_ConnectionNotificationCode code)
{
	(void)cls;
	client_conn *cc = *socket_context;
	if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
		if (cc) /* out of its group before the entry can go */
			srv_conn_close(cc->live);
		if (cc && cc->c) {
			pthread_mutex_lock(&lock);
			cc->c->count--;
			pthread_mutex_unlock(&lock);
		}
		free(cc);
		*socket_context = NULL;
		return;
	}
	unsigned char addr[16];
	int family, over = SRV_CONN_OK;
	cc = calloc(1, sizeof *cc);
	if (!cc) {
		*socket_context = NULL;
		return;
	}
	if (peer(conn, addr, &family)) {
		pthread_mutex_lock(&lock);
		cc->c = find_client(addr, family);
		if (cc->c)
			cc->c->count++; /* the entry stays its address's */
		pthread_mutex_unlock(&lock);
	}
	/* room at the caps: the least progressing connection, of all or of
	 * this address, is closed; over only when its others are all busy */
	cc->live = srv_conn_open(conn, cc->c ? cc->c->group : NULL, &over);
	cc->over = over != SRV_CONN_OK;
	if (over == SRV_CONN_DROPPED)
		atomic_fetch_add(&connections_dropped, 1);
	*socket_context = cc;
}

srv_conn *srv_budget_live(struct MHD_Connection *conn)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
	const client_conn *cc = ci ? ci->socket_context : NULL;
	return cc ? cc->live : NULL;
}

int srv_budget_client_over(struct MHD_Connection *conn, api_problem *pb)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(conn, MHD_CONNECTION_INFO_SOCKET_CONTEXT);
	const client_conn *cc = ci ? ci->socket_context : NULL;
	if (!cc || !cc->over)
		return 0;
	atomic_fetch_add(&client_refused, 1);
	api_fail(pb, API_LIMIT, NULL,
		 "this client address has more than %d connection%s open, its budget "
		 "(--max-client-connections), and every other one is being answered (an idle or slow "
		 "one would have been closed to make room); close some and retry",
		 cfg->max_client_connections, api_plural(cfg->max_client_connections, "", "s"));
	api_budget(pb, "connections", cfg->max_client_connections, 1);
	pb->close = 1; /* one too many: the answer closes it */
	return 1;
}

unsigned long long srv_budget_client_refused(void)
{
	return atomic_load(&client_refused);
}

unsigned long long srv_budget_connections_dropped(void)
{
	return atomic_load(&connections_dropped);
}

void srv_budget_mhd_log(void *cls, const char *fmt, va_list ap)
{
	(void)cls;
	char line[512];
	vsnprintf(line, sizeof line, fmt, ap);
	size_t n = strlen(line);
	while (n && line[n - 1] == '\n')
		line[--n] = '\0';
	int refused = strstr(line, "connection limit") != NULL ||
		      strstr(line, "connections from this IP") != NULL;
	if (refused)
		atomic_fetch_add(&connections_dropped, 1);
	srv_log(refused ? SRV_LOG_DEBUG : SRV_LOG_WARN, "libmicrohttpd: %s",
		line);
}
