/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fitjob.c - calibration fits as jobs (POST /api/v1/fits).
 *
 * A fit is one driver thread running the fitting module's fit_run (the
 * Levenberg-Marquardt loop, which mostly waits) whose model evaluations go
 * to the worker pool as jobs, a batch at a time (srv_pool_map, pool.c),
 * so fits and sweeps share the pool's threads. Fits live in a registry
 * (registry.c) like sweeps: the registry holds one reference, the driver
 * one; DELETE cancels (the driver's evaluations then return at once and
 * the fit stops after those already running) and unlinks it. A fit's
 * fields are guarded by its own lock. The fit is one kind of job
 * (job.h): srv_fit_job below is its descriptor.
 *
 * With --data-dir a fit persists like a sweep: fits/ID.bin holds its
 * request body, written at creation, and once over its progress and its
 * result's JSON and CSV, so a restart serves a finished fit byte for byte;
 * a fit that was running when the daemon stopped or died runs again from
 * its start. A fit that ends because the daemon stops is not written over.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "fit.h"
#include "fitjob.h"
#include "job.h"
#include "pool.h"
#include "records.h"
#include "registry.h"
#include "store.h"
#include "util.h"

typedef struct srv_fit {
	srv_entry entry;
	pthread_mutex_t lock;
	fit_request req;       /* read-only once the driver runs */
	fit_point *points;
	char *body;            /* the request as posted (persisted) */
	size_t body_len;
	pthread_t thread;
	/* guarded by lock */
	int running, over, cancelled;
	fit_progress pr;
	int has_pr;
	fit_result res;
	char *json, *csv;      /* the result's text once over */
	char store_error[256]; /* its record's last write failed: why (state
				  "error": a restart would not find it) */
} srv_fit;

static void destroy(srv_entry *en);
static srv_registry fits = SRV_REGISTRY_INIT(destroy);
/* drivers still running (detached threads), for the shutdown's wait */
static pthread_mutex_t drivers_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t drivers_gone = PTHREAD_COND_INITIALIZER;
static int drivers;

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
	free(f->body);
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
	if (f->store_error[0])
		return "error";
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
	v->error = f->store_error;
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

/* ---- persistence (store.h) ---------------------------------------------
 *
 * fits/ID.bin: the record below, then the request body, the result's JSON
 * and its CSV (empty until over). */
static const char *const phases[] = {"fitting", "covariance", "curve", "done"};
#define NPHASES (sizeof phases / sizeof *phases)

typedef srv_fit_record fit_record; /* records.h */

/* A write's outcome for fit id (malloc'd, freed here): a failure puts the
 * fit in state "error" with the reason; a later write that lands clears
 * it (its record is on disk again). */
static void written(void *arg, int err, const char *what)
{
	char *id = arg;
	srv_entry *en = srv_registry_get(&fits, id);
	free(id);
	if (!en)
		return;
	srv_fit *f = fit_of(en);
	pthread_mutex_lock(&f->lock);
	if (err)
		snprintf(f->store_error, sizeof f->store_error, "%s", what);
	else if (what && what[0] == '\0')
		f->store_error[0] = '\0';
	pthread_mutex_unlock(&f->lock);
	srv_registry_put(&fits, en);
}

/* Queue fits/ID.bin (lock held); now: write it on this thread (its
 * creation: on disk before the answer). */
static void persist_locked(srv_fit *f, int now)
{
	if (!srv_store_enabled())
		return;
	fit_record r;
	memset(&r, 0, sizeof r);
	snprintf(r.id, sizeof r.id, "%s", f->entry.id);
	r.over = f->over;
	r.status = f->res.status;
	r.has_pr = f->has_pr;
	r.phase = -1;
	for (size_t i = 0; f->has_pr && f->pr.phase && i < NPHASES; i++)
		if (strcmp(f->pr.phase, phases[i]) == 0)
			r.phase = (int32_t)i;
	r.iteration = f->pr.iteration;
	r.evaluations = f->pr.evaluations;
	r.cost = f->pr.cost;
	memcpy(r.x, f->pr.x, sizeof r.x);
	r.body_len = f->body_len;
	r.json_len = f->over && f->json ? strlen(f->json) : 0;
	r.csv_len = f->over && f->csv ? strlen(f->csv) : 0;
	size_t n = sizeof r + r.body_len + r.json_len + r.csv_len;
	char *p = malloc(n);
	if (!p)
		return;
	memcpy(p, &r, sizeof r);
	memcpy(p + sizeof r, f->body, r.body_len);
	if (r.json_len) /* none until over */
		memcpy(p + sizeof r + r.body_len, f->json, r.json_len);
	if (r.csv_len)
		memcpy(p + sizeof r + r.body_len + r.json_len, f->csv, r.csv_len);
	char *id = now ? NULL : strdup(f->entry.id);
	if (now)
		srv_job_save_now(&srv_fit_job, f->entry.id, p, n, f->store_error,
				 sizeof f->store_error);
	else if (id && srv_job_save(&srv_fit_job, f->entry.id, p, n, written, id) != 0)
		free(id);
	free(p);
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
	/* not when deleted, nor when the daemon stops it: it runs again */
	if (!f->cancelled && !srv_stopping())
		persist_locked(f, 0);
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

/* A fit for a request body (kept for its record); NULL with *pb. */
static srv_fit *fit_new(const char *body, size_t len, api_problem *pb)
{
	srv_fit *f = calloc(1, sizeof *f);
	if (!f) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	pthread_mutex_init(&f->lock, NULL);
	if (api_parse_fit(body, len, &f->req, &f->points, pb) != API_OK) {
		fit_free_job(f);
		return NULL;
	}
	f->body = malloc(len + 1);
	if (!f->body) {
		fit_free_job(f);
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	memcpy(f->body, body, len);
	f->body[len] = '\0';
	f->body_len = len;
	f->req.map = srv_pool_map;
	f->req.progress = on_progress;
	f->req.cancelled = is_cancelled;
	f->req.ctx = f;
	return f;
}

/* A new fit, refused whole where one evaluation (its model at the start
 * values) would outlast --max-cpu-seconds (a restored one is not). */
static srv_entry *fit_create(const char *body, size_t len, api_problem *pb)
{
	srv_fit *f = fit_new(body, len, pb);
	if (!f)
		return NULL;
	api_spec spec = {.params = f->req.p, .scene = f->req.sc, .method = f->req.m};
	if (srv_budget_run_check(&spec, f->req.t_end, pb) != API_OK) {
		fit_free_job(f);
		return NULL;
	}
	return &f->entry;
}

static void fit_discard(srv_entry *en)
{
	fit_free_job(fit_of(en));
}

/* Its record first, then its driver: the answer shows it queued. */
static api_err fitjob_start(srv_entry *en, int client_fd, char **answer, api_problem *pb)
{
	(void)client_fd; /* queued: nothing runs in the request */
	srv_fit *f = fit_of(en);
	api_fit_view v;
	pthread_mutex_lock(&f->lock);
	persist_locked(f, 1); /* the answer shows a failure */
	fill_view(f, &v);
	char *text = api_fit_json(&v);
	pthread_mutex_unlock(&f->lock);
	if (start_driver(f) != 0) {
		free(text);
		return api_fail(pb, API_UNAVAILABLE, NULL, "cannot start the fit (stopping?)");
	}
	*answer = text;
	return API_OK;
}

static pthread_mutex_t *fit_lock(srv_entry *en)
{
	return &fit_of(en)->lock;
}

static char *fit_text(srv_entry *en, int csv)
{
	srv_fit *f = fit_of(en);
	api_fit_view v;
	fill_view(f, &v);
	return !csv ? api_fit_json(&v) : f->csv ? strdup(f->csv) : strdup(FIT_CSV_HEADER "\n");
}

static void fit_view(srv_entry *en, void *view, void *scratch)
{
	(void)scratch;
	fill_view(fit_of(en), view);
}

static char *fit_list_text(const void *views, size_t n, int csv)
{
	return csv ? api_fit_list_csv(views, n) : api_fit_list_json(views, n);
}

/* DELETE: the driver's evaluations return at once. */
static int fit_cancel(srv_entry *en, int only_running)
{
	srv_fit *f = fit_of(en);
	if (only_running && (f->over || f->cancelled))
		return 0;
	f->cancelled = 1;
	return 1;
}

/* A fit from its record (taken): over with its progress and result, or
 * to run again (fit_resume); NULL with the reason. */
static srv_entry *fit_load(void *payload, size_t len, char *why, size_t whylen)
{
	char *p = payload;
	fit_record r;
	int ok = len >= sizeof r;
	if (ok) {
		memcpy(&r, p, sizeof r);
		ok = r.body_len <= len && r.json_len <= len && r.csv_len <= len &&
		     len == sizeof r + r.body_len + r.json_len + r.csv_len &&
		     r.phase >= -1 && r.phase < (int32_t)NPHASES &&
		     (!r.over || (r.json_len > 0 && r.csv_len > 0));
	}
	api_problem pb;
	srv_fit *f = ok ? fit_new(p + sizeof r, r.body_len, &pb) : NULL;
	if (!ok)
		snprintf(why, whylen, "inconsistent");
	else if (!f)
		snprintf(why, whylen, "%s", pb.detail);
	if (f && r.over) {
		f->json = strndup(p + sizeof r + r.body_len, r.json_len);
		f->csv = strndup(p + sizeof r + r.body_len + r.json_len, r.csv_len);
		f->over = 1;
		f->res.status = r.status;
		f->has_pr = r.has_pr;
		f->pr.phase = r.phase >= 0 ? phases[r.phase] : NULL;
		f->pr.iteration = r.iteration;
		f->pr.evaluations = r.evaluations;
		f->pr.cost = r.cost;
		memcpy(f->pr.x, r.x, sizeof r.x);
		if (!f->json || !f->csv) {
			snprintf(why, whylen, "out of memory");
			fit_free_job(f);
			f = NULL;
		}
	}
	if (f) {
		r.id[SRV_ID_LEN - 1] = '\0';
		snprintf(f->entry.id, sizeof f->entry.id, "%s", r.id);
	}
	free(p);
	return f ? &f->entry : NULL;
}

api_err srv_fit_band_source(const char *id, fit_band_source *src, api_problem *pb)
{
	srv_entry *en = srv_registry_get(&fits, id);
	if (!en)
		return api_fail(pb, API_INVALID, "band_from_fit",
				"band_from_fit: no fit has the id '%s' (GET /api/v1/fits lists them)",
				id);
	srv_fit *f = fit_of(en);
	char msg[300] = "";
	pthread_mutex_lock(&f->lock);
	const char *state = fit_state(f);
	int rc = SIM_EPARAM;
	if (!f->over || !f->json)
		snprintf(msg, sizeof msg, "is %s; a band needs a finished fit", state);
	else if ((rc = fit_band_source_parse(f->json, src, msg, sizeof msg)) == SIM_OK)
		src->fd_rel = f->req.fd_rel;
	pthread_mutex_unlock(&f->lock);
	srv_registry_put(&fits, en);
	if (rc != SIM_OK)
		return api_fail(pb, API_INVALID, "band_from_fit", "band_from_fit: fit '%s' %s%s", id,
				strncmp(msg, "is ", 3) == 0 ? "" : ": ", msg);
	return API_OK;
}

/* A restored fit that was not over runs again from its start. */
static void fit_resume(srv_entry *en)
{
	srv_fit *f = fit_of(en);
	if (!f->over && start_driver(f) != 0)
		srv_log(SRV_LOG_WARN, "fit %s: cannot run again (stopping?)", f->entry.id);
}

const srv_job_kind srv_fit_job = {
	.name = "fit",
	.plural = "fits",
	.reg = &fits,
	.created_status = 202,
	.limit = "running or kept; delete one",
	.store_kind = SRV_STORE_FIT,
	.create = fit_create,
	.discard = fit_discard,
	.start = fitjob_start,
	.evictable = evictable,
	.lock = fit_lock,
	.text = fit_text,
	.view_size = sizeof(api_fit_view),
	.view = fit_view,
	.list_text = fit_list_text,
	.cancel = fit_cancel,
	.load = fit_load,
	.resume = fit_resume,
};

void srv_fits_shutdown(void)
{
	/* the drivers see srv_stopping() and end after their running evaluations */
	pthread_mutex_lock(&drivers_lock);
	while (drivers > 0)
		pthread_cond_wait(&drivers_gone, &drivers_lock);
	pthread_mutex_unlock(&drivers_lock);
	srv_job_close(&srv_fit_job);
}
