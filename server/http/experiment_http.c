/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_http.c - the experiments as a kind of job: their registry and
 * the descriptor the handlers of /api/v1/experiments[/{id}] use (job.c).
 *
 * Experiments are kept in a registry until shutdown; beyond
 * --max-experiments (256) the oldest finished one is evicted once the new
 * one has started (job.c: a refused start keeps it). Creating one either creates a fresh session with the
 * experiment attached before its first step, or attaches it to a running
 * session; the session's worker then runs it (experiment.c).
 */
#include <stdlib.h>

#include "experiment.h"
#include "experiment_http.h"
#include "job.h"
#include "metrics.h"
#include "session.h"
#include "store.h"
#include "util.h"

static void destroy(srv_entry *en)
{
	srv_exp_free(srv_exp_from_entry(en));
}

static srv_registry experiments = SRV_REGISTRY_INIT(destroy);
static const srv_config *cfg;

void srv_experiments_init(const srv_config *config)
{
	cfg = config;
	srv_job_open(&srv_experiment_job, (size_t)cfg->max_experiments);
}

static int evictable(srv_entry *en)
{
	return srv_exp_finished(srv_exp_from_entry(en));
}

srv_experiment *srv_experiment_get(const char *id)
{
	srv_entry *en = srv_registry_get(&experiments, id);
	return en ? srv_exp_from_entry(en) : NULL;
}

void srv_experiment_put(srv_experiment *e)
{
	if (e)
		srv_registry_put(&experiments, srv_exp_entry(e));
}

size_t srv_experiments_interrupt_orphans(void)
{
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(&experiments, &all), count = 0;
	for (size_t i = 0; i < n; i++)
		count += (size_t)srv_exp_interrupt(srv_exp_from_entry(all[i]));
	srv_registry_release(&experiments, all, n);
	return count;
}

srv_experiment *srv_experiments_readopt(const char *session_id)
{
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(&experiments, &all);
	srv_experiment *hit = NULL;
	for (size_t i = 0; i < n && !hit; i++)
		if (srv_exp_readopt(srv_exp_from_entry(all[i]), session_id))
			hit = srv_exp_from_entry(all[i]);
	srv_registry_release(&experiments, all, n);
	return hit;
}

/* Run e on a fresh session or attach it to the one it names; the session
 * notes its id in e before its worker can run it. A fresh one settles
 * within what e's measurements left of --max-cpu-seconds, and is not kept
 * when the client on client_fd left meanwhile (session.h). A client that
 * left while e measured (an identification's slopes, a closed loop's
 * curve) gets neither: e is withdrawn before a fresh session is built or
 * an existing one attached. */
static api_err start_on_session(srv_experiment *e, const api_experiment_req *req,
				int client_fd, api_problem *pb)
{
	srv_session *s;
	if (srv_client_left(client_fd, 0, &srv_stats.experiments_abandoned, "experiment",
			    srv_exp_id(e), "started", "measured", pb))
		return pb->code;
	if (req->fresh) {
		s = srv_session_create(&req->spec, e, client_fd, srv_exp_measured_cpu(e), pb);
		if (!s) { /* its admission names the spec's fields as the client sent them */
			api_field_within(pb, "session");
			return pb->code;
		}
	} else {
		s = srv_session_get(req->session_id);
		if (!s)
			return api_fail(pb, API_NOTFOUND, "session",
					"no session with id \"%.40s\"",
					req->session_id);
		if (srv_session_replaying(s, pb) != API_OK ||
		    srv_session_attach(s, e, pb) != API_OK) {
			srv_session_put(s);
			return pb->code;
		}
		/* the session's scene, for each segment's model error */
		srv_exp_set_spec(e, srv_session_spec(s));
	}
	srv_session_put(s); /* it noted its id in e before its worker ran */
	return API_OK;
}

/* The experiment as JSON, from a consistent copy of its state. */
static char *experiment_json(srv_experiment *e, int csv)
{
	api_experiment_view v;
	srv_exp_scratch *sc = malloc(sizeof *sc);
	if (!sc)
		return NULL;
	srv_exp_view(e, &v, sc);
	char *text = csv ? api_experiment_csv(&v, 1) : api_experiment_json(&v);
	free(sc);
	return text;
}

/* s's spec with its rotation and omega_ss as they are now (a PATCH may
 * have changed them since its creation), in req->spec's room (the
 * experiment took its own copy). */
static const api_spec *now_spec(srv_session *s, api_experiment_req *req)
{
	api_view v;
	srv_session_view(s, &v);
	req->spec = *srv_session_spec(s);
	if (v.has_status) {
		req->spec.params.rotation = v.st.rotation;
		req->spec.params.omega_ss = v.st.omega_ss;
	}
	return &req->spec;
}

/* An experiment for a request body; NULL with *pb. */
static srv_entry *experiment_create(const char *body, size_t len, api_problem *pb)
{
	api_experiment_req *req = malloc(sizeof *req);
	if (!req) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	api_exp_ext *ext = malloc(sizeof *ext);
	srv_experiment *e = NULL;
	if (!ext)
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
	else if (api_parse_experiment(body, len, req, ext, pb) == API_OK)
		e = srv_exp_new(req, ext, cfg->data_dir, pb);
	/* an identification or a closed loop measures the scene it will run
	 * on first: the fresh session's, or the named one's (a missing one
	 * is start's 404) */
	srv_session *s = e && !req->fresh ? srv_session_get(req->session_id) : NULL;
	if (e && srv_exp_ready(e, s ? now_spec(s, req) : &req->spec, pb) != API_OK) {
		srv_exp_free(e);
		e = NULL;
	}
	if (s)
		srv_session_put(s);
	free(ext);
	free(req);
	return e ? srv_exp_entry(e) : NULL;
}

static void experiment_discard(srv_entry *en)
{
	srv_exp_free(srv_exp_from_entry(en));
}

/* DELETE: a running experiment is let go by its session, aborted, as at
 * its session's end; a fresh session it created and would have removed at
 * its end is deleted now, one the client made or kept stays. */
static int experiment_cancel(srv_entry *en, int only_running)
{
	srv_experiment *e = srv_exp_from_entry(en);
	char sid[SRV_ID_LEN], why[96];
	int on = srv_exp_cancel(e, only_running, sid, sizeof sid);
	if (on < 0)
		return 0;
	if (!on)
		return 1;
	srv_session *s = srv_session_get(sid);
	snprintf(why, sizeof why, "deleted (DELETE /api/v1/experiments/%s)", srv_exp_id(e));
	if (s && srv_session_detach(s, e, why))
		srv_session_delete(s);
	srv_session_put(s);
	return 1;
}

/* On its session (a fresh one or the one it names), then its record. */
static api_err experiment_start(srv_entry *en, int client_fd, char **answer, api_problem *pb)
{
	srv_experiment *e = srv_exp_from_entry(en);
	if (start_on_session(e, srv_exp_request(e), client_fd, pb) != API_OK)
		return pb->code;
	if (srv_exp_deleted(e)) /* a DELETE came before it was on its session */
		experiment_cancel(en, 0);
	srv_exp_persist(e); /* not once deleted */
	atomic_fetch_add(&srv_stats.experiments, 1);
	*answer = experiment_json(e, 0);
	return API_OK;
}

static char *experiment_text(srv_entry *en, int csv)
{
	return experiment_json(srv_exp_from_entry(en), csv);
}

static void experiment_view(srv_entry *en, void *view, void *scratch)
{
	srv_exp_view(srv_exp_from_entry(en), view, scratch);
}

static char *experiment_list_text(const void *views, size_t n, int csv)
{
	return csv ? api_experiment_csv(views, n) : api_experiment_list_json(views, n);
}

static srv_entry *experiment_load(void *payload, size_t len, char *why, size_t whylen)
{
	srv_experiment *e = srv_exp_load(payload, len, why, whylen);
	return e ? srv_exp_entry(e) : NULL;
}

static srv_entry *experiment_damaged(const char *id, const char *why)
{
	srv_experiment *e = srv_exp_damaged(id, why);
	return e ? srv_exp_entry(e) : NULL;
}

const srv_job_kind srv_experiment_job = {
	.name = "experiment",
	.plural = "experiments",
	.reg = &experiments,
	.created_status = 201,
	.limit = "running or held by a session; wait for one to end",
	.store_kind = SRV_STORE_EXPERIMENT,
	.result_file = "experiment-%s.json",
	.restore_evicts = 1,
	.create = experiment_create,
	.discard = experiment_discard,
	.start = experiment_start,
	.evictable = evictable,
	.text = experiment_text,
	.view_size = sizeof(api_experiment_view),
	.scratch_size = sizeof(srv_exp_scratch),
	.view = experiment_view,
	.list_text = experiment_list_text,
	.cancel = experiment_cancel,
	.load = experiment_load,
	.damaged = experiment_damaged,
};
