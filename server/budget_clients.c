/*
 * budget_clients.c - the connections budget of each client address:
 * connections are counted per address in a small table sized by
 * --max-connections (libmicrohttpd never holds more), from libmicrohttpd's
 * connection notification; a connection beyond --max-client-connections
 * is answered 429 and closed. libmicrohttpd's own refusals at accept are
 * counted from its log.
 */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "util.h"

static const srv_config *cfg;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER; /* a leaf */

void srv_budget_clients_init(const srv_config *config)
{
	cfg = config;
}

/* ---- connections per client -------------------------------------------------------- */

typedef struct client {
	unsigned char addr[16]; /* IPv4 in the first 4 bytes */
	int family;
	int count;              /* lock; 0: a free entry */
} client;

/* What a connection's socket context holds. */
typedef struct client_conn {
	client *c;
	int over;
} client_conn;

static client *clients;  /* lock; cfg->max_connections + 1 entries */
static atomic_ullong client_refused;

/* The address bytes of a connection's peer; 0 if it has none. */
static int peer(struct MHD_Connection *conn, unsigned char addr[16],
		int *family)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CLIENT_ADDRESS);
	if (!ci || !ci->client_addr)
		return 0;
	memset(addr, 0, 16);
	*family = ci->client_addr->sa_family;
	if (*family == AF_INET)
		memcpy(addr, &((const struct sockaddr_in *)(const void *)ci->client_addr)
				      ->sin_addr, 4);
	else if (*family == AF_INET6)
		memcpy(addr, &((const struct sockaddr_in6 *)(const void *)ci->client_addr)
				      ->sin6_addr, 16);
	else
		return 0;
	return 1;
}

/* The entry of addr, or a free one for it; NULL when full (lock held). */
static client *find_client(const unsigned char addr[16], int family)
{
	size_t n = (size_t)cfg->max_connections + 1;
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
	if (free_one) {
		memcpy(free_one->addr, addr, 16);
		free_one->family = family;
	}
	return free_one;
}

void srv_budget_connection(void *cls, struct MHD_Connection *conn,
			   void **socket_context,
			   enum MHD_ConnectionNotificationCode code)
{
	(void)cls;
	client_conn *cc = *socket_context;
	if (code == MHD_CONNECTION_NOTIFY_CLOSED) {
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
	int family;
	cc = calloc(1, sizeof *cc);
	if (!cc || !peer(conn, addr, &family)) {
		*socket_context = cc;
		return;
	}
	pthread_mutex_lock(&lock);
	cc->c = find_client(addr, family);
	if (cc->c)
		cc->over = ++cc->c->count > cfg->max_client_connections;
	pthread_mutex_unlock(&lock);
	*socket_context = cc;
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
		 "this client address has more than %d connections open, its "
		 "budget (--max-client-connections); close some (idle ones "
		 "close after %g s) and retry", cfg->max_client_connections,
		 cfg->connection_timeout);
	api_budget(pb, "connections", cfg->max_client_connections, 1);
	pb->close = 1; /* one too many: the answer closes it */
	return 1;
}

unsigned long long srv_budget_client_refused(void)
{
	return atomic_load(&client_refused);
}

static atomic_ullong connections_dropped;

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
