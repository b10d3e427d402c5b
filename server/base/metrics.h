/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * metrics.h - the daemon's counters and their Prometheus text.
 *
 * Counters are atomics that the modules bump where things happen; gauges
 * (live sessions, steps per second, queued pool jobs) belong to other
 * modules and are handed in when /metrics is scraped. A leaf: it calls
 * nothing else of server/.
 */
#ifndef CONVSIM_METRICS_H
#define CONVSIM_METRICS_H

#include <stdatomic.h>

typedef struct srv_metrics {
	atomic_ullong sessions_created, sessions_deleted;
	atomic_ullong sessions_abandoned; /* their client left while they
					     settled: not created */
	atomic_ullong steps;             /* all sessions */
	atomic_int stream_clients;
	atomic_ullong streams_opened, dropped_samples, stream_records;
	atomic_ullong sweep_points, experiments;
	atomic_ullong experiments_abandoned; /* their client left while they
						measured */
	atomic_ullong store_writes, store_errors; /* files the writer wrote, failed */
	atomic_ullong log_syncs;  /* fdatasyncs of control logs (one a round
				     of group commit) */
	atomic_ullong requests[6];       /* by status class 1xx..5xx (index 1..5) */
} srv_metrics;
extern srv_metrics srv_stats;

/* Gauges read by the caller at scrape time. */
typedef struct srv_gauges {
	double sessions;
	double steps_per_s;   /* summed over running sessions */
	double pool_queued;
	/* budgets (budget.c) */
	double memory_reserved, memory_budget; /* bytes */
	double paced_cores, paced_cores_budget; /* held by running paced
						   sessions, --max-paced-cores */
	double cpu_busy, cpu_waiting;  /* pace "max" slots in use, waiting */
	double settling, settling_max; /* requests settling now, the most at
					  once (budget_settling.c) */
	double settling_refused;       /* requests refused beyond them */
	double sweep_points;           /* queued or running */
	double client_refused;         /* connections answered 429 */
	double connections_dropped;    /* closed by libmicrohttpd at accept */
	double connections_evicted;    /* closed at the cap (conns.c) */
	double connections_timed_out;  /* closed at their deadline (conns.c) */
	double connections_answered_408; /* of those timed out (conns.c) */
	double connections_accepted;   /* accepted (acceptor.c) */
	double connections_waiting_max; /* most waiting at once (acceptor.c) */
} srv_gauges;

/* Count one response with this HTTP status. */
void srv_metrics_count(int status);
/* The Prometheus text exposition (malloc'd, caller frees; NULL when out of
 * memory). */
char *srv_metrics_text(const srv_gauges *g);

#endif
