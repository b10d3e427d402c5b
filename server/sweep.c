/*
 * sweep.c - v(beta) sweeps on the worker pool (POST /api/v1/sweeps).
 *
 * A sweep is a grid of (beta, rotation) points; each point is one pool
 * job that builds a fresh instance with sim_measure_velocity (thread-safe,
 * no session involved) and stores the steady transport velocity. A sweep
 * is reference-counted: the registry holds one reference and every queued
 * job one, so DELETE (cancel) can unlink it while jobs drain. Results are
 * served as JSON or CSV and, with --data-dir, saved as CSV when done.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "srv.h"
#include "units.h"

typedef struct srv_sweep {
	char id[24];
	api_sweep_req req;
	api_sweep_point *pt;
	size_t total, done;
	int running, cancelled, refs;
	struct srv_sweep *next;
} srv_sweep;

typedef struct sweep_job {
	srv_sweep *sw;
	size_t i;
} sweep_job;

static pthread_mutex_t sweep_lock = PTHREAD_MUTEX_INITIALIZER;
static srv_sweep *sweep_head;
static int sweep_count;

void srv_sweeps_init(void)
{
	sweep_head = NULL;
	sweep_count = 0;
}

static void sweep_free(srv_sweep *sw)
{
	if (!sw)
		return;
	free(sw->req.betas);
	free(sw->pt);
	free(sw);
}

/* Drop a reference (sweep_lock held); frees on the last. */
static void sweep_put_locked(srv_sweep *sw)
{
	if (--sw->refs == 0)
		sweep_free(sw);
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
	snprintf(v->id, sizeof v->id, "%s", sw->id);
	v->state = sweep_state(sw);
	v->total = sw->total;
	v->done = sw->done;
	v->t_end = sw->req.t_end;
	v->pt = sw->pt;
}

static void save_results(const srv_sweep *sw)
{
	if (!srv_cfg.data_dir)
		return;
	api_sweep_view v;
	fill_view(sw, &v);
	char *text = api_sweep_csv(&v);
	char path[4096];
	snprintf(path, sizeof path, "%s/sweep-%s.csv", srv_cfg.data_dir,
		 sw->id);
	FILE *f = text ? fopen(path, "w") : NULL;
	if (f) {
		fputs(text, f);
		fclose(f);
	} else {
		srv_log(SRV_LOG_WARN, "cannot write %s", path);
	}
	free(text);
}

static void run_point(void *arg)
{
	sweep_job *job = arg;
	srv_sweep *sw = job->sw;
	api_sweep_point *p = &sw->pt[job->i];
	free(job);
	pthread_mutex_lock(&sweep_lock);
	int skip = sw->cancelled || atomic_load(&srv_stopping);
	if (!skip) {
		p->state = 1;
		sw->running++;
	}
	pthread_mutex_unlock(&sweep_lock);
	if (!skip) {
		api_spec spec = sw->req.spec;
		char msg[160] = "";
		double v = 0;
		int rc = sim_set_user(&spec.params, &spec.scene, &spec.method,
				 "beta", p->beta, msg, sizeof msg);
		spec.params.rotation = p->rotation;
		if (rc == SIM_OK)
			rc = sim_measure_velocity(&spec.params, &spec.scene,
						  &spec.method, sw->req.t_end,
						  &v, msg, sizeof msg);
		pthread_mutex_lock(&sweep_lock);
		sw->running--;
		if (rc == SIM_OK) {
			p->state = 2;
			p->velocity = v;
		} else {
			p->state = 3;
			snprintf(p->error, sizeof p->error, "%s",
				 msg[0] ? msg : sim_strerror(rc));
		}
		sw->done++;
		atomic_fetch_add(&srv_stats.sweep_points, 1);
		if (sw->done == sw->total)
			save_results(sw);
		pthread_mutex_unlock(&sweep_lock);
	}
	pthread_mutex_lock(&sweep_lock);
	sweep_put_locked(sw);
	pthread_mutex_unlock(&sweep_lock);
}

void srv_sweeps_shutdown(void)
{
	/* the pool has drained: only the registry's references remain */
	pthread_mutex_lock(&sweep_lock);
	while (sweep_head) {
		srv_sweep *sw = sweep_head;
		sweep_head = sw->next;
		sweep_put_locked(sw);
	}
	sweep_count = 0;
	pthread_mutex_unlock(&sweep_lock);
}

/* Room for one more (sweep_lock held): unlink the oldest finished one. */
static int make_room(void)
{
	if (sweep_count < srv_cfg.max_sweeps)
		return 1;
	srv_sweep **pp = &sweep_head, **victim = NULL;
	for (; *pp; pp = &(*pp)->next)
		if ((*pp)->done == (*pp)->total || (*pp)->cancelled)
			victim = pp;
	if (!victim)
		return 0;
	srv_sweep *v = *victim;
	*victim = v->next;
	sweep_count--;
	sweep_put_locked(v);
	return 1;
}

enum MHD_Result srv_h_sweeps_create(srv_req *r)
{
	enum MHD_Result res;
	api_problem pb;
	if (!srv_need_json(r, 1, &res))
		return res;
	srv_sweep *sw = calloc(1, sizeof *sw);
	if (!sw)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	if (api_parse_sweep(r->body, r->body_len, &sw->req, &pb) != API_OK) {
		sweep_free(sw);
		return srv_reply_problem(r, &pb, NULL);
	}
	sw->total = (size_t)sw->req.nbeta * (size_t)sw->req.nrot;
	sw->pt = calloc(sw->total, sizeof *sw->pt);
	if (!sw->pt) {
		sweep_free(sw);
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	}
	for (int ro = 0; ro < sw->req.nrot; ro++)
		for (int b = 0; b < sw->req.nbeta; b++) {
			api_sweep_point *p =
				&sw->pt[(size_t)ro * (size_t)sw->req.nbeta +
					(size_t)b];
			p->beta = sw->req.betas[b];
			p->rotation = sw->req.rotations[ro];
		}
	srv_new_id(sw->id);
	pthread_mutex_lock(&sweep_lock);
	if (!make_room()) {
		pthread_mutex_unlock(&sweep_lock);
		sweep_free(sw);
		return srv_fail(r, API_LIMIT, NULL,
				"%d sweeps are running or kept; delete one",
				srv_cfg.max_sweeps);
	}
	sw->refs = 1;
	sw->next = sweep_head;
	sweep_head = sw;
	sweep_count++;
	for (size_t i = 0; i < sw->total; i++) {
		sweep_job *job = malloc(sizeof *job);
		if (job) {
			job->sw = sw;
			job->i = i;
			sw->refs++;
		}
		if (!job || srv_pool_submit(run_point, job) != 0) {
			if (job)
				sw->refs--;
			free(job);
			sw->pt[i].state = 3;
			snprintf(sw->pt[i].error, sizeof sw->pt[i].error,
				 "not queued (out of memory or stopping)");
			sw->done++;
		}
	}
	api_sweep_view v;
	fill_view(sw, &v);
	char *text = api_sweep_json(&v);
	pthread_mutex_unlock(&sweep_lock);
	char location[96];
	snprintf(location, sizeof location, "/api/v1/sweeps/%s", v.id);
	return srv_reply(r, 202, "application/json", text,
			 MHD_HTTP_HEADER_LOCATION, location);
}

enum MHD_Result srv_h_sweep_get(srv_req *r)
{
	api_problem pb;
	int csv = srv_table_format(r, &pb);
	if (csv < 0)
		return srv_reply_problem(r, &pb, NULL);
	char *text = NULL;
	int found = 0;
	pthread_mutex_lock(&sweep_lock);
	for (srv_sweep *sw = sweep_head; sw; sw = sw->next)
		if (strcmp(sw->id, r->arg[0]) == 0) {
			api_sweep_view v;
			fill_view(sw, &v);
			text = csv ? api_sweep_csv(&v) : api_sweep_json(&v);
			found = 1;
			break;
		}
	pthread_mutex_unlock(&sweep_lock);
	if (!found)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no sweep with id \"%.40s\"", r->arg[0]);
	return srv_reply(r, 200, csv ? "text/csv" : "application/json", text,
			 NULL, NULL);
}

enum MHD_Result srv_h_sweeps_list(srv_req *r)
{
	pthread_mutex_lock(&sweep_lock);
	api_sweep_view *v = calloc((size_t)sweep_count + 1, sizeof *v);
	size_t n = 0;
	for (srv_sweep *sw = sweep_head; v && sw; sw = sw->next)
		fill_view(sw, &v[n++]);
	char *text = v ? api_sweep_list_json(v, n) : NULL;
	pthread_mutex_unlock(&sweep_lock);
	free(v);
	return srv_reply_json(r, 200, text);
}

enum MHD_Result srv_h_sweep_delete(srv_req *r)
{
	pthread_mutex_lock(&sweep_lock);
	srv_sweep **pp = &sweep_head;
	while (*pp && strcmp((*pp)->id, r->arg[0]) != 0)
		pp = &(*pp)->next;
	srv_sweep *sw = *pp;
	if (sw) {
		*pp = sw->next;
		sweep_count--;
		if (sw->done < sw->total)
			sw->cancelled = 1;
		sweep_put_locked(sw);
	}
	pthread_mutex_unlock(&sweep_lock);
	if (!sw)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no sweep with id \"%.40s\"", r->arg[0]);
	struct MHD_Response *resp =
		MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT);
	return srv_queue(r, 204, resp);
}
