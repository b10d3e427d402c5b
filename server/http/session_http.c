/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_http.c - the session resources: POST/GET /api/v1/sessions,
 * GET/PATCH/DELETE /api/v1/sessions/{id} and its trajectory.
 *
 * Handlers parse with api/, act through session.c (never the core) and
 * answer with api/'s text. A rejected request changes nothing: bodies are
 * validated whole before anything is queued.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_routes.h"
#include "peers.h"
#include "session.h"
#include "session_http.h"

#define CONTROL_TIMEOUT_S 5.0

static enum MHD_Result not_found(srv_req *r)
{
	return srv_reply_not_found(r, "session");
}

enum MHD_Result srv_h_sessions_create(srv_req *r)
{
	enum MHD_Result res;
	api_spec spec;
	api_problem pb;
	if (api_parse_session(r->body, r->body_len, &spec, &pb) != API_OK)
		return srv_reply_problem(r, &pb, NULL);
	/* the client's socket: a LIGGGHTS bed stops settling when it leaves,
	 * and nothing is created for one that left while it settled (its
	 * answer then goes nowhere and closes the connection) */
	srv_session *s = srv_session_create(&spec, NULL, srv_client_fd(r), 0, &pb);
	if (!s)
		return srv_reply_problem(r, &pb, NULL);
	api_view v;
	srv_session_view(s, &v);
	res = srv_reply_created(r, 201, api_session_json(&v, 1),
				"/api/v1/sessions", v.id);
	srv_session_put(s);
	return res;
}

enum MHD_Result srv_h_sessions_list(srv_req *r)
{
	srv_session **all = NULL;
	size_t n = srv_sessions_all(&all);
	api_view *views = calloc(n ? n : 1, sizeof *views);
	char *text = NULL;
	if (views) {
		for (size_t i = 0; i < n; i++)
			srv_session_view(all[i], &views[i]);
		text = r->csv ? api_session_csv(views, n) : api_session_list_json(views, n);
	}
	srv_sessions_release(all, n);
	free(views);
	return srv_peers_reply(r, text, "sessions");
}

enum MHD_Result srv_h_session_get(srv_req *r)
{
	srv_session *s = srv_session_get(r->arg[0]);
	if (!s)
		return not_found(r);
	api_problem pb;
	if (srv_session_replaying(s, &pb) != API_OK) {
		srv_session_put(s);
		return srv_reply_problem(r, &pb, NULL);
	}
	api_view v;
	srv_session_view(s, &v);
	enum MHD_Result res =
		srv_reply_result(r, r->csv ? api_session_csv(&v, 1) : api_session_json(&v, 1));
	srv_session_put(s);
	return res;
}

enum MHD_Result srv_h_session_patch(srv_req *r)
{
	enum MHD_Result res;
	srv_session *s = srv_session_get(r->arg[0]);
	if (!s)
		return not_found(r);
	api_control c;
	api_problem pb;
	double t_eff = NAN;
	api_view v;
	srv_session_view(s, &v);
	if (srv_session_replaying(s, &pb) != API_OK ||
	    api_parse_control(r->body, r->body_len, v.spec, &c, &pb) !=
		    API_OK ||
	    srv_session_control(s, &c, CONTROL_TIMEOUT_S, &t_eff, &pb) !=
		    API_OK) {
		res = srv_reply_problem(r, &pb, NULL);
		goto out;
	}
	srv_session_view(s, &v);
	res = srv_reply_json(r, 200, api_control_result_json(&v, &c, 1, t_eff));
out:
	srv_session_put(s);
	return res;
}

enum MHD_Result srv_h_session_delete(srv_req *r)
{
	srv_session *s = srv_session_get(r->arg[0]);
	if (!s)
		return not_found(r);
	api_problem pb;
	if (srv_session_check_removable(s, &pb) != API_OK) {
		srv_session_put(s);
		return srv_reply_problem(r, &pb, NULL);
	}
	int removed = srv_session_delete(s);
	srv_session_put(s);
	return srv_reply_deleted(r, removed, "session");
}

enum MHD_Result srv_h_trajectory(srv_req *r)
{
	api_problem pb;
	api_trajectory_query q;
	double stride = 0, *rows = NULL;
	if (api_parse_trajectory_query(srv_query(r, "from"), srv_query(r, "to"),
				       srv_query(r, "stride"), &q, &pb) != API_OK)
		return srv_reply_problem(r, &pb, NULL);
	double from = q.from, to = q.to, every = q.stride;
	srv_session *s = srv_session_get(r->arg[0]);
	if (!s)
		return not_found(r);
	if (srv_session_replaying(s, &pb) != API_OK) {
		srv_session_put(s);
		return srv_reply_problem(r, &pb, NULL);
	}
	int columns, layers;
	srv_session_feed_size(s, &columns, &layers);
	size_t n = srv_session_history(s, from, to, &rows, &stride);
	srv_session_put(s);
	if (rows && every > 0) {
		/* rows on the grid of multiples of the asked stride, which must
		 * be a whole number of the recorded spacing (and is taken as
		 * that multiple) */
		if (api_trajectory_stride(every, stride, &every, &pb) != API_OK) {
			free(rows);
			return srv_reply_problem(r, &pb, NULL);
		}
		/* a row is on the grid when its time is within a millionth
		 * of the recorded spacing of a multiple of the stride (a
		 * ratio alone keeps every row of a stride far beyond them) */
		size_t width = API_HISTORY_WIDTH(columns), kept = 0;
		for (size_t i = 0; i < n; i++) {
			double t = rows[i * width];
			if (fabs(t - floor(t / every + 0.5) * every) < 1e-6 * stride)
				memmove(rows + kept++ * width, rows + i * width,
					width * sizeof *rows);
		}
		n = kept;
		stride = every;
	}
	char *text = !rows  ? NULL
		     : r->csv ? api_trajectory_csv(rows, n, columns)
			   : api_trajectory_json(rows, n, columns, stride);
	free(rows);
	return srv_reply_result(r, text);
}
