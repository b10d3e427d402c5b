/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * util.h - small services every part of the daemon uses: levelled logging
 * to stderr, clocks, timed-wait deadlines, random ids, the daemon's
 * "stopping" flag, whether a client's socket is still there. A leaf: it
 * uses nothing else of server/.
 */
#ifndef CONVSIM_UTIL_H
#define CONVSIM_UTIL_H

#include <stdatomic.h>
#include <time.h>

struct api_problem; /* api.h */
struct sockaddr;    /* sys/socket.h */

enum { SRV_LOG_ERROR, SRV_LOG_WARN, SRV_LOG_INFO, SRV_LOG_DEBUG };

/* Messages above level are dropped (default SRV_LOG_INFO). */
void srv_log_init(int level);
/* One line "convsimd LEVEL: message" on stderr. */
void srv_log(int level, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
/* Wall-clock seconds: monotonic (for pacing) and unix time. */
double srv_now(void);
double srv_unix_time(void);
/* The calling thread's CPU time, seconds. */
double srv_thread_cpu(void);
/* Ids made from now on start "node_id-" (borrowed, kept; NULL or "": no
 * prefix). Call once at start-up, before any id is made. */
void srv_ids_init(const char *node_id);
/* 1 if the n bytes at s are an id srv_new_id could make, with any
 * replica's prefix. */
int srv_id_valid(const char *s, size_t n);
/* A fresh random id into id (>= 24 bytes): 16 hex digits, or with a node
 * id "NODE-" and 12 hex digits (a proxy routes by the prefix). */
void srv_new_id(char *id);
/* Absolute deadline for pthread_cond_timedwait, seconds from now
 * (clamped to [0, 3600]). */
struct timespec srv_deadline(double seconds);
/* 1 when the peer of the connected socket fd has left: it closed (the end
 * of its data, also a shutdown of its sending half only) or reset it; 0
 * while it is there (nothing to read, or more requests), and for fd < 0.
 * Reads nothing (a peek); never blocks. */
int srv_peer_gone(int fd);
/* The address bytes of sa in addr (IPv4 in the first 4, the rest 0): 1,
 * or 0 (all 0) for another family. */
int srv_addr_bytes(const struct sockaddr *sa, unsigned char addr[16]);
/* Whether the client on fd left (or left says it did) while the daemon
 * worked for it before its answer: then counted in *abandoned, logged at
 * info ("WHAT ID not DONE: its client left while it WHILE"), and *pb the
 * 503 that ends the connection (an answer to nobody); 1, else 0. */
int srv_client_left(int fd, int left, atomic_ullong *abandoned, const char *what,
		    const char *id, const char *done, const char *while_, struct api_problem *pb);

/* The threads that compute (session workers, the sweep and fit pool) run
 * at a nice value above the request and stream threads' 0 (--worker-nice),
 * so that answers stay prompt when the computations want more CPU than
 * there is. Set it once at start-up, before any such thread starts. */
void srv_background_nice_init(int nice);
/* Give the calling thread that nice value (Linux: nice is per thread, set
 * by its thread id); name (<= 15 characters) shows in ps and top.
 * Failures are logged at debug level and otherwise ignored. */
void srv_thread_background(const char *name);

/* The daemon is shutting down (set once, on SIGTERM/SIGINT): streams end,
 * pool jobs return at once, the API answers 503. */
int srv_stopping(void);
void srv_stop(void);

#endif
