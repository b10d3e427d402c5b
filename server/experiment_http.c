/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_http.c - the experiment resources: POST/GET
 * /api/v1/experiments and GET /api/v1/experiments/{id}.
 *
 * Experiments are kept in a registry until shutdown; beyond
 * --max-experiments the oldest finished one that no worker refers to is
 * evicted. Creating one either creates a fresh session with the
 * experiment attached before its first step, or attaches it to a running
 * session; the session's worker then runs it (experiment.c).
 */
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "experiment_http.h"
#include "metrics.h"
#include "peers.h"
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
	srv_registry_open(&experiments, (size_t)cfg->max_experiments);
}

void srv_experiments_shutdown(void)
{
	srv_registry_clear(&experiments);
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

size_t srv_experiments_restore(void)
{
	char **names = NULL;
	size_t n = srv_store_enabled() ? srv_store_list_ids("experiments", 0, &names)
				       : 0,
	       count = 0;
	for (size_t i = 0; i < n; i++) {
		size_t l = strlen(names[i]);
		api_problem pb;
		srv_experiment *e = NULL;
		if (l > 4 && strcmp(names[i] + l - 4, ".bin") == 0)
			e = srv_exp_load(names[i], &pb);
		if (e && srv_registry_reserve(&experiments, srv_exp_entry(e),
					      evictable) == 0) {
			srv_registry_publish(&experiments, srv_exp_entry(e));
			srv_registry_put(&experiments, srv_exp_entry(e));
			count++;
		} else if (e) {
			srv_exp_free(e);
		} else if (l > 4 && strcmp(names[i] + l - 4, ".bin") == 0) {
			srv_log(SRV_LOG_WARN, "experiment not restored: %s",
				pb.detail);
			names[i][l - 4] = '\0';
			e = srv_exp_damaged(names[i], pb.detail);
			if (e && srv_registry_reserve(&experiments, srv_exp_entry(e),
						      NULL) == 0) {
				srv_registry_publish(&experiments, srv_exp_entry(e));
				srv_registry_put(&experiments, srv_exp_entry(e));
				count++;
			} else {
				srv_exp_free(e);
			}
		}
		free(names[i]);
	}
	free(names);
	return count;
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

/* Run e on a fresh session or attach it to the one it names; the session's
 * id is noted in e. */
static api_err start_on_session(srv_experiment *e,
				const api_experiment_req *req, api_problem *pb)
{
	srv_session *s;
	if (req->fresh) {
		s = srv_session_create(&req->spec, e, pb);
		if (!s)
			return pb->code;
	} else {
		s = srv_session_get(req->session_id);
		if (!s)
			return api_fail(pb, API_NOTFOUND, "session",
					"no session with id \"%.40s\"",
					req->session_id);
		if (srv_session_attach(s, e, pb) != API_OK) {
			srv_session_put(s);
			return pb->code;
		}
	}
	srv_exp_set_session(e, srv_session_id(s));
	srv_session_put(s);
	return API_OK;
}

/* The experiment as JSON, from a consistent copy of its state. */
static char *experiment_json(srv_experiment *e, int csv)
{
	api_experiment_view v;
	api_segment seg[API_EXP_MAX_SEGMENTS];
	srv_exp_view(e, &v, seg);
	return csv ? api_experiment_csv(&v, 1) : api_experiment_json(&v);
}

enum MHD_Result srv_h_experiments_create(srv_req *r)
{
	enum MHD_Result res;
	api_problem pb;
	api_experiment_req *req = malloc(sizeof *req);
	if (!req)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	if (api_parse_experiment(r->body, r->body_len, req, &pb) != API_OK) {
		free(req);
		return srv_reply_problem(r, &pb, NULL);
	}
	srv_experiment *e = srv_exp_new(req, cfg->data_dir, &pb);
	if (!e) {
		free(req);
		return srv_reply_problem(r, &pb, NULL);
	}
	if (srv_registry_reserve(&experiments, srv_exp_entry(e), evictable)) {
		free(req);
		srv_exp_free(e);
		return srv_fail(r, API_LIMIT, NULL,
				"%d experiments are running or kept "
				"(--max-experiments)", cfg->max_experiments);
	}
	if (start_on_session(e, req, &pb) != API_OK) {
		free(req);
		srv_registry_cancel(&experiments, srv_exp_entry(e));
		srv_exp_free(e);
		return srv_reply_problem(r, &pb, NULL);
	}
	free(req);
	srv_registry_publish(&experiments, srv_exp_entry(e));
	srv_exp_persist(e);
	atomic_fetch_add(&srv_stats.experiments, 1);
	res = srv_reply_created(r, 201, experiment_json(e, 0),
				"/api/v1/experiments", srv_exp_id(e));
	srv_registry_put(&experiments, srv_exp_entry(e));
	return res;
}

enum MHD_Result srv_h_experiment_get(srv_req *r)
{
	srv_entry *en = srv_registry_get(&experiments, r->arg[0]);
	if (!en)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no experiment with id \"%.40s\"", r->arg[0]);
	char *text = experiment_json(srv_exp_from_entry(en), r->csv);
	srv_registry_put(&experiments, en);
	return srv_reply_result(r, text);
}

enum MHD_Result srv_h_experiments_list(srv_req *r)
{
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(&experiments, &all);
	api_experiment_view *v = calloc(n + 1, sizeof *v);
	api_segment *seg = calloc(n * API_EXP_MAX_SEGMENTS + 1, sizeof *seg);
	char *text = NULL;
	if (v && seg) {
		for (size_t i = 0; i < n; i++)
			srv_exp_view(srv_exp_from_entry(all[i]), &v[i],
				     seg + i * API_EXP_MAX_SEGMENTS);
		text = r->csv ? api_experiment_csv(v, n) : api_experiment_list_json(v, n);
	}
	srv_registry_release(&experiments, all, n);
	free(v);
	free(seg);
	return srv_peers_reply(r, text, "experiments");
}
