/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * metrics.c - counters and the Prometheus text exposition at /metrics.
 *
 * Counters are atomics bumped where things happen (requests by status,
 * steps, stream records, dropped samples); gauges (sessions, stream
 * clients, steps per second) are read when scraped: the caller hands in
 * the ones other modules own, so this file calls nothing of server/.
 */
#include <stdio.h>
#include <stdlib.h>

#include "metrics.h"

srv_metrics srv_stats;
static atomic_ullong by_status[600];

void srv_metrics_count(int status)
{
	if (status >= 100 && status < 600) {
		atomic_fetch_add(&by_status[status], 1);
		atomic_fetch_add(&srv_stats.requests[status / 100], 1);
	}
}

static void metric(FILE *f, const char *name, const char *type,
		   const char *help, double value)
{
	fprintf(f, "# HELP %s %s\n# TYPE %s %s\n%s %.17g\n", name, help, name,
		type, name, value);
}

/* The counters and gauges of sessions, steps, streams, jobs and the store. */
static void activity_metrics(FILE *f, const srv_gauges *g)
{
	metric(f, "convsim_sessions", "gauge", "Live simulation sessions.",
	       g->sessions);
	metric(f, "convsim_sessions_created_total", "counter",
	       "Sessions created.", (double)srv_stats.sessions_created);
	metric(f, "convsim_sessions_deleted_total", "counter",
	       "Sessions deleted.", (double)srv_stats.sessions_deleted);
	metric(f, "convsim_sessions_abandoned_total", "counter",
	       "Creations discarded because their client left while they settled.",
	       (double)srv_stats.sessions_abandoned);
	metric(f, "convsim_steps_total", "counter",
	       "Integrator steps taken by all sessions.",
	       (double)srv_stats.steps);
	metric(f, "convsim_steps_per_second", "gauge",
	       "Integrator steps per wall second, summed over sessions.",
	       g->steps_per_s);
	metric(f, "convsim_stream_clients", "gauge",
	       "Open stream connections.",
	       (double)atomic_load(&srv_stats.stream_clients));
	metric(f, "convsim_streams_opened_total", "counter",
	       "Stream connections opened.", (double)srv_stats.streams_opened);
	metric(f, "convsim_stream_records_total", "counter",
	       "Records written to stream clients.",
	       (double)srv_stats.stream_records);
	metric(f, "convsim_stream_dropped_samples_total", "counter",
	       "Records slow stream clients missed.",
	       (double)srv_stats.dropped_samples);
	metric(f, "convsim_experiments_total", "counter",
	       "Experiments started.", (double)srv_stats.experiments);
	metric(f, "convsim_experiments_abandoned_total", "counter",
	       "Experiments withdrawn because their client left while they measured.",
	       (double)srv_stats.experiments_abandoned);
	metric(f, "convsim_sweep_points_total", "counter",
	       "Sweep points measured.", (double)srv_stats.sweep_points);
	metric(f, "convsim_store_writes_total", "counter",
	       "Files written to the data directory.",
	       (double)srv_stats.store_writes);
	metric(f, "convsim_control_log_syncs_total", "counter",
	       "Control-log syncs: each makes every control appended before it durable.",
	       (double)srv_stats.log_syncs);
	metric(f, "convsim_store_errors_total", "counter",
	       "Writes to the data directory that failed (ENOSPC, EIO, ...).",
	       (double)srv_stats.store_errors);
	metric(f, "convsim_pool_queued", "gauge",
	       "Sweep jobs waiting for a pool thread.",
	       g->pool_queued);
}

/* The budgets' use and limits, and the connections refused or closed. */
static void budget_metrics(FILE *f, const srv_gauges *g)
{
	const struct {
		const char *name, *type, *help;
		double value;
	} budgets[] = {
		{"convsim_memory_reserved_bytes", "gauge", "Estimated memory of live "
		 "sessions and streams (the memory budget's use).", g->memory_reserved},
		{"convsim_memory_budget_bytes", "gauge", "The memory budget "
		 "(--max-memory).", g->memory_budget},
		{"convsim_paced_cpu_cores", "gauge", "Cores committed to running "
		 "paced sessions: each its CPU s per simulated s times its pace "
		 "(the paced CPU budget's use).", g->paced_cores},
		{"convsim_paced_cpu_budget_cores", "gauge", "The cores running "
		 "paced sessions may need together (--max-paced-cores).",
		 g->paced_cores_budget},
		{"convsim_cpu_slots_busy", "gauge", "Pace max sessions stepping now "
		 "(at most --max-busy).", g->cpu_busy},
		{"convsim_cpu_slots_waiting", "gauge", "Pace max sessions waiting "
		 "for their turn.", g->cpu_waiting},
		{"convsim_settling", "gauge", "Requests settling simulations in "
		 "their own thread now: creations, experiments' measurements "
		 "(at most --max-settling).", g->settling},
		{"convsim_settling_max", "gauge", "The most requests that settled "
		 "simulations at once.", g->settling_max},
		{"convsim_settling_refused_total", "counter", "Requests answered "
		 "503 beyond --max-settling.", g->settling_refused},
		{"convsim_sweep_points_queued", "gauge", "Sweep points queued or "
		 "running (at most --max-queued-points).", g->sweep_points},
		{"convsim_client_connections_refused_total", "counter", "Connections "
		 "answered 429 beyond --max-client-connections.", g->client_refused},
		{"convsim_connections_dropped_total", "counter", "Connections closed "
		 "at accept: beyond a client's budget and its grace, or beyond "
		 "--max-connections.", g->connections_dropped},
		{"convsim_connections_evicted_total", "counter", "Connections "
		 "closed to make room at --max-connections: the one with the "
		 "least progress (idle longest, headers or body furthest "
		 "behind), never one being answered.", g->connections_evicted},
		{"convsim_connections_timed_out_total", "counter", "Connections "
		 "closed at their deadline: idle beyond --connection-timeout, "
		 "headers not all in within --request-timeout, a body slower "
		 "than --min-body-rate.", g->connections_timed_out},
		{"convsim_connections_answered_408_total", "counter", "Of the "
		 "connections closed at their deadline, the bodies answered 408 "
		 "first.", g->connections_answered_408},
		{"convsim_connections_accepted_total", "counter", "Connections "
		 "accepted from the listening socket.", g->connections_accepted},
		{"convsim_connections_waiting_max", "gauge", "The most accepted "
		 "connections that waited at once to be handed to the HTTP "
		 "library, those of addresses with fewer open ones first.",
		 g->connections_waiting_max},
	};
	for (size_t i = 0; i < sizeof budgets / sizeof *budgets; i++)
		metric(f, budgets[i].name, budgets[i].type, budgets[i].help,
		       budgets[i].value);
}

char *srv_metrics_text(const srv_gauges *g)
{
	char *text = NULL;
	size_t len = 0;
	FILE *f = open_memstream(&text, &len);
	if (!f)
		return NULL;
	activity_metrics(f, g);
	budget_metrics(f, g);
	fprintf(f, "# HELP convsim_http_requests_total HTTP responses by "
		   "status.\n# TYPE convsim_http_requests_total counter\n");
	for (int s = 100; s < 600; s++) {
		unsigned long long n = atomic_load(&by_status[s]);
		if (n)
			fprintf(f,
				"convsim_http_requests_total{status=\"%d\"} "
				"%llu\n", s, n);
	}
	fclose(f);
	return text;
}
