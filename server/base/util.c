/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * util.c - small services of the daemon: levelled logging to stderr,
 * clocks, timed-wait deadlines, random ids (with the replica's node id)
 * the stopping flag, and whether a client's socket is still there.
 */
#define _GNU_SOURCE /* gettid, pthread_setname_np */
#include <errno.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <pthread.h>
#include <stdarg.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <sys/random.h>
#include <sys/resource.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include "api.h"
#include "util.h"

static atomic_int log_level = SRV_LOG_INFO;
static atomic_int stopping;

void srv_log_init(int level)
{
	atomic_store(&log_level, level);
}

void srv_log(int level, const char *fmt, ...)
{
	static const char *const names[] = {"error", "warn", "info", "debug"};
	if (level > atomic_load(&log_level))
		return;
	char line[1024];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof line, fmt, ap);
	va_end(ap);
	fprintf(stderr, "convsimd %s: %s\n", names[level & 3], line);
}

static int background_nice;

void srv_background_nice_init(int nice)
{
	background_nice = nice;
}

void srv_thread_background(const char *name)
{
	pthread_setname_np(pthread_self(), name);
	if (setpriority(PRIO_PROCESS, (id_t)gettid(), background_nice) != 0)
		srv_log(SRV_LOG_DEBUG, "cannot lower the priority of a %s thread",
			name);
}

double srv_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double srv_thread_cpu(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

double srv_unix_time(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

struct timespec srv_deadline(double seconds)
{
	struct timespec ts;
	clock_gettime(CLOCK_REALTIME, &ts);
	if (seconds < 0)
		seconds = 0;
	if (seconds > 3600)
		seconds = 3600;
	long long ns = (long long)ts.tv_nsec + (long long)(seconds * 1e9);
	ts.tv_sec += (time_t)(ns / 1000000000LL);
	ts.tv_nsec = (long)(ns % 1000000000LL);
	return ts;
}

int srv_peer_gone(int fd)
{
	if (fd < 0)
		return 0;
	char c;
	ssize_t n;
	do
		n = recv(fd, &c, 1, MSG_PEEK | MSG_DONTWAIT);
	while (n < 0 && errno == EINTR);
	if (n > 0)
		return 0; /* its next request waits (pipelined): it is there */
	if (n == 0)
		return 1; /* the end of its data: it closed */
	return errno != EAGAIN && errno != EWOULDBLOCK; /* reset, or worse */
}

static const char *node_prefix; /* set once, before any thread starts */

void srv_ids_init(const char *node_id)
{
	node_prefix = node_id && *node_id ? node_id : NULL;
}

void srv_new_id(char *id)
{
	static atomic_uint counter;
	unsigned char raw[8];
	int nraw = 8;
	if (getrandom(raw, sizeof raw, 0) != (ssize_t)sizeof raw) {
		unsigned long long x = (unsigned long long)(srv_unix_time() *
							    1e6) ^
				       ((unsigned long long)atomic_fetch_add(
						&counter, 1)
					<< 40);
		memcpy(raw, &x, sizeof raw);
	}
	if (node_prefix) {
		id += sprintf(id, "%s-", node_prefix);
		nraw = 6;
	}
	for (int i = 0; i < nraw; i++)
		snprintf(id + 2 * i, 3, "%02x", raw[i]);
}

/* 1 if the n bytes at s are lowercase hex digits. */
static int hex_digits(const char *s, size_t n)
{
	for (size_t i = 0; i < n; i++)
		if (!((s[i] >= '0' && s[i] <= '9') || (s[i] >= 'a' && s[i] <= 'f')))
			return 0;
	return 1;
}

int srv_id_valid(const char *s, size_t n)
{
	if (n == 16)
		return hex_digits(s, 16);
	/* NODE-: 1 to 10 of a-z 0-9 - (any replica's, config.c), then 12 */
	if (n < 14 || n > 23 || s[n - 13] != '-' || !hex_digits(s + n - 12, 12))
		return 0;
	for (size_t i = 0; i < n - 13; i++)
		if (!((s[i] >= 'a' && s[i] <= 'z') || (s[i] >= '0' && s[i] <= '9') ||
		      s[i] == '-'))
			return 0;
	return 1;
}

int srv_stopping(void)
{
	return atomic_load(&stopping);
}

void srv_stop(void)
{
	atomic_store(&stopping, 1);
}

int srv_addr_bytes(const struct sockaddr *sa, unsigned char addr[16])
{
	memset(addr, 0, 16);
	if (sa->sa_family == AF_INET)
		memcpy(addr, &((const struct sockaddr_in *)(const void *)sa)->sin_addr, 4);
	else if (sa->sa_family == AF_INET6)
		memcpy(addr, &((const struct sockaddr_in6 *)(const void *)sa)->sin6_addr, 16);
	else
		return 0;
	return 1;
}

int srv_client_left(int fd, int left, atomic_ullong *abandoned, const char *what,
		    const char *id, const char *done, const char *while_, struct api_problem *pb)
{
	if (!left && !srv_peer_gone(fd))
		return 0;
	atomic_fetch_add(abandoned, 1);
	srv_log(SRV_LOG_INFO, "%s %s not %s: its client left while it %s", what, id, done, while_);
	api_fail(pb, API_UNAVAILABLE, NULL, "the client left while its %s %s; nothing was %s",
		 what, while_, done);
	pb->close = 1;
	return 1;
}
