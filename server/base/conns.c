/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * conns.c - the open connections, their deadlines, and the ones closed
 * to make room at the global cap and at each address's (see conns.h).
 *
 * A connection is in one of four states; each but "busy" has a progress
 * time (how far it has come) and a deadline (when it is cut):
 *
 *   idle  accepted, or between requests: progress = since then,
 *         deadline = progress + --connection-timeout;
 *   head  a request line came (libmicrohttpd saw its URI), its headers
 *         not yet all: progress = then, deadline = progress +
 *         --request-timeout;
 *   body  the headers passed the gate, the body is being read: progress =
 *         its start + bytes read / --min-body-rate, deadline = progress +
 *         --request-timeout (a body slower than the rate falls behind);
 *   busy  the request is being answered (a stream for its whole life):
 *         never closed here.
 *
 * Two binary min-heaps hold the connections that are not busy, one by
 * progress and one by deadline, so that each change is O(log n) under
 * the lock and nothing is ever scanned. Beyond --max-connections each new
 * connection closes the one with the oldest progress; an idle one whose
 * request bytes already wait unread on its socket (accepted just before
 * a burst of others, its thread not yet run) is a request arriving: it
 * goes to "head" with progress now instead; after SRV_CONN_PEEKS of those
 * for one new connection the oldest is closed whatever waits on it, so
 * the listen thread's work per connection is bounded. Each client
 * address's connections (a group, budget.c's entry for the address) sit
 * in a third heap by progress, its own: beyond --max-client-connections
 * a new connection closes the oldest of its group by the same rule; a
 * group whose every connection is busy makes the new one "over" (a 429,
 * counted apart; beyond SRV_CLIENT_GRACE of those it is closed at once).
 * Once a
 * second srv_conns_reap closes every connection past its deadline.
 * Closing is a shutdown(2) of the socket under the lock: libmicrohttpd
 * notifies the close (srv_conn_close, which takes the lock) before it
 * closes the descriptor, so a descriptor here is never another's.
 */
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>

#include "api.h"
#include "conns.h"
#include "util.h"

/* Idle connections with request bytes waiting that one new connection
 * passes over (each to the back) before it closes the oldest anyway. */
#define SRV_CONN_PEEKS 16

/* The heaps a connection sits in: the global ones by progress and by
 * deadline, and its client address's own by progress (BY_GROUP, keyed as
 * BY_PROGRESS). */
enum { BY_PROGRESS, BY_DEADLINE, BY_GROUP, SLOTS };
enum { HEAPS = BY_GROUP };
enum conn_state { CONN_IDLE, CONN_HEAD, CONN_BODY, CONN_BUSY, CONN_CLOSING };

typedef struct heap {
	srv_conn **v;
	size_t n, cap;
} heap;

/* A client address's connections (budget.c keeps one an address). */
struct srv_conn_group {
	heap by_progress;    /* lock: its listed connections */
	int open;            /* lock: registered, not closing, not over */
	int over;            /* lock: open beyond the cap, all others busy */
};

struct srv_conn {
	int fd;
	enum conn_state state;
	srv_conn_group *group; /* NULL: no address (not capped per client) */
	int over;            /* counted in group->over, not in open */
	double key[SLOTS];   /* progress, deadline, progress; srv_now() s */
	size_t at[SLOTS];    /* index in each heap; NOWHERE when out */
	double body_start;   /* state body: when the headers passed */
	size_t body_bytes;   /* state body: bytes read so far */
};

#define NOWHERE ((size_t)-1)

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static heap heaps[HEAPS];  /* lock */
static int open_count;     /* lock: registered and not closing */
static const srv_config *cfg;
static atomic_ullong evicted, timed_out, answered_late;
/* When the connection this thread registers next was accepted (0: now). */
static _Thread_local double opened_at;

/* The 408 written on a connection whose body fell behind its deadline. */
static char *late_answer;
static size_t late_len;

void srv_conns_init(const srv_config *config)
{
	cfg = config;
	api_problem pb;
	api_fail(&pb, API_TIMEOUT, "body",
		 "the body came slower than %zu bytes/s (--min-body-rate) after "
		 "its first %g s (--request-timeout); nothing was done with the "
		 "request and the connection is closed: send it again at a "
		 "steady pace", cfg->min_body_rate, cfg->request_timeout);
	char *json = api_problem_json(&pb, NULL);
	size_t n = json ? strlen(json) : 0;
	free(late_answer);
	late_answer = json ? malloc(n + 256) : NULL;
	if (late_answer)
		late_len = (size_t)snprintf(
			late_answer, n + 256,
			"HTTP/1.1 408 Request Timeout\r\nConnection: close\r\n"
			"Content-Type: application/problem+json\r\n"
			"Cache-Control: no-store\r\nContent-Length: %zu\r\n\r\n%s",
			n, json);
	free(json);
}

/* ---- the heaps (lock held) ------------------------------------------------- */

static int before(int h, const srv_conn *a, const srv_conn *b)
{
	return a->key[h] < b->key[h];
}

static void place(heap *hp, int h, size_t i, srv_conn *c)
{
	hp->v[i] = c;
	c->at[h] = i;
}

static void sift_up(heap *hp, int h, size_t i)
{
	srv_conn *c = hp->v[i];
	while (i > 0) {
		size_t parent = (i - 1) / 2;
		if (!before(h, c, hp->v[parent]))
			break;
		place(hp, h, i, hp->v[parent]);
		i = parent;
	}
	place(hp, h, i, c);
}

static void sift_down(heap *hp, int h, size_t i)
{
	srv_conn *c = hp->v[i];
	for (;;) {
		size_t child = 2 * i + 1;
		if (child >= hp->n)
			break;
		if (child + 1 < hp->n && before(h, hp->v[child + 1], hp->v[child]))
			child++;
		if (!before(h, hp->v[child], c))
			break;
		place(hp, h, i, hp->v[child]);
		i = child;
	}
	place(hp, h, i, c);
}

/* Add c to heap hp in slot h; -1 when out of memory. */
static int heap_add(heap *hp, int h, srv_conn *c)
{
	if (hp->n == hp->cap) {
		size_t cap = hp->cap ? 2 * hp->cap : 16;
		srv_conn **v = realloc(hp->v, cap * sizeof *v);
		if (!v)
			return -1;
		hp->v = v;
		hp->cap = cap;
	}
	place(hp, h, hp->n++, c);
	sift_up(hp, h, hp->n - 1);
	return 0;
}

static void heap_remove(heap *hp, int h, srv_conn *c)
{
	size_t i = c->at[h];
	if (i == NOWHERE)
		return;
	c->at[h] = NOWHERE;
	srv_conn *last = hp->v[--hp->n];
	if (last == c)
		return;
	place(hp, h, i, last);
	sift_up(hp, h, i);
	sift_down(hp, h, last->at[h]);
}

/* ---- states (lock held) ---------------------------------------------------- */

/* Out of every heap. */
static void unlist(srv_conn *c)
{
	heap_remove(&heaps[BY_PROGRESS], BY_PROGRESS, c);
	heap_remove(&heaps[BY_DEADLINE], BY_DEADLINE, c);
	if (c->group)
		heap_remove(&c->group->by_progress, BY_GROUP, c);
}

/* Into every heap it belongs to; out of all when out of memory. */
static void list(srv_conn *c)
{
	if (heap_add(&heaps[BY_PROGRESS], BY_PROGRESS, c) != 0 ||
	    heap_add(&heaps[BY_DEADLINE], BY_DEADLINE, c) != 0 ||
	    (c->group && !c->over && heap_add(&c->group->by_progress, BY_GROUP, c) != 0))
		unlist(c);
}

/* c leaves the counts of open connections (closing or closed). */
static void uncount(srv_conn *c)
{
	open_count--;
	if (c->group && c->over)
		c->group->over--;
	else if (c->group)
		c->group->open--;
}

/* c in state s with this progress time; its deadline follows from it.
 * Out of memory for the heaps: c stays unlisted (not closed here). */
static void set_state(srv_conn *c, enum conn_state s, double progress)
{
	unlist(c);
	c->state = s;
	if (s == CONN_BUSY || s == CONN_CLOSING)
		return;
	c->key[BY_PROGRESS] = c->key[BY_GROUP] = progress;
	c->key[BY_DEADLINE] = progress + (s == CONN_IDLE
						  ? cfg->connection_timeout
						  : cfg->request_timeout);
	list(c);
}

/* Close c: shut its socket down; libmicrohttpd then closes it as a peer
 * that left and notifies srv_conn_close. */
static void cut(srv_conn *c)
{
	set_state(c, CONN_CLOSING, 0);
	uncount(c);
	shutdown(c->fd, SHUT_RDWR);
}

/* Close c at its deadline. A body of which bytes were read is answered
 * 408 first: nothing has been sent on c (libmicrohttpd answers once the
 * body is in, and any "100 Continue" went before the first byte was
 * read), and the answer and the shutdown happen under the lock, so that
 * nothing of the request's own answer can follow (the state is closing;
 * a later write fails on the shut socket). */
static void cut_late(srv_conn *c)
{
	if (c->state == CONN_BODY && c->body_bytes > 0 && late_answer &&
	    send(c->fd, late_answer, late_len, MSG_DONTWAIT | MSG_NOSIGNAL) ==
		    (ssize_t)late_len)
		atomic_fetch_add(&answered_late, 1);
	cut(c);
}

/* Bytes wait unread on c's socket: a request on its way. */
static int request_waiting(const srv_conn *c)
{
	char byte;
	return recv(c->fd, &byte, 1, MSG_PEEK | MSG_DONTWAIT) > 0;
}

/* Close the connection with the oldest progress in hp (slot h); 0 if
 * none is listed. An idle one with request bytes waiting goes to the back
 * as a request arriving; after SRV_CONN_PEEKS of those the oldest is
 * closed whatever waits on it, so that the cap holds and the work stays
 * bounded. */
static int evict_one(heap *hp, double now)
{
	for (int peeks = 0; hp->n; peeks++) {
		srv_conn *victim = hp->v[0];
		if (peeks < SRV_CONN_PEEKS && victim->state == CONN_IDLE &&
		    request_waiting(victim)) {
			set_state(victim, CONN_HEAD, now);
			continue;
		}
		cut(victim);
		return 1;
	}
	return 0;
}

/* ---- the interface ---------------------------------------------------------- */

srv_conn_group *srv_conn_group_new(void)
{
	return calloc(1, sizeof(srv_conn_group));
}

void srv_conn_group_free(srv_conn_group *g)
{
	if (g)
		free(g->by_progress.v);
	free(g);
}

/* Room for c (lock held): beyond --max-connections the connection with
 * the least progress is closed, beyond its address's cap its address's
 * own; when every one of its address's is busy c is over (a 429) or,
 * beyond the grace, closed at once. How many were closed to make room. */
static int make_room(srv_conn *c, double now, int *over)
{
	int closed = 0;
	while (open_count >= cfg->max_connections && evict_one(&heaps[BY_PROGRESS], now))
		closed++;
	srv_conn_group *g = c->group;
	*over = SRV_CONN_OK;
	while (g && g->open >= cfg->max_client_connections && evict_one(&g->by_progress, now))
		closed++;
	if (g && g->open >= cfg->max_client_connections) {
		c->over = 1;
		*over = g->over >= SRV_CLIENT_GRACE ? SRV_CONN_DROPPED : SRV_CONN_OVER;
	}
	return closed;
}

void srv_conn_opened_at(double t)
{
	opened_at = t;
}

srv_conn *srv_conn_open(struct MHD_Connection *conn, srv_conn_group *g, int *over)
{
	const union MHD_ConnectionInfo *ci =
		MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
	srv_conn *c = ci ? calloc(1, sizeof *c) : NULL;
	*over = SRV_CONN_OK;
	if (!c)
		return NULL;
	c->fd = ci->connect_fd;
	c->group = g;
	c->at[BY_PROGRESS] = c->at[BY_DEADLINE] = c->at[BY_GROUP] = NOWHERE;
	double now = srv_now();
	if (opened_at > 0 && opened_at < now)
		now = opened_at; /* idle since it was accepted */
	opened_at = 0;
	int closed = 0;
	pthread_mutex_lock(&lock);
	if (cfg)
		closed = make_room(c, now, over);
	open_count++;
	if (g && c->over)
		g->over++;
	else if (g)
		g->open++;
	set_state(c, CONN_IDLE, now);
	if (*over == SRV_CONN_DROPPED)
		cut(c);
	pthread_mutex_unlock(&lock);
	if (closed) {
		atomic_fetch_add(&evicted, (unsigned long long)closed);
		srv_log(SRV_LOG_DEBUG, "at the cap of %d connections or of %d from one "
				       "address: closed %d", cfg->max_connections,
			cfg->max_client_connections, closed);
	}
	return c;
}

void srv_conn_close(srv_conn *c)
{
	if (!c)
		return;
	pthread_mutex_lock(&lock);
	if (c->state != CONN_CLOSING)
		uncount(c);
	unlist(c);
	pthread_mutex_unlock(&lock);
	free(c);
}

void srv_conn_request_line(srv_conn *c)
{
	if (!c)
		return;
	pthread_mutex_lock(&lock);
	if (c->state == CONN_IDLE || c->state == CONN_HEAD)
		set_state(c, CONN_HEAD, srv_now());
	pthread_mutex_unlock(&lock);
}

void srv_conn_body_start(srv_conn *c)
{
	if (!c)
		return;
	pthread_mutex_lock(&lock);
	if (c->state != CONN_CLOSING) {
		c->body_start = srv_now();
		c->body_bytes = 0;
		set_state(c, CONN_BODY, c->body_start);
	}
	pthread_mutex_unlock(&lock);
}

int srv_conn_body_read(srv_conn *c, size_t n)
{
	if (!c)
		return 1;
	double now = srv_now();
	int keep = 0, late = 0;
	pthread_mutex_lock(&lock);
	if (c->state == CONN_BODY && now > c->key[BY_DEADLINE]) {
		late = 1;
		cut_late(c);
	} else if (c->state == CONN_BODY) {
		c->body_bytes += n;
		set_state(c, CONN_BODY,
			  c->body_start + (double)c->body_bytes /
						  (double)cfg->min_body_rate);
		keep = 1;
	}
	pthread_mutex_unlock(&lock);
	if (late)
		atomic_fetch_add(&timed_out, 1);
	return keep;
}

void srv_conn_busy(srv_conn *c, int busy)
{
	if (!c)
		return;
	pthread_mutex_lock(&lock);
	if (c->state != CONN_CLOSING)
		set_state(c, busy ? CONN_BUSY : CONN_IDLE, srv_now());
	pthread_mutex_unlock(&lock);
}

void srv_conns_reap(void)
{
	double now = srv_now();
	unsigned long long n = 0;
	pthread_mutex_lock(&lock);
	while (heaps[BY_DEADLINE].n && heaps[BY_DEADLINE].v[0]->key[BY_DEADLINE] < now) {
		cut_late(heaps[BY_DEADLINE].v[0]);
		n++;
	}
	pthread_mutex_unlock(&lock);
	if (n) {
		atomic_fetch_add(&timed_out, n);
		srv_log(SRV_LOG_DEBUG, "closed %llu connections past their "
				       "deadline", n);
	}
}

unsigned long long srv_conns_evicted(void)
{
	return atomic_load(&evicted);
}

unsigned long long srv_conns_timed_out(void)
{
	return atomic_load(&timed_out);
}

unsigned long long srv_conns_answered_late(void)
{
	return atomic_load(&answered_late);
}

void srv_conns_shutdown(void)
{
	pthread_mutex_lock(&lock);
	for (int h = 0; h < HEAPS; h++) {
		free(heaps[h].v);
		heaps[h] = (heap){0};
	}
	open_count = 0;
	pthread_mutex_unlock(&lock);
}
