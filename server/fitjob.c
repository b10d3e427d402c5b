/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fitjob.c - calibration fits as jobs (POST /api/v1/fits).
 *
 * A fit is one driver thread running the fitting module's fit_run (the
 * Levenberg-Marquardt loop, which mostly waits) whose model evaluations go
 * to the worker pool as jobs, a batch at a time (the map function below),
 * so fits and sweeps share the pool's threads. Fits live in a registry
 * (registry.c) like sweeps: the registry holds one reference, the driver
 * one; DELETE cancels (the driver's evaluations then return at once and
 * the fit stops after those already running) and unlinks it. A fit's
 * fields are guarded by its own lock. Fits are kept in memory only: they
 * do not outlive the daemon.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit.h"
#include "fitjob.h"
#include "peers.h"
#include "pool.h"
#include "registry.h"
#include "util.h"

typedef struct srv_fit {
	srv_entry entry;
	pthread_mutex_t lock;
	fit_request req;       /* read-only once the driver runs */
	fit_point *points;
	pthread_t thread;
	/* guarded by lock */
	int running, over, cancelled;
	fit_progress pr;
	int has_pr;
	fit_result res;
	char *json, *csv;      /* the result's text once over */
} srv_fit;

static void destroy(srv_entry *en);
static srv_registry fits = SRV_REGISTRY_INIT(destroy);
/* drivers still running (detached threads), for the shutdown's wait */
static pthread_mutex_t drivers_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t drivers_gone = PTHREAD_COND_INITIALIZER;
static int drivers;

void srv_fits_init(const srv_config *cfg)
{
	srv_registry_open(&fits, (size_t)cfg->max_fits);
}

static srv_fit *fit_of(srv_entry *en)
{
	return SRV_CONTAINER(en, srv_fit, entry);
}

static void fit_free_job(srv_fit *f)
{
	if (!f)
		return;
	fit_result_free(&f->res);
	free(f->points);
	free(f->json);
	free(f->csv);
	pthread_mutex_destroy(&f->lock);
	free(f);
}

static void destroy(srv_entry *en)
{
	fit_free_job(fit_of(en));
}

static const char *fit_state(const srv_fit *f)
{
	if (f->over)
		return f->res.status == FIT_FAILED      ? "failed"
		       : f->res.status == FIT_CANCELLED ? "cancelled"
							: "done";
	if (f->cancelled)
		return "cancelled";
	return f->running ? "running" : "queued";
}

static void fill_view(const srv_fit *f, api_fit_view *v)
{
	memset(v, 0, sizeof *v);
	snprintf(v->id, sizeof v->id, "%s", f->entry.id);
	v->state = fit_state(f);
	v->req = &f->req;
	v->pr = f->pr;
	if (!f->has_pr)
		v->pr.phase = NULL, v->pr.cost = NAN;
	v->result = f->json;
}

/* ---- the pool as the fit's map ------------------------------------------ */

typedef struct batch {
	pthread_mutex_t lock;
	pthread_cond_t done;
	size_t left;
	fit_job job;
	void *arg;
} batch;

typedef struct batch_item {
	batch *b;
	size_t i;
} batch_item;

static void batch_finish(batch *b)
{
	pthread_mutex_lock(&b->lock);
	if (--b->left == 0)
		pthread_cond_signal(&b->done);
	pthread_mutex_unlock(&b->lock);
}

static void run_item(void *arg)
{
	batch_item *it = arg;
	batch *b = it->b;
	size_t i = it->i;
	free(it);
	b->job(b->arg, i); /* cheap when cancelled or stopping: it checks */
	batch_finish(b);
}

/* Every job of the batch on the pool (inline when it cannot take one);
 * returns when all are done. */
static void pool_map(void *ctx, size_t n, fit_job job, void *arg)
{
	(void)ctx;
	batch b = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, n, job, arg};
	for (size_t i = 0; i < n; i++) {
		batch_item *it = malloc(sizeof *it);
		if (it)
			*it = (batch_item){&b, i};
		if (!it || srv_pool_submit(run_item, it) != 0) {
			free(it);
			job(arg, i);
			batch_finish(&b);
		}
	}
	pthread_mutex_lock(&b.lock);
	while (b.left)
		pthread_cond_wait(&b.done, &b.lock);
	pthread_mutex_unlock(&b.lock);
	pthread_mutex_destroy(&b.lock);
	pthread_cond_destroy(&b.done);
}

static int is_cancelled(void *ctx)
{
	srv_fit *f = ctx;
	pthread_mutex_lock(&f->lock);
	int c = f->cancelled;
	pthread_mutex_unlock(&f->lock);
	return c || srv_stopping();
}

static void on_progress(void *ctx, const fit_progress *pr)
{
	srv_fit *f = ctx;
	pthread_mutex_lock(&f->lock);
	f->pr = *pr;
	f->has_pr = 1;
	pthread_mutex_unlock(&f->lock);
}

static void *driver(void *arg)
{
	srv_fit *f = arg;
	pthread_mutex_lock(&f->lock);
	f->running = 1;
	pthread_mutex_unlock(&f->lock);
	fit_result res;
	fit_run(&f->req, &res);
	char *json = fit_result_json(&f->req, &res), *csv = fit_result_csv(&f->req, &res);
	pthread_mutex_lock(&f->lock);
	f->res = res;
	f->json = json;
	f->csv = csv;
	f->running = 0;
	f->over = 1;
	pthread_mutex_unlock(&f->lock);
	srv_log(SRV_LOG_INFO, "fit %s: %s after %d iterations, %ld evaluations", f->entry.id,
		fit_status_name(res.status), res.iterations, res.evaluations);
	srv_registry_put(&fits, &f->entry);
	pthread_mutex_lock(&drivers_lock);
	if (--drivers == 0)
		pthread_cond_broadcast(&drivers_gone);
	pthread_mutex_unlock(&drivers_lock);
	return NULL;
}

static int evictable(srv_entry *en)
{
	srv_fit *f = fit_of(en);
	pthread_mutex_lock(&f->lock);
	int over = f->over;
	pthread_mutex_unlock(&f->lock);
	return over;
}

/* Start f's driver with its reference; -1 when no thread. */
static int start_driver(srv_fit *f)
{
	pthread_mutex_lock(&drivers_lock);
	int rc = -1;
	pthread_attr_t attr;
	pthread_attr_init(&attr);
	pthread_attr_setdetachstate(&attr, PTHREAD_CREATE_DETACHED);
	if (!srv_stopping()) {
		srv_registry_hold(&fits, &f->entry);
		rc = pthread_create(&f->thread, &attr, driver, f) == 0 ? 0 : -1;
		if (rc == 0)
			drivers++;
		else
			srv_registry_put(&fits, &f->entry);
	}
	pthread_attr_destroy(&attr);
	pthread_mutex_unlock(&drivers_lock);
	return rc;
}

enum MHD_Result srv_h_fits_create(srv_req *r)
{
	enum MHD_Result res;
	api_problem pb;
	srv_fit *f = calloc(1, sizeof *f);
	if (!f)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	pthread_mutex_init(&f->lock, NULL);
	if (api_parse_fit(r->body, r->body_len, &f->req, &f->points, &pb) != API_OK) {
		fit_free_job(f);
		return srv_reply_problem(r, &pb, NULL);
	}
	f->req.map = pool_map;
	f->req.progress = on_progress;
	f->req.cancelled = is_cancelled;
	f->req.ctx = f;
	if (srv_registry_reserve(&fits, &f->entry, evictable)) {
		fit_free_job(f);
		return srv_fail(r, API_LIMIT, NULL, "%zu fits are running or kept; delete one",
				fits.cap);
	}
	srv_registry_publish(&fits, &f->entry);
	api_fit_view v;
	pthread_mutex_lock(&f->lock);
	fill_view(f, &v);
	char *text = api_fit_json(&v);
	pthread_mutex_unlock(&f->lock);
	if (start_driver(f) != 0) {
		srv_registry_remove(&fits, &f->entry);
		srv_registry_put(&fits, &f->entry);
		free(text);
		return srv_fail(r, API_UNAVAILABLE, NULL, "cannot start the fit (stopping?)");
	}
	res = srv_reply_created(r, 202, text, "/api/v1/fits", v.id);
	srv_registry_put(&fits, &f->entry);
	return res;
}

enum MHD_Result srv_h_fit_get(srv_req *r)
{
	srv_entry *en = srv_registry_get(&fits, r->arg[0]);
	if (!en)
		return srv_fail(r, API_NOTFOUND, NULL, "no fit with id \"%.40s\"", r->arg[0]);
	srv_fit *f = fit_of(en);
	api_fit_view v;
	pthread_mutex_lock(&f->lock);
	fill_view(f, &v);
	char *text = !r->csv ? api_fit_json(&v)
		     : f->csv ? strdup(f->csv)
			      : strdup(FIT_CSV_HEADER "\n");
	pthread_mutex_unlock(&f->lock);
	srv_registry_put(&fits, en);
	return srv_reply_result(r, text);
}

enum MHD_Result srv_h_fits_list(srv_req *r)
{
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(&fits, &all);
	api_fit_view *v = calloc(n + 1, sizeof *v);
	char *text = NULL;
	if (v) {
		for (size_t i = 0; i < n; i++) {
			srv_fit *f = fit_of(all[i]);
			pthread_mutex_lock(&f->lock);
			fill_view(f, &v[i]);
			pthread_mutex_unlock(&f->lock);
		}
		text = r->csv ? api_fit_list_csv(v, n) : api_fit_list_json(v, n);
	}
	srv_registry_release(&fits, all, n);
	free(v);
	return srv_peers_reply(r, text, "fits");
}

enum MHD_Result srv_h_fit_delete(srv_req *r)
{
	srv_entry *en = srv_registry_get(&fits, r->arg[0]);
	if (!en)
		return srv_fail(r, API_NOTFOUND, NULL, "no fit with id \"%.40s\"", r->arg[0]);
	srv_fit *f = fit_of(en);
	pthread_mutex_lock(&f->lock);
	f->cancelled = 1;
	pthread_mutex_unlock(&f->lock);
	srv_registry_remove(&fits, en);
	srv_registry_put(&fits, en);
	return srv_reply_empty(r);
}

void srv_fits_shutdown(void)
{
	/* the drivers see srv_stopping() and end after their running evaluations */
	pthread_mutex_lock(&drivers_lock);
	while (drivers > 0)
		pthread_cond_wait(&drivers_gone, &drivers_lock);
	pthread_mutex_unlock(&drivers_lock);
	srv_registry_clear(&fits);
}
