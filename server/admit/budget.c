/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget.c - the daemon's resource budgets: memory reservations, the cores
 * of paced sessions, CPU turns for pace "max" sessions (connections per client address:
 * budget_clients.c).
 *
 * Memory is an estimate made before anything is allocated: the buffers the
 * server allocates are counted exactly from their sizes (record ring,
 * trajectory history, stream buffers); the core instance and the threads
 * are a constant plus a cost per feed element, calibrated against the
 * resident memory the daemon gained per session (docs/budgets.md "Budgets and
 * load" gives the formula; tests/http/memory_formula.test.mjs checks it
 * against what the daemon reserves). The cores of paced sessions are committed
 * the same way: each session holds its need (CPU s per simulated s, first
 * estimated from its integrator and feed, then measured by its worker,
 * times its pace) while it runs. CPU turns are a first-come-first-served
 * queue of at most --max-busy holders, each holding for a time slice while
 * others wait (round robin: each gets an equal share of the cores).
 * The CPU estimate of a session is budget_cost.c's.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "budget_turns.h"
#include "util.h"

/* Calibrated once against resident memory (the formula in docs/budgets.md): bytes a session holds
 * besides its ring and history, as base + per feed element. */
#define SESSION_BASE_BYTES ((size_t)128 << 10)
#define ELEMENT_BYTES ((size_t)384)
/* A stream's connection thread and its bookkeeping. */
#define STREAM_BASE_BYTES ((size_t)96 << 10)
/* Retry-After of a memory refusal: sessions come and go in seconds. */
#define MEMORY_RETRY_S 5
/* Retry-After of a refusal for CPU: paced sessions come and go. */
#define CPU_RETRY_S 5

static const srv_config *cfg;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static size_t reserved;                 /* lock */
static double paced;                    /* lock: cores held */

void srv_budget_init(const srv_config *config)
{
	cfg = config;
	srv_cpu_turns_init(config);
	srv_budget_cost_init(config->max_cpu_seconds);
	srv_budget_clients_init(config);
}

/* ---- memory ---------------------------------------------------------------- */

size_t srv_budget_session_need(int columns, int layers)
{
	size_t ring = cfg->ring > 16 ? (size_t)cfg->ring : 16;
	size_t hist = cfg->history > 16 ? (size_t)cfg->history : 16;
	size_t per = srv_budget_record_doubles(columns, layers);
	return SESSION_BASE_BYTES +
	       ELEMENT_BYTES * (size_t)columns * (size_t)layers +
	       ring * (sizeof(api_sample) + per * sizeof(double)) +
	       hist * API_HISTORY_WIDTH(columns) * sizeof(double) +
	       per * sizeof(double);
}

size_t srv_budget_stream_need(int columns, int layers)
{
	/* stream.c: the record copy and 4 formatted records + 64 kB */
	return STREAM_BASE_BYTES +
	       srv_budget_record_doubles(columns, layers) * sizeof(double) +
	       4 * api_record_max(columns, layers) + 65536;
}

size_t srv_budget_memory(void)
{
	return cfg->max_memory;
}

size_t srv_budget_reserved(void)
{
	pthread_mutex_lock(&lock);
	size_t n = reserved;
	pthread_mutex_unlock(&lock);
	return n;
}

static double mib(size_t bytes)
{
	return (double)bytes / (1 << 20);
}

/* Add n to *pool if it stays within cap (or force); *before: the pool
 * before. 1 if added. */
static int reserve(size_t *pool, size_t cap, size_t n, int force,
		   size_t *before)
{
	pthread_mutex_lock(&lock);
	*before = *pool;
	int room = force || (*pool <= cap && n <= cap - *pool);
	if (room)
		*pool += n;
	pthread_mutex_unlock(&lock);
	return room;
}

api_err srv_budget_take(size_t bytes, const char *what, int force,
			api_problem *pb)
{
	size_t used;
	if (reserve(&reserved, cfg->max_memory, bytes, force, &used))
		return API_OK;
	api_fail(pb, API_UNAVAILABLE, NULL,
		 "%s needs %.1f MiB and %.1f MiB of the memory budget of "
		 "%.1f MiB (--max-memory) are taken; nothing was created, "
		 "retry when sessions or streams have ended", what, mib(bytes),
		 mib(used), mib(cfg->max_memory));
	return api_budget(pb, "memory", (double)cfg->max_memory, MEMORY_RETRY_S);
}

api_err srv_budget_take_session(int columns, int layers, size_t *need,
				api_problem *pb)
{
	*need = srv_budget_session_need(columns, layers);
	if (*need <= cfg->max_memory)
		return srv_budget_take(*need, "this session", 0, pb);
	/* alone too large: the largest feed of this shape that fits */
	int fit = layers;
	while (fit > 0 && srv_budget_session_need(columns, fit) > cfg->max_memory)
		fit--;
	const char *field = fit > 0 ? "scene.layers" : "scene.columns";
	api_fail(pb, API_RANGE, field,
		 "this session needs %.1f MiB (%d x %d feed, %d stream records, "
		 "%d trajectory rows), more than the whole memory budget of "
		 "%.1f MiB (--max-memory); %s", mib(*need), columns, layers,
		 cfg->ring, cfg->history, mib(cfg->max_memory),
		 fit > 0 ? "fewer layers fit" : "fewer columns fit");
	if (fit == 0) {
		fit = columns;
		while (fit > 0 && srv_budget_session_need(fit, 1) > cfg->max_memory)
			fit--;
	}
	pb->has_range = 1;
	pb->min = fit > 0 ? 1 : 0;
	pb->max = fit;
	return api_budget(pb, "memory", (double)cfg->max_memory, 0);
}

void srv_budget_give(size_t bytes)
{
	pthread_mutex_lock(&lock);
	reserved -= bytes < reserved ? bytes : reserved;
	pthread_mutex_unlock(&lock);
}

/* ---- cores of paced sessions ------------------------------------------------ */

int srv_budget_raise_paced(double *held, double need, double *taken)
{
	pthread_mutex_lock(&lock);
	double others = paced - *held;
	int fits = need <= *held || others + need <= cfg->max_paced_cores * (1 + 1e-12);
	if (fits && need > *held) {
		paced = others + need;
		*held = need;
	}
	*taken = paced;
	pthread_mutex_unlock(&lock);
	return fits;
}

api_err srv_budget_take_paced(double *held, double cpu_per_s, double pace,
			      const char *field, const char *verb,
			      api_problem *pb)
{
	double need = cpu_per_s * pace, limit = cfg->max_paced_cores, taken;
	if (srv_budget_raise_paced(held, need, &taken))
		return API_OK;
	double others = taken - *held;
	if (need > limit) {
		/* none from the least pace up fits: "max" only, pace's one choice (no range) */
		int none = !(limit / cpu_per_s >= API_PACE_MIN);
		api_fail(pb, API_RANGE, field,
			 "this session needs %.3g core%s (%.3g ms of CPU per "
			 "simulated s at pace %g), more than the %g core%s for "
			 "paced sessions (--max-paced-cores); nothing was %s, %s",
			 need, api_plural_g(need, 3, "", "s"), 1e3 * cpu_per_s, pace, limit,
			 api_plural_g(limit, 6, "", "s"), verb,
			 none ? "no pace from 0.001 fits: run it at pace \"max\"" : "lower the pace");
		pb->has_range = !none;
		pb->min = API_PACE_MIN;
		pb->max = limit / cpu_per_s;
		if (none && strcmp(field, "pace") == 0)
			snprintf(pb->choices, sizeof pb->choices, "max");
		return api_budget(pb, "cpu", limit, 0);
	}
	api_fail(pb, API_UNAVAILABLE, field,
		 "this session needs %.3g core%s (%.3g ms of CPU per simulated s "
		 "at pace %g) and running paced sessions hold %.3g of the %g "
		 "core%s for paced sessions (--max-paced-cores); nothing was %s, "
		 "retry when paced sessions have ended, paused or slowed down",
		 need, api_plural_g(need, 3, "", "s"), 1e3 * cpu_per_s, pace, others, limit,
		 api_plural_g(limit, 6, "", "s"), verb);
	return api_budget(pb, "cpu", limit, CPU_RETRY_S);
}

double srv_budget_fit_pace(double *held, srv_pace_cost cost, const void *session, double pace)
{
	pthread_mutex_lock(&lock);
	double others = paced - *held, room = cfg->max_paced_cores - others;
	double fit = pace;
	if (cost(session, pace) * pace > room * (1 + 1e-12)) {
		fit = srv_budget_greatest_pace(cost, session, room);
		if (fit > 0) { /* three significant digits */
			double unit = pow(10, floor(log10(fit)) - 2);
			fit = floor(fit / unit) * unit;
		}
	}
	if (!(fit >= API_PACE_MIN))
		fit = API_PACE_MIN;
	if (fit > pace)
		fit = pace;
	*held = cost(session, fit) * fit;
	paced = others + *held;
	pthread_mutex_unlock(&lock);
	return fit;
}

void srv_budget_set_paced(double *held, double need)
{
	if (!(need >= 0))
		need = 0;
	pthread_mutex_lock(&lock);
	paced += need - *held;
	if (paced < 1e-12)
		paced = 0; /* no drift below nothing */
	*held = need;
	pthread_mutex_unlock(&lock);
}

double srv_budget_paced(void)
{
	pthread_mutex_lock(&lock);
	double c = paced;
	pthread_mutex_unlock(&lock);
	return c;
}

double srv_budget_paced_limit(void)
{
	return cfg->max_paced_cores;
}

/* ---- queued sweep points ------------------------------------------------------ */

static size_t points;               /* lock */
static double point_seconds = 1.0;  /* lock: mean wall time of a point */

api_err srv_budget_take_points(size_t n, const char *field, int force,
			       api_problem *pb)
{
	size_t cap = (size_t)cfg->max_queued_points;
	if (n > cap && !force) {
		api_fail_range(pb, field, 1, (double)cap,
			       "this sweep has %zu points, more than the %zu sweep "
			       "point%s that may be queued (--max-queued-points); "
			       "split it", n, cap, api_plural((double)cap, "", "s"));
		return api_budget(pb, "sweep-points", (double)cap, 0);
	}
	size_t queued;
	if (reserve(&points, cap, n, force, &queued))
		return API_OK;
	/* the wait: the points beyond the budget, at the pool's pace */
	pthread_mutex_lock(&lock);
	double wait = (double)(queued + n - cap) * point_seconds /
		      (cfg->pool_threads > 0 ? cfg->pool_threads : 1);
	pthread_mutex_unlock(&lock);
	api_fail(pb, API_LIMIT, NULL,
		 "%zu sweep point%s %s queued or running and this sweep adds %zu: the budget is %zu "
		 "(--max-queued-points); nothing was queued", queued, api_plural((double)queued, "", "s"),
		 api_plural((double)queued, "is", "are"), n, cap);
	return api_budget(pb, "sweep-points", (double)cap,
			  wait < 1 ? 1 : wait > 3600 ? 3600 : (int)(wait + 0.999));
}

void srv_budget_point_done(double seconds)
{
	pthread_mutex_lock(&lock);
	if (points)
		points--;
	if (seconds > 0) /* a running mean over the last few dozen points */
		point_seconds += (seconds - point_seconds) / 32;
	pthread_mutex_unlock(&lock);
}

void srv_budget_give_points(size_t n)
{
	pthread_mutex_lock(&lock);
	points -= n < points ? n : points;
	pthread_mutex_unlock(&lock);
}

size_t srv_budget_points(void)
{
	pthread_mutex_lock(&lock);
	size_t n = points;
	pthread_mutex_unlock(&lock);
	return n;
}
