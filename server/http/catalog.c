/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * catalog.c - the daemon's read-only resources: presets and the settings
 * table, health, /metrics (the gauges gathered here, the text by
 * metrics.c) and the OpenAPI document (built once, on first use).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <pthread.h>

#include "acceptor.h"
#include "api_routes.h"
#include "budget.h"
#include "budget_turns.h"
#include "catalog.h"
#include "conns.h"
#include "metrics.h"
#include "pool.h"
#include "session.h"
#include "util.h"

static pthread_once_t openapi_once = PTHREAD_ONCE_INIT;
static char *openapi_text;
static double started;
static const srv_config *cfg;

static void build_openapi(void)
{
	openapi_text = api_openapi_json();
}

void srv_catalog_shutdown(void)
{
	free(openapi_text);
	openapi_text = NULL;
}

enum MHD_Result srv_h_openapi(srv_req *r)
{
	pthread_once(&openapi_once, build_openapi);
	if (!openapi_text)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	return srv_reply_static(r, 200, "application/json", openapi_text,
				strlen(openapi_text));
}

enum MHD_Result srv_h_problem(srv_req *r)
{
	char *page = api_problem_page(r->arg[0]);
	if (!page)
		return srv_fail(r, API_NOTFOUND, NULL, "no problem type \"%.40s\"; "
				"/api/v1/problems/not-found lists them all", r->arg[0]);
	return srv_reply(r, 200, "text/html; charset=utf-8", page, NULL, NULL);
}

enum MHD_Result srv_h_presets(srv_req *r)
{
	return srv_reply_json(r, 200, api_presets_json());
}

void srv_catalog_init(const srv_config *config)
{
	cfg = config;
	started = srv_now();
}

enum MHD_Result srv_h_health(srv_req *r)
{
	api_health h = {
		.status = srv_stopping() ? "stopping" : "ok",
		.uptime = srv_now() - started,
		.sessions = (int)srv_session_count(),
		.max_sessions = cfg->max_sessions,
		.stream_clients = atomic_load(&srv_stats.stream_clients),
		.max_streams = cfg->max_streams,
		.pool_threads = cfg->pool_threads,
		.pool_queued = srv_pool_queued(),
	};
	return srv_reply_json(r, srv_stopping() ? 503 : 200,
			      api_health_json(&h));
}

enum MHD_Result srv_h_metrics(srv_req *r)
{
	int busy, waiting, settling, settling_max;
	unsigned long long settling_refused;
	srv_cpu_counts(&busy, &waiting);
	srv_budget_settling_counts(&settling, &settling_max, &settling_refused);
	srv_gauges g = {
		.sessions = (double)srv_session_count(),
		.steps_per_s = srv_sessions_steps_per_s(),
		.pool_queued = (double)srv_pool_queued(),
		.memory_reserved = (double)srv_budget_reserved(),
		.memory_budget = (double)srv_budget_memory(),
		.paced_cores = srv_budget_paced(),
		.paced_cores_budget = srv_budget_paced_limit(),
		.cpu_busy = busy,
		.cpu_waiting = waiting,
		.settling = settling,
		.settling_max = settling_max,
		.settling_refused = (double)settling_refused,
		.sweep_points = (double)srv_budget_points(),
		.client_refused = (double)srv_budget_client_refused(),
		.connections_dropped = (double)srv_budget_connections_dropped(),
		.connections_evicted = (double)srv_conns_evicted(),
		.connections_timed_out = (double)srv_conns_timed_out(),
		.connections_answered_408 = (double)srv_conns_answered_late(),
		.connections_accepted = (double)srv_acceptor_accepted(),
		.connections_waiting_max = (double)srv_acceptor_queued_max(),
	};
	return srv_reply(r, 200, "text/plain; version=0.0.4; charset=utf-8",
			 srv_metrics_text(&g), NULL, NULL);
}
