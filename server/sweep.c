/*
 * sweep.c - v(beta) sweeps on the worker pool (POST /api/v1/sweeps).
 *
 * A sweep is a grid of (beta, rotation) points; each point is one pool
 * job that builds a fresh instance with sim_measure (thread-safe,
 * no session involved) and stores the steady transport velocity. Sweeps
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

#include "metrics.h"
#include "pool.h"
#include "registry.h"
#include "sweep.h"
#include "util.h"

typedef struct srv_sweep {
	srv_entry entry;       /* id and references: the registry */
	pthread_mutex_t lock;
	/* guarded by lock */
	api_sweep_req req;
	api_sweep_point *pt;
	size_t total, done;
	int running, cancelled;
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
	pthread_mutex_destroy(&sw->lock);
	free(sw);
}

static void destroy(srv_entry *en)
{
	sweep_free(sweep_of(en));
}

static const char *sweep_state(const srv_sweep *sw)
{
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
	v->total = sw->total;
	v->done = sw->done;
	v->t_end = sw->req.t_end;
	v->pt = sw->pt;
}

static void save_results(const srv_sweep *sw)
{
	if (!cfg->data_dir)
		return;
	api_sweep_view v;
	fill_view(sw, &v);
	char *text = api_sweep_csv(&v);
	char name[64];
	snprintf(name, sizeof name, "sweep-%s.csv", sw->entry.id);
	srv_write_file(cfg->data_dir, name, text, 0);
	free(text);
}

static void run_point(void *arg)
{
	sweep_job *job = arg;
	srv_sweep *sw = job->sw;
	api_sweep_point *p = &sw->pt[job->i];
	free(job);
	pthread_mutex_lock(&sw->lock);
	int skip = sw->cancelled || srv_stopping();
	if (!skip) {
		p->state = 1;
		sw->running++;
	}
	pthread_mutex_unlock(&sw->lock);
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
		} else {
			p->state = 3;
			snprintf(p->error, sizeof p->error, "%s",
				 msg[0] ? msg : sim_strerror(rc));
		}
		sw->done++;
		atomic_fetch_add(&srv_stats.sweep_points, 1);
		if (sw->done == sw->total)
			save_results(sw);
		pthread_mutex_unlock(&sw->lock);
	}
	srv_registry_put(&sweeps, &sw->entry);
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
	return sw;
}

/* Queue one pool job per point, each with a reference; a point that cannot
 * be queued is marked failed. Returns the references not handed out. */
static size_t submit_points(srv_sweep *sw)
{
	size_t unused = 0;
	for (size_t i = 0; i < sw->total; i++) {
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
			unused++;
		}
	}
	return unused;
}

enum MHD_Result srv_h_sweeps_create(srv_req *r)
{
	enum MHD_Result res;
	api_problem pb;
	if (!srv_need_json(r, 1, &res))
		return res;
	srv_sweep *sw = sweep_new(r, &pb);
	if (!sw)
		return srv_reply_problem(r, &pb, NULL);
	if (srv_registry_reserve(&sweeps, &sw->entry, evictable)) {
		sweep_free(sw);
		return srv_fail(r, API_LIMIT, NULL,
				"%d sweeps are running or kept; delete one",
				cfg->max_sweeps);
	}
	srv_registry_publish(&sweeps, &sw->entry);
	for (size_t i = 0; i < sw->total; i++)
		srv_registry_hold(&sweeps, &sw->entry); /* one per job */
	/* jobs wait for the lock: the answer shows the sweep as queued */
	pthread_mutex_lock(&sw->lock);
	size_t unused = submit_points(sw);
	api_sweep_view v;
	fill_view(sw, &v);
	char *text = api_sweep_json(&v);
	pthread_mutex_unlock(&sw->lock);
	for (size_t i = 0; i < unused; i++)
		srv_registry_put(&sweeps, &sw->entry);
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
	char *text = r->csv ? api_sweep_csv(&v) : api_sweep_json(&v);
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
	return srv_reply_result(r, text);
}

enum MHD_Result srv_h_sweep_delete(srv_req *r)
{
	srv_entry *en = srv_registry_get(&sweeps, r->arg[0]);
	if (!en)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no sweep with id \"%.40s\"", r->arg[0]);
	srv_sweep *sw = sweep_of(en);
	pthread_mutex_lock(&sw->lock);
	if (sw->done < sw->total)
		sw->cancelled = 1;
	pthread_mutex_unlock(&sw->lock);
	srv_registry_remove(&sweeps, en);
	srv_registry_put(&sweeps, en);
	return srv_reply_empty(r);
}
