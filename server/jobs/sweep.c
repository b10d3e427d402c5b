/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep.c - v(beta) sweeps on the worker pool (POST /api/v1/sweeps).
 *
 * A sweep is a grid of (beta, rotation) points, or of any number settings'
 * values and rotation (a study, core/study.h); each point is one pool job
 * that builds a fresh instance with sim_measure (thread-safe, no session
 * involved) and stores the steady transport velocity. Under the mirror
 * reduction (sim_mirror_plan) a point that is the mirror image of another
 * is no job of its own: it is filled when the other is done. Sweeps live in
 * a registry (registry.c) that holds one reference, and every queued job
 * holds one, so DELETE (cancel) can unlink a sweep while its jobs drain;
 * beyond --max-sweeps the oldest finished one is evicted. A sweep's fields
 * are guarded by its own lock. Results are served as JSON or CSV and, with
 * --data-dir, saved as CSV when done. The sweep is one kind of job (job.h):
 * srv_sweep_job below is its descriptor. The mirror reduction's plan of its
 * points and the check of a record read back are sweep_plan.c. With
 * band_from_fit each point is measured again per fitted parameter
 * (fit_band_point) for its band from the fit's covariance.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "fitjob.h"
#include "job.h"
#include "metrics.h"
#include "pool.h"
#include "records.h"
#include "registry.h"
#include "store.h"
#include "sweep_int.h"
#include "util.h"

typedef struct sweep_job {
	srv_sweep *sw;
	size_t i;
} sweep_job;

static void destroy(srv_entry *en);
static srv_registry sweeps = SRV_REGISTRY_INIT(destroy);

static srv_sweep *sweep_of(srv_entry *en)
{
	return SRV_CONTAINER(en, srv_sweep, entry);
}

static void sweep_free(srv_sweep *sw)
{
	if (!sw)
		return;
	free(sw->req.betas);
	free(sw->req.values);
	free(sw->pt);
	free(sw->image);
	free(sw->csv);
	pthread_mutex_destroy(&sw->lock);
	free(sw);
}

static void destroy(srv_entry *en)
{
	sweep_free(sweep_of(en));
}

static const char *sweep_state(const srv_sweep *sw)
{
	if (sw->damaged[0])
		return "damaged";
	if (sw->store_error[0])
		return "error";
	if (sw->cancelled)
		return "cancelled";
	if (sw->done == sw->total)
		return "done";
	return sw->done || sw->running ? "running" : "queued";
}

static void fill_view(const srv_sweep *sw, api_sweep_view *v)
{
	snprintf(v->id, sizeof v->id, "%s", sw->entry.id);
	v->state = sweep_state(sw);
	v->error = sw->damaged[0] ? sw->damaged : sw->store_error;
	v->total = sw->total;
	v->done = sw->done;
	v->t_end = sw->req.t_end;
	v->req = sw->damaged[0] ? NULL : &sw->req;
	v->pt = sw->pt;
}

/* ---- persistence (store.h) ---------------------------------------------
 *
 * sweeps/ID.bin: the record below (the varied settings' names in its
 * request), the betas and every point (with its values), written at
 * creation, after each point and at a cancel (a pending write is replaced
 * by the newer one); at the end, sweep-ID.csv. A restart serves finished
 * sweeps again and queues the points that were pending or running. */
typedef srv_sweep_record sweep_record; /* records.h */

/* A write's outcome for sweep id (malloc'd, freed here). */
static void written(void *arg, int err, const char *what)
{
	char *id = arg;
	srv_entry *en = err ? srv_registry_get(&sweeps, id) : NULL;
	free(id);
	if (!en)
		return;
	srv_sweep *sw = sweep_of(en);
	pthread_mutex_lock(&sw->lock);
	snprintf(sw->store_error, sizeof sw->store_error, "%s", what);
	pthread_mutex_unlock(&sw->lock);
	srv_registry_put(&sweeps, en);
}

/* Queue sweeps/ID.bin (lock held); now: write it on this thread (its
 * creation: on disk before the answer). */
static void persist_locked(srv_sweep *sw, int now)
{
	if (!srv_store_enabled())
		return;
	sweep_record r;
	memset(&r, 0, sizeof r);
	snprintf(r.id, sizeof r.id, "%s", sw->entry.id);
	r.req = sw->req;
	r.req.betas = NULL;
	r.req.values = NULL;
	r.total = sw->total;
	r.done = sw->done;
	r.cancelled = sw->cancelled;
	size_t nb = (size_t)sw->req.nbeta * sizeof *sw->req.betas,
	       np = sw->total * sizeof *sw->pt;
	char *p = malloc(sizeof r + nb + np);
	if (!p)
		return;
	memcpy(p, &r, sizeof r);
	memcpy(p + sizeof r, sw->req.betas, nb);
	memcpy(p + sizeof r + nb, sw->pt, np);
	char *id = now ? NULL : strdup(sw->entry.id);
	if (now)
		srv_job_save_now(&srv_sweep_job, sw->entry.id, p, sizeof r + nb + np,
				 sw->store_error, sizeof sw->store_error);
	else if (id && srv_job_save(&srv_sweep_job, id, p, sizeof r + nb + np, written, id) != 0)
		free(id);
	free(p);
}

/* The CSV result (lock held). */
static void save_results(const srv_sweep *sw)
{
	if (!srv_store_enabled())
		return;
	api_sweep_view v;
	fill_view(sw, &v);
	char *text = api_sweep_csv(&v);
	char name[64];
	snprintf(name, sizeof name, "sweep-%s.csv", sw->entry.id);
	if (text)
		srv_store_write(name, text, strlen(text), 0, written,
				strdup(sw->entry.id));
}

static void run_point(void *arg)
{
	sweep_job *job = arg;
	srv_sweep *sw = job->sw;
	size_t job_i = job->i;
	api_sweep_point *p = &sw->pt[job_i];
	free(job);
	pthread_mutex_lock(&sw->lock);
	int skip = sw->cancelled || srv_stopping();
	if (!skip) {
		p->state = 1;
		sw->running++;
	}
	pthread_mutex_unlock(&sw->lock);
	double started = srv_now();
	if (!skip) {
		api_spec spec = sw->req.spec;
		char msg[160] = "";
		sim_measurement r;
		/* beta was checked and converted to SI by api/, the other
		 * varied settings checked there */
		int rc = srv_sweep_apply(sw, job_i, &spec, msg, sizeof msg);
		/* as the command line's sweep: with a band, the whole window */
		if (rc == SIM_OK)
			rc = (sw->req.band ? sim_measure : sim_measure_point)(
				&spec.params, &spec.scene, &spec.method, sw->req.t_end, &r, msg,
				sizeof msg);
		double band[2] = {NAN, NAN};
		if (rc == SIM_OK && sw->req.band)
			rc = fit_band_point(&sw->req.band_src, sw->req.band_skip, &spec.params,
					    &spec.scene, &spec.method, sw->req.t_end, &r, &band[0],
					    &band[1], msg, sizeof msg);
		pthread_mutex_lock(&sw->lock);
		sw->running--;
		if (rc == SIM_OK) {
			p->state = 2;
			p->m = r;
			p->band[0] = band[0];
			p->band[1] = band[1];
			/* not shown: the record stays the same for the same sweep */
			p->m.cpu_seconds = 0.0;
		} else {
			p->state = 3;
			snprintf(p->error, sizeof p->error, "%s",
				 msg[0] ? msg : sim_strerror(rc));
		}
		sw->done++;
		srv_sweep_fill_image(sw, job_i);
		atomic_fetch_add(&srv_stats.sweep_points, 1);
		/* a deleted sweep's files are gone: none are written again */
		if (!sw->cancelled) {
			srv_sweep_curve_tol(sw);
			persist_locked(sw, 0);
			if (sw->done == sw->total)
				save_results(sw);
		}
		pthread_mutex_unlock(&sw->lock);
	}
	srv_budget_point_done(skip ? 0 : srv_now() - started);
	srv_registry_put(&sweeps, &sw->entry);
}

/* Queue one pool job for each point of a restored sweep that was pending
 * or running, each with a reference (the caller holds one). */
static void sweep_resume(srv_entry *en)
{
	srv_sweep *sw = sweep_of(en);
	pthread_mutex_lock(&sw->lock);
	size_t refs = 0;
	for (size_t k = 0; k < sw->total && !sw->cancelled; k++) {
		if (sw->pt[k].state != 0 || sw->pt[k].mirrored)
			continue;
		sweep_job *job = malloc(sizeof *job);
		if (!job)
			continue;
		job->sw = sw;
		job->i = k;
		srv_registry_hold(&sweeps, &sw->entry);
		srv_budget_take_points(1, NULL, 1, NULL);
		if (srv_pool_submit(run_point, job) != 0) {
			free(job);
			srv_budget_give_points(1);
			refs++;
		}
	}
	pthread_mutex_unlock(&sw->lock);
	for (size_t k = 0; k < refs; k++)
		srv_registry_put(&sweeps, &sw->entry);
}

/* A sweep from its record (taken), its points as they were: those that
 * were running are pending again; NULL with the reason. */
static srv_entry *sweep_load(void *payload, size_t len, char *why, size_t whylen)
{
	char *p = payload;
	sweep_record r;
	size_t nb = 0, np = 0;
	int ok = len >= sizeof r;
	if (ok) {
		memcpy(&r, p, sizeof r);
		nb = (size_t)r.req.nbeta * sizeof(api_value);
		np = r.total * sizeof(api_sweep_point);
		ok = r.req.nbeta >= 0 && r.req.nbeta <= API_SWEEP_MAX_POINTS &&
		     r.total <= API_SWEEP_MAX_POINTS && len == sizeof r + nb + np;
	}
	if (!ok)
		snprintf(why, whylen, "inconsistent");
	srv_sweep *sw = ok ? calloc(1, sizeof *sw) : NULL;
	if (sw) {
		pthread_mutex_init(&sw->lock, NULL);
		sw->req = r.req;
		sw->req.values = NULL;
		sw->req.betas = malloc(nb ? nb : 1);
		sw->pt = malloc(np ? np : 1);
		snprintf(sw->entry.id, sizeof sw->entry.id, "%.*s", SRV_ID_LEN - 1, r.id);
	}
	int planned = 0, consistent = 1;
	if (sw && sw->req.betas && sw->pt) {
		memcpy(sw->req.betas, p + sizeof r, nb);
		memcpy(sw->pt, p + sizeof r + nb, np);
		consistent = srv_sweep_record_check(&sw->req, sw->pt, r.total, why, whylen) == 0;
	}
	if (consistent && sw && sw->req.betas && sw->pt) {
		sw->total = r.total;
		sw->cancelled = r.cancelled;
		sw->done = 0;
		for (size_t k = 0; k < sw->total; k++) {
			if (sw->pt[k].state == 1) /* was running */
				sw->pt[k].state = 0;
			sw->done += sw->pt[k].state >= 2;
		}
		/* the plan again; an image whose point is over is filled (written
		 * together, but a stop may fall between the two writes) */
		planned = srv_sweep_plan(sw) == 0;
		for (size_t k = 0; planned && k < sw->total; k++)
			if (sw->pt[k].state >= 2)
				srv_sweep_fill_image(sw, k);
	}
	if (ok && !planned) {
		if (consistent)
			snprintf(why, whylen, "out of memory");
		sweep_free(sw);
		sw = NULL;
	}
	free(p);
	return sw ? &sw->entry : NULL;
}

static int evictable(srv_entry *en)
{
	srv_sweep *sw = sweep_of(en);
	pthread_mutex_lock(&sw->lock);
	int over = sw->done == sw->total || sw->cancelled;
	pthread_mutex_unlock(&sw->lock);
	return over;
}

/* A sweep for a request body with its grid of points and their place in
 * the points' budget; NULL with *pb. */
static srv_entry *sweep_create(const char *body, size_t len, api_problem *pb)
{
	srv_sweep *sw = calloc(1, sizeof *sw);
	if (!sw) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	pthread_mutex_init(&sw->lock, NULL);
	if (api_parse_sweep(body, len, &sw->req, pb) != API_OK ||
	    (sw->req.band_fit[0] && srv_sweep_prepare_band(&sw->req, pb) != API_OK)) {
		sweep_free(sw);
		return NULL;
	}
	sw->total = (size_t)sw->req.nbeta * (size_t)sw->req.nrot;
	sw->pt = calloc(sw->total, sizeof *sw->pt);
	if (!sw->pt) {
		sweep_free(sw);
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	for (int ro = 0; ro < sw->req.nrot; ro++)
		for (int b = 0; b < sw->req.nbeta; b++) {
			api_sweep_point *p =
				&sw->pt[(size_t)ro * (size_t)sw->req.nbeta +
					(size_t)b];
			p->beta = sw->req.betas[b];
			p->rotation = sw->req.rotations[ro];
			for (int a = 0; a < sw->req.nvary; a++)
				p->vary[a] = sw->req.values[(size_t)b * (size_t)sw->req.nvary +
							    (size_t)a];
		}
	/* the points hold the values from here on (and in the record) */
	free(sw->req.values);
	sw->req.values = NULL;
	api_err e = srv_sweep_plan(sw) != 0 ? api_fail(pb, API_UNAVAILABLE, NULL, "out of memory")
					     : srv_sweep_check_cost(sw, pb);
	if (e != API_OK || srv_budget_take_points(sw->jobs, "beta", 0, pb) != API_OK) {
		sweep_free(sw);
		return NULL;
	}
	return &sw->entry;
}

/* A created sweep that was not kept: its points' budget goes back. */
static void sweep_discard(srv_entry *en)
{
	srv_sweep *sw = sweep_of(en);
	srv_budget_give_points(sw->jobs);
	sweep_free(sw);
}

/* Queue one pool job per point that runs (not a mirror image), each with
 * a reference; a point that cannot be queued is marked failed, and its
 * image with it. Returns the references not handed out. */
static size_t submit_points(srv_sweep *sw)
{
	size_t unused = 0;
	for (size_t i = 0; i < sw->total; i++) {
		if (sw->pt[i].mirrored)
			continue;
		sweep_job *job = malloc(sizeof *job);
		if (job) {
			job->sw = sw;
			job->i = i;
		}
		if (!job || srv_pool_submit(run_point, job) != 0) {
			free(job);
			sw->pt[i].state = 3;
			snprintf(sw->pt[i].error, sizeof sw->pt[i].error,
				 "not queued (out of memory or stopping)");
			sw->done++;
			srv_sweep_fill_image(sw, i);
			unused++;
		}
	}
	return unused;
}

/* Queue the points of a published sweep; the answer shows it queued. */
static api_err sweep_start(srv_entry *en, int client_fd, char **answer, api_problem *pb)
{
	(void)pb;
	(void)client_fd; /* queued: nothing runs in the request */
	srv_sweep *sw = sweep_of(en);
	for (size_t i = 0; i < sw->jobs; i++)
		srv_registry_hold(&sweeps, &sw->entry); /* one per job */
	/* jobs wait for the lock: the answer shows the sweep as queued */
	pthread_mutex_lock(&sw->lock);
	persist_locked(sw, 1);
	size_t unused = submit_points(sw);
	api_sweep_view v;
	fill_view(sw, &v);
	*answer = api_sweep_json(&v);
	pthread_mutex_unlock(&sw->lock);
	for (size_t i = 0; i < unused; i++)
		srv_registry_put(&sweeps, &sw->entry);
	srv_budget_give_points(unused);
	return API_OK;
}

static pthread_mutex_t *sweep_lock(srv_entry *en)
{
	return &sweep_of(en)->lock;
}

static char *sweep_text(srv_entry *en, int csv)
{
	srv_sweep *sw = sweep_of(en);
	api_sweep_view v;
	fill_view(sw, &v);
	/* a damaged sweep's stored result, as it was written */
	if (csv && sw->csv)
		return strndup(sw->csv, sw->csv_len);
	return csv ? api_sweep_csv(&v) : api_sweep_json(&v);
}

static void sweep_view(srv_entry *en, void *view, void *scratch)
{
	(void)scratch;
	fill_view(sweep_of(en), view);
}

static char *sweep_list_text(const void *views, size_t n, int csv)
{
	return csv ? api_sweep_list_csv(views, n) : api_sweep_list_json(views, n);
}

/* A sweep whose record is unusable: listed as "damaged" with why, as a
 * session is, and its CSV result, when one was stored, still served as it
 * is. NULL when out of memory. */
static srv_entry *sweep_damaged(const char *id, const char *why)
{
	srv_sweep *sw = calloc(1, sizeof *sw);
	if (!sw)
		return NULL;
	pthread_mutex_init(&sw->lock, NULL);
	snprintf(sw->entry.id, sizeof sw->entry.id, "%.23s", id);
	snprintf(sw->damaged, sizeof sw->damaged, "damaged: %.200s", why);
	char name[64];
	snprintf(name, sizeof name, "sweep-%s.csv", sw->entry.id);
	sw->csv = srv_store_read_text(name, &sw->csv_len);
	return &sw->entry;
}

/* DELETE: the points not yet run are skipped. */
static int sweep_cancel(srv_entry *en, int only_running)
{
	srv_sweep *sw = sweep_of(en);
	if (only_running && (sw->done == sw->total || sw->cancelled))
		return 0;
	if (sw->done < sw->total)
		sw->cancelled = 1;
	return 1;
}

const srv_job_kind srv_sweep_job = {
	.name = "sweep",
	.plural = "sweeps",
	.reg = &sweeps,
	.created_status = 202,
	.limit = "running or kept; delete one",
	.store_kind = SRV_STORE_SWEEP,
	.result_file = "sweep-%s.csv",
	.create = sweep_create,
	.discard = sweep_discard,
	.start = sweep_start,
	.evictable = evictable,
	.lock = sweep_lock,
	.text = sweep_text,
	.view_size = sizeof(api_sweep_view),
	.view = sweep_view,
	.list_text = sweep_list_text,
	.cancel = sweep_cancel,
	.damaged = sweep_damaged,
	.load = sweep_load,
	.resume = sweep_resume,
};
