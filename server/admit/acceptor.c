/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * acceptor.c - the listening socket and the accept loop (see acceptor.h).
 *
 * One thread polls the listening socket and a wake-up pipe. When the
 * socket is readable it accepts until the kernel's queue is empty (or its
 * own is full), each connection into a binary min-heap keyed by how many
 * connections its address has open (budget.c) and waiting here, then by
 * arrival: the order libmicrohttpd gets them in. It hands them over while
 * fewer than SRV_ACCEPT_INFLIGHT are handed over and not yet taken up, and
 * libmicrohttpd has room below its limit; libmicrohttpd's notifications
 * (srv_acceptor_notify, from its threads) count the connections taken up
 * and closed and wake the loop. A handed-over connection libmicrohttpd
 * never takes up (it closed it at its limit, or out of memory) would hold
 * its place for ever: after a second with none taken up, those places are
 * given back. The waiting ones' addresses are counted in a small open
 * hash table (linear probing, removal by backward shift), so each step is
 * O(log n) or O(1) apart from budget.c's look-up of the address.
 */
#define _GNU_SOURCE /* accept4, pipe2 */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <poll.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <unistd.h>

#include "acceptor.h"
#include "budget.h"
#include "conns.h"
#include "util.h"

/* Slots of the table of waiting addresses: twice the queue. */
#define SLOTS_N (2 * SRV_ACCEPT_QUEUE)

typedef struct waiting {
	unsigned long long key; /* (open + waiting from its address) << 40 | arrival */
	double at;              /* accepted, srv_now() */
	int fd;
	socklen_t len;
	struct sockaddr_storage addr;
} waiting;

typedef struct slot {
	unsigned char addr[16];
	int family;
	int n; /* waiting from this address; 0: a free slot */
} slot;

static struct {
	int lfd, wake[2];
	struct MHD_Daemon *d;
	int limit;              /* libmicrohttpd's connections, at most */
	pthread_t tid;
	int running;
	atomic_int stop, inflight, live;
	atomic_ullong started, accepted, queued_max;
	/* the loop's own */
	waiting *heap;
	size_t n;
	slot *slots;
	double *at;             /* accepted, by descriptor (nfds of them) */
	size_t nfds;
	unsigned long long arrivals;
	double full_since, stall_since, pause_until;
	unsigned long long started_seen;
} A = {.lfd = -1, .wake = {-1, -1}};

/* ---- the waiting addresses ------------------------------------------------- */

static size_t home(const unsigned char b[16])
{
	unsigned long long h = 1469598103934665603ULL; /* FNV-1a */
	for (int i = 0; i < 16; i++)
		h = (h ^ b[i]) * 1099511628211ULL;
	return (size_t)(h % SLOTS_N);
}

/* The slot of ss's address, or the free one where it would go. */
static size_t find_slot(const struct sockaddr_storage *ss)
{
	unsigned char b[16];
	srv_addr_bytes((const struct sockaddr *)(const void *)ss, b);
	size_t i = home(b);
	while (A.slots[i].n &&
	       (A.slots[i].family != ss->ss_family || memcmp(A.slots[i].addr, b, 16)))
		i = (i + 1) % SLOTS_N;
	if (!A.slots[i].n) {
		memcpy(A.slots[i].addr, b, 16);
		A.slots[i].family = ss->ss_family;
	}
	return i;
}

/* One fewer waiting from slot i's address; a slot emptied is removed and
 * the ones after it in its run moved back so that every look-up finds
 * them. */
static void slot_drop(size_t i)
{
	if (--A.slots[i].n)
		return;
	for (size_t j = (i + 1) % SLOTS_N; A.slots[j].n; j = (j + 1) % SLOTS_N) {
		size_t h = home(A.slots[j].addr);
		/* j may move to i when i lies cyclically in [h, j) */
		if ((j > i && (h <= i || h > j)) || (j < i && h <= i && h > j)) {
			A.slots[i] = A.slots[j];
			A.slots[j].n = 0;
			i = j;
		}
	}
}

/* ---- the heap of waiting connections --------------------------------------- */

static void push(const waiting *w)
{
	size_t i = A.n++;
	while (i > 0 && A.heap[(i - 1) / 2].key > w->key) {
		A.heap[i] = A.heap[(i - 1) / 2];
		i = (i - 1) / 2;
	}
	A.heap[i] = *w;
	if (A.n > atomic_load(&A.queued_max))
		atomic_store(&A.queued_max, (unsigned long long)A.n);
}

static waiting pop(void)
{
	waiting top = A.heap[0], last = A.heap[--A.n];
	size_t i = 0;
	for (;;) {
		size_t c = 2 * i + 1;
		if (c >= A.n)
			break;
		if (c + 1 < A.n && A.heap[c + 1].key < A.heap[c].key)
			c++;
		if (A.heap[c].key >= last.key)
			break;
		A.heap[i] = A.heap[c];
		i = c;
	}
	if (A.n)
		A.heap[i] = last;
	slot_drop(find_slot(&top.addr));
	return top;
}

/* ---- the loop -------------------------------------------------------------- */

/* Accept until the kernel's queue or ours is empty or full. */
static void take(void)
{
	while (A.n < SRV_ACCEPT_QUEUE) {
		waiting w = {.len = sizeof w.addr};
		w.fd = accept4(A.lfd, (struct sockaddr *)&w.addr, &w.len,
			       SOCK_NONBLOCK | SOCK_CLOEXEC);
		if (w.fd < 0 && (errno == EINTR || errno == ECONNABORTED))
			continue;
		if (w.fd < 0) {
			/* out of descriptors or memory: pause, do not spin */
			if (errno != EAGAIN && errno != EWOULDBLOCK)
				A.pause_until = srv_now() + 0.1;
			return;
		}
		atomic_fetch_add(&A.accepted, 1);
		w.at = srv_now();
		size_t s = find_slot(&w.addr);
		unsigned long long ahead =
			(unsigned long long)srv_budget_open_from((struct sockaddr *)&w.addr) +
			(unsigned long long)A.slots[s].n++;
		if (ahead > 0xfffff)
			ahead = 0xfffff;
		w.key = ahead << 40 | (A.arrivals++ & 0xffffffffffULL);
		push(&w);
	}
}

/* libmicrohttpd at its limit for SRV_ACCEPT_WAIT: close every waiting
 * one, as it did at accept. */
static void drop_waiting(void)
{
	size_t n = A.n;
	while (A.n) {
		waiting w = pop();
		close(w.fd);
		srv_budget_count_dropped();
	}
	srv_log(SRV_LOG_DEBUG, "at the limit of %d connections for %.0f s: "
			       "closed %zu waiting", A.limit, SRV_ACCEPT_WAIT, n);
}

/* Hand the first waiting ones to libmicrohttpd while it has room. */
static void hand_over(double now)
{
	unsigned long long started = atomic_load(&A.started);
	if (started != A.started_seen)
		A.stall_since = now;
	A.started_seen = started;
	while (A.n) {
		int inflight = atomic_load(&A.inflight);
		if (inflight >= SRV_ACCEPT_INFLIGHT && now - A.stall_since > 1.0) {
			atomic_store(&A.inflight, 0); /* never taken up */
			A.stall_since = now;
			inflight = 0;
		}
		if (inflight >= SRV_ACCEPT_INFLIGHT)
			return;
		if (atomic_load(&A.live) + inflight >= A.limit) {
			if (A.full_since == 0)
				A.full_since = now;
			if (now - A.full_since >= SRV_ACCEPT_WAIT)
				drop_waiting();
			return;
		}
		A.full_since = 0;
		if (inflight == 0)
			A.stall_since = now;
		waiting w = pop();
		if ((size_t)w.fd < A.nfds)
			A.at[w.fd] = w.at;
		atomic_fetch_add(&A.inflight, 1);
		/* on failure libmicrohttpd closed it (and logged its limit) */
		if (MHD_add_connection(A.d, w.fd, (struct sockaddr *)&w.addr, w.len) != MHD_YES)
			atomic_fetch_sub(&A.inflight, 1);
	}
	A.full_since = 0; /* none waits: the next wait starts afresh */
}

static void *loop(void *arg)
{
	(void)arg;
	struct pollfd p[2] = {{.fd = A.lfd, .events = POLLIN},
			      {.fd = A.wake[0], .events = POLLIN}};
	while (!atomic_load(&A.stop)) {
		double now = srv_now();
		p[0].fd = A.n < SRV_ACCEPT_QUEUE && now >= A.pause_until ? A.lfd : -1;
		p[0].revents = p[1].revents = 0;
		int timeout = A.n || now < A.pause_until ? 100 : -1;
		if (poll(p, 2, timeout) < 0 && errno != EINTR)
			break;
		char buf[256];
		if (p[1].revents)
			while (read(A.wake[0], buf, sizeof buf) > 0)
				;
		if (p[0].revents & POLLIN)
			take();
		hand_over(srv_now());
	}
	return NULL;
}

/* ---- the interface --------------------------------------------------------- */

int srv_acceptor_open(const srv_config *cfg, int *port)
{
	struct sockaddr_storage ss = {0};
	struct sockaddr_in *a4 = (struct sockaddr_in *)(void *)&ss;
	struct sockaddr_in6 *a6 = (struct sockaddr_in6 *)(void *)&ss;
	socklen_t len;
	if (inet_pton(AF_INET, cfg->listen, &a4->sin_addr) == 1) {
		a4->sin_family = AF_INET;
		a4->sin_port = htons((uint16_t)cfg->port);
		len = sizeof *a4;
	} else if (inet_pton(AF_INET6, cfg->listen, &a6->sin6_addr) == 1) {
		a6->sin6_family = AF_INET6;
		a6->sin6_port = htons((uint16_t)cfg->port);
		len = sizeof *a6;
	} else {
		return -1;
	}
	int fd = socket(ss.ss_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
	int on = 1;
	if (fd < 0 || setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &on, sizeof on) ||
	    (ss.ss_family == AF_INET6 &&
	     setsockopt(fd, IPPROTO_IPV6, IPV6_V6ONLY, &on, sizeof on)) ||
	    bind(fd, (struct sockaddr *)&ss, len) || listen(fd, SOMAXCONN) ||
	    getsockname(fd, (struct sockaddr *)&ss, &len)) {
		if (fd >= 0)
			close(fd);
		return -1;
	}
	*port = ntohs(ss.ss_family == AF_INET ? a4->sin_port : a6->sin6_port);
	A.lfd = fd;
	return 0;
}

int srv_acceptor_start(struct MHD_Daemon *d, const srv_config *cfg)
{
	A.d = d;
	A.limit = cfg->max_connections + SRV_CONN_HEADROOM / 2;
	A.heap = malloc(SRV_ACCEPT_QUEUE * sizeof *A.heap);
	A.slots = calloc(SLOTS_N, sizeof *A.slots);
	struct rlimit rl;
	A.nfds = getrlimit(RLIMIT_NOFILE, &rl) == 0 && rl.rlim_cur < (1u << 22)
			 ? (size_t)rl.rlim_cur : (1u << 22);
	A.at = calloc(A.nfds, sizeof *A.at);
	if (!A.heap || !A.slots || !A.at || pipe2(A.wake, O_NONBLOCK | O_CLOEXEC) ||
	    pthread_create(&A.tid, NULL, loop, NULL))
		return -1;
	A.running = 1;
	return 0;
}

static void wake(void)
{
	if (A.wake[1] >= 0 && write(A.wake[1], "", 1) < 0) {
		/* full: the loop wakes anyway */
	}
}

void srv_acceptor_stop(void)
{
	if (A.running) {
		atomic_store(&A.stop, 1);
		wake();
		pthread_join(A.tid, NULL);
		A.running = 0;
	}
	while (A.n)
		close(pop().fd);
	if (A.lfd >= 0)
		close(A.lfd);
	A.lfd = -1;
}

void srv_acceptor_free(void)
{
	srv_acceptor_stop();
	for (int i = 0; i < 2; i++)
		if (A.wake[i] >= 0)
			close(A.wake[i]);
	A.wake[0] = A.wake[1] = -1;
	free(A.heap);
	free(A.slots);
	free(A.at);
	A.heap = NULL;
	A.slots = NULL;
	A.at = NULL;
	A.nfds = 0;
}

void srv_acceptor_notify(void *cls, struct MHD_Connection *conn,
			 void **socket_context,
			 enum MHD_ConnectionNotificationCode code)
{
	if (code == MHD_CONNECTION_NOTIFY_STARTED) {
		const union MHD_ConnectionInfo *ci =
			MHD_get_connection_info(conn, MHD_CONNECTION_INFO_CONNECTION_FD);
		if (ci && (size_t)ci->connect_fd < A.nfds)
			srv_conn_opened_at(A.at[ci->connect_fd]);
	}
	srv_budget_connection(cls, conn, socket_context, code);
	if (code == MHD_CONNECTION_NOTIFY_STARTED) {
		atomic_fetch_add(&A.live, 1);
		atomic_fetch_sub(&A.inflight, 1);
		atomic_fetch_add(&A.started, 1);
	} else {
		atomic_fetch_sub(&A.live, 1);
	}
	wake();
}

unsigned long long srv_acceptor_accepted(void)
{
	return atomic_load(&A.accepted);
}

unsigned long long srv_acceptor_queued_max(void)
{
	return atomic_load(&A.queued_max);
}
