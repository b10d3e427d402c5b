/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep.c - v(beta) sweeps on the worker pool (POST /api/v1/sweeps).
 *
 * A sweep is a grid of (beta, rotation) points; each point is one pool
 * job that builds a fresh instance with sim_measure (thread-safe,
 * no session involved) and stores the steady transport velocity. Under
 * the mirror reduction (sim_mirror_plan) a point that is the mirror image
 * of another is no job of its own: it is filled when the other is done. Sweeps
 * live in a registry (registry.c) that holds one reference, and every
 * queued job holds one, so DELETE (cancel) can unlink a sweep while its
 * jobs drain; beyond --max-sweeps the oldest finished one is evicted. A
 * sweep's fields are guarded by its own lock. Results are served as JSON
 * or CSV and, with --data-dir, saved as CSV when done.
 */
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "metrics.h"
#include "peers.h"
#include "pool.h"
#include "registry.h"
#include "store.h"
#include "sweep.h"
#include "util.h"

typedef struct srv_sweep {
	srv_entry entry;       /* id and references: the registry */
	pthread_mutex_t lock;
	/* guarded by lock */
	api_sweep_req req;
	api_sweep_point *pt;
	long *image;           /* the point derived from point i, or -1 */
	size_t total, done;
	size_t jobs;           /* points that run (the others are images) */
	int running, cancelled;
	char store_error[256];  /* a write failed: state "error" */
	char damaged[256];      /* its record is unusable: why (state
				   "damaged", no points) */
	char *csv;              /* damaged: the result file as stored, or NULL */
	size_t csv_len;
} srv_sweep;

typedef struct sweep_job {
	srv_sweep *sw;
	size_t i;
} sweep_job;

static void destroy(srv_entry *en);
static srv_registry sweeps = SRV_REGISTRY_INIT(destroy);
static const srv_config *cfg;

void srv_sweeps_init(const srv_config *config)
{
	cfg = config;
	srv_registry_open(&sweeps, (size_t)cfg->max_sweeps);
}

static srv_sweep *sweep_of(srv_entry *en)
{
	return SRV_CONTAINER(en, srv_sweep, entry);
}

static void sweep_free(srv_sweep *sw)
{
	if (!sw)
		return;
	free(sw->req.betas);
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
	v->pt = sw->pt;
}

/* ---- persistence (store.h) ---------------------------------------------
 *
 * sweeps/ID.bin: the record below, the betas and every point, written at
 * creation, after each point and at a cancel (a pending write is replaced
 * by the newer one); at the end, sweep-ID.csv. A restart serves finished
 * sweeps again and queues the points that were pending or running. */
typedef struct sweep_record {
	char id[SRV_ID_LEN];
	api_sweep_req req;     /* betas: NULL here, they follow */
	uint64_t total, done;
	int32_t cancelled, pad;
} sweep_record;

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

/* Queue sweeps/ID.bin (lock held). */
static void persist_locked(const srv_sweep *sw)
{
	if (!srv_store_enabled())
		return;
	sweep_record r;
	memset(&r, 0, sizeof r);
	snprintf(r.id, sizeof r.id, "%s", sw->entry.id);
	r.req = sw->req;
	r.req.betas = NULL;
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
	size_t len;
	void *buf = srv_store_frame(SRV_STORE_SWEEP, p, sizeof r + nb + np, &len);
	free(p);
	char path[64];
	snprintf(path, sizeof path, "sweeps/%s.bin", sw->entry.id);
	if (buf)
		srv_store_write(path, buf, len, 0, written, strdup(sw->entry.id));
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

/* The mirror reduction's plan of the sweep's points: which are mirror
 * images of which (sw->image, sw->jobs, each point's `mirrored`). The
 * plan depends only on the request, so a restart makes it again. 0, or
 * -1 when out of memory. */
static int plan(srv_sweep *sw)
{
	size_t n = sw->total;
	double *beta = malloc(sizeof *beta * (n ? n : 1));
	int *rot = malloc(sizeof *rot * (n ? n : 1));
	long *source = malloc(sizeof *source * (n ? n : 1));
	sw->image = malloc(sizeof *sw->image * (n ? n : 1));
	int rc = beta && rot && source && sw->image ? 0 : -1;
	for (size_t i = 0; rc == 0 && i < n; i++) {
		beta[i] = sw->pt[i].beta.si;
		rot[i] = sw->pt[i].rotation;
		sw->image[i] = -1;
	}
	if (rc == 0) {
		sw->jobs = sim_mirror_plan(&sw->req.spec.params, &sw->req.spec.scene, n, beta,
					   rot, source);
		for (size_t i = 0; i < n; i++) {
			sw->pt[i].mirrored = source[i] >= 0;
			if (source[i] >= 0)
				sw->image[source[i]] = (long)i;
		}
	}
	free(beta);
	free(rot);
	free(source);
	return rc;
}

/* Point i is over (done or failed): its mirror image, if it has one, is
 * too (lock held). */
static void fill_image(srv_sweep *sw, size_t i)
{
	long j = sw->image[i];
	if (j < 0 || sw->pt[j].state >= 2)
		return;
	const api_sweep_point *src = &sw->pt[i];
	api_sweep_point *p = &sw->pt[j];
	p->state = src->state;
	p->velocity = -src->velocity;
	p->uncertainty = src->uncertainty;
	p->steady = src->steady;
	p->dt = src->dt;
	p->substeps = src->substeps;
	p->step_error = src->step_error;
	p->tol_met = src->tol_met;
	if (src->state == 3)
		sim_mirror_failure(p->error, sizeof p->error, src->beta.user, src->rotation,
				   src->error);
	sw->done++;
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
		/* beta was checked and converted to SI by api/ */
		spec.params.beta = p->beta.si;
		spec.params.rotation = p->rotation;
		int rc = sim_measure(&spec.params, &spec.scene, &spec.method,
				     sw->req.t_end, &r, msg, sizeof msg);
		pthread_mutex_lock(&sw->lock);
		sw->running--;
		if (rc == SIM_OK) {
			p->state = 2;
			p->velocity = r.transport_velocity;
			p->uncertainty = r.uncertainty;
			p->steady = r.steady;
			p->dt = r.dt;
			p->substeps = r.substeps;
			p->step_error = r.step_error;
			p->tol_met = r.tol_met;
		} else {
			p->state = 3;
			snprintf(p->error, sizeof p->error, "%s",
				 msg[0] ? msg : sim_strerror(rc));
		}
		sw->done++;
		fill_image(sw, job_i);
		atomic_fetch_add(&srv_stats.sweep_points, 1);
		persist_locked(sw);
		if (sw->done == sw->total)
			save_results(sw);
		pthread_mutex_unlock(&sw->lock);
	}
	srv_budget_point_done(skip ? 0 : srv_now() - started);
	srv_registry_put(&sweeps, &sw->entry);
}

/* A sweep whose record is unusable is listed as "damaged" with why, as
 * a session is, and its CSV result, when one was stored, is still served
 * as it is. 0, or -1 when the registry has no room or memory ran out. */
static int restore_damaged(const char *id, const char *why)
{
	srv_sweep *sw = calloc(1, sizeof *sw);
	if (!sw)
		return -1;
	pthread_mutex_init(&sw->lock, NULL);
	snprintf(sw->entry.id, sizeof sw->entry.id, "%.23s", id);
	snprintf(sw->damaged, sizeof sw->damaged, "damaged: %.200s", why);
	char name[64];
	snprintf(name, sizeof name, "sweep-%s.csv", sw->entry.id);
	sw->csv = srv_store_read_text(name, &sw->csv_len);
	if (srv_registry_reserve(&sweeps, &sw->entry, NULL)) {
		sweep_free(sw);
		return -1;
	}
	srv_registry_publish(&sweeps, &sw->entry);
	srv_registry_put(&sweeps, &sw->entry);
	return 0;
}

size_t srv_sweeps_restore(void)
{
	char **names = NULL;
	size_t n = srv_store_enabled() ? srv_store_list_ids("sweeps", 0, &names) : 0,
	       count = 0;
	for (size_t i = 0; i < n; i++) {
		char path[300], why[300];
		snprintf(path, sizeof path, "sweeps/%s", names[i]);
		free(names[i]);
		size_t l = strlen(path), len = 0;
		char *p = l > 4 && strcmp(path + l - 4, ".bin") == 0
				  ? srv_store_read(path, SRV_STORE_SWEEP, &len,
						   why, sizeof why)
				  : NULL;
		sweep_record r;
		size_t nb = 0, np = 0;
		int ok = p && len >= sizeof r;
		if (ok) {
			memcpy(&r, p, sizeof r);
			nb = (size_t)r.req.nbeta * sizeof(api_value);
			np = r.total * sizeof(api_sweep_point);
			ok = r.req.nbeta >= 0 && r.req.nbeta <= API_SWEEP_MAX_POINTS &&
			     r.total <= API_SWEEP_MAX_POINTS &&
			     len == sizeof r + nb + np;
		}
		srv_sweep *sw = ok ? calloc(1, sizeof *sw) : NULL;
		if (sw) {
			pthread_mutex_init(&sw->lock, NULL);
			sw->req = r.req;
			sw->req.betas = malloc(nb ? nb : 1);
			sw->pt = malloc(np ? np : 1);
			r.id[SRV_ID_LEN - 1] = '\0';
			snprintf(sw->entry.id, sizeof sw->entry.id, "%s", r.id);
		}
		if (sw && sw->req.betas && sw->pt) {
			memcpy(sw->req.betas, p + sizeof r, nb);
			memcpy(sw->pt, p + sizeof r + nb, np);
			sw->total = r.total;
			sw->cancelled = r.cancelled;
			sw->done = 0;
			for (size_t k = 0; k < sw->total; k++) {
				if (sw->pt[k].state == 1) /* was running */
					sw->pt[k].state = 0;
				sw->done += sw->pt[k].state >= 2;
			}
			/* the plan again; an image whose point is over is
			 * filled (written together, but a stop may fall
			 * between the two writes) */
			int planned = plan(sw) == 0;
			for (size_t k = 0; planned && k < sw->total; k++)
				if (sw->pt[k].state >= 2)
					fill_image(sw, k);
			if (planned && srv_registry_reserve(&sweeps, &sw->entry, NULL) == 0) {
				srv_registry_publish(&sweeps, &sw->entry);
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
				srv_registry_put(&sweeps, &sw->entry);
				count++;
				sw = NULL;
			}
		} else if (!ok && p) {
			snprintf(why, sizeof why, "%.200s: inconsistent", path);
		}
		if (!ok && l > 4 && strcmp(path + l - 4, ".bin") == 0) {
			srv_log(SRV_LOG_WARN, "sweep not restored: %s", why);
			path[l - 4] = '\0';
			count += restore_damaged(path + strlen("sweeps/"), why) == 0;
		}
		sweep_free(sw);
		free(p);
	}
	free(names);
	return count;
}

void srv_sweeps_shutdown(void)
{
	/* the pool has drained: only the registry's references remain */
	srv_registry_clear(&sweeps);
}

static int evictable(srv_entry *en)
{
	srv_sweep *sw = sweep_of(en);
	pthread_mutex_lock(&sw->lock);
	int over = sw->done == sw->total || sw->cancelled;
	pthread_mutex_unlock(&sw->lock);
	return over;
}

/* A sweep for the body of r with its grid of points; NULL with *pb. */
static srv_sweep *sweep_new(srv_req *r, api_problem *pb)
{
	srv_sweep *sw = calloc(1, sizeof *sw);
	if (!sw) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	pthread_mutex_init(&sw->lock, NULL);
	if (api_parse_sweep(r->body, r->body_len, &sw->req, pb) != API_OK) {
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
		}
	if (plan(sw) != 0) {
		sweep_free(sw);
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	return sw;
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
			fill_image(sw, i);
			unused++;
		}
	}
	return unused;
}

enum MHD_Result srv_h_sweeps_create(srv_req *r)
{
	enum MHD_Result res;
	api_problem pb;
	srv_sweep *sw = sweep_new(r, &pb);
	if (!sw)
		return srv_reply_problem(r, &pb, NULL);
	if (srv_budget_take_points(sw->jobs, "beta", 0, &pb) != API_OK) {
		sweep_free(sw);
		return srv_reply_problem(r, &pb, NULL);
	}
	if (srv_registry_reserve(&sweeps, &sw->entry, evictable)) {
		srv_budget_give_points(sw->jobs);
		sweep_free(sw);
		return srv_fail(r, API_LIMIT, NULL,
				"%d sweeps are running or kept; delete one",
				cfg->max_sweeps);
	}
	srv_registry_publish(&sweeps, &sw->entry);
	for (size_t i = 0; i < sw->jobs; i++)
		srv_registry_hold(&sweeps, &sw->entry); /* one per job */
	/* jobs wait for the lock: the answer shows the sweep as queued */
	pthread_mutex_lock(&sw->lock);
	persist_locked(sw);
	size_t unused = submit_points(sw);
	api_sweep_view v;
	fill_view(sw, &v);
	char *text = api_sweep_json(&v);
	pthread_mutex_unlock(&sw->lock);
	for (size_t i = 0; i < unused; i++)
		srv_registry_put(&sweeps, &sw->entry);
	srv_budget_give_points(unused);
	res = srv_reply_created(r, 202, text, "/api/v1/sweeps", v.id);
	srv_registry_put(&sweeps, &sw->entry);
	return res;
}

enum MHD_Result srv_h_sweep_get(srv_req *r)
{
	srv_entry *en = srv_registry_get(&sweeps, r->arg[0]);
	if (!en)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no sweep with id \"%.40s\"", r->arg[0]);
	srv_sweep *sw = sweep_of(en);
	api_sweep_view v;
	pthread_mutex_lock(&sw->lock);
	fill_view(sw, &v);
	char *text = r->csv && sw->csv ? strndup(sw->csv, sw->csv_len)
		     : r->csv	       ? api_sweep_csv(&v)
				       : api_sweep_json(&v);
	pthread_mutex_unlock(&sw->lock);
	srv_registry_put(&sweeps, en);
	return srv_reply_result(r, text);
}

enum MHD_Result srv_h_sweeps_list(srv_req *r)
{
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(&sweeps, &all);
	api_sweep_view *v = calloc(n + 1, sizeof *v);
	char *text = NULL;
	if (v) {
		for (size_t i = 0; i < n; i++) {
			srv_sweep *sw = sweep_of(all[i]);
			pthread_mutex_lock(&sw->lock);
			fill_view(sw, &v[i]);
			pthread_mutex_unlock(&sw->lock);
		}
		text = r->csv ? api_sweep_list_csv(v, n) : api_sweep_list_json(v, n);
	}
	srv_registry_release(&sweeps, all, n);
	free(v);
	return srv_peers_reply(r, text, "sweeps");
}

enum MHD_Result srv_h_sweep_delete(srv_req *r)
{
	srv_entry *en = srv_registry_get(&sweeps, r->arg[0]);
	if (!en)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no sweep with id \"%.40s\"", r->arg[0]);
	srv_sweep *sw = sweep_of(en);
	char rec[64];
	api_problem pb;
	snprintf(rec, sizeof rec, "sweeps/%s.bin", sw->entry.id);
	if (srv_store_check_removable(rec, &pb) != API_OK) {
		srv_registry_put(&sweeps, en);
		return srv_reply_problem(r, &pb, NULL);
	}
	pthread_mutex_lock(&sw->lock);
	if (sw->done < sw->total)
		sw->cancelled = 1;
	pthread_mutex_unlock(&sw->lock);
	if (srv_registry_remove(&sweeps, en) && srv_store_enabled()) {
		/* the record and the result go with it */
		char path[64];
		snprintf(path, sizeof path, "sweeps/%s.bin", sw->entry.id);
		srv_store_remove(path);
		snprintf(path, sizeof path, "sweep-%s.csv", sw->entry.id);
		srv_store_remove(path);
	}
	srv_registry_put(&sweeps, en);
	return srv_reply_empty(r);
}
