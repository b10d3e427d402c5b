/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_store.c - a session's files in the data directory, written and
 * (docs/operations.md "Persistence"), written.
 *
 *   sessions/ID/spec.json        the spec as created, the API's JSON
 *                                (api_spec_file), read first
 *   sessions/ID/spec.bin         the same as this build's record (framed,
 *                                store.h), for earlier builds
 *   sessions/ID/controls.ndjson  every acknowledged control, one JSON
 *                                object a line with t_effective (s);
 *                                appended and synced before the control
 *                                is answered (control_log.c)
 *   sessions/ID/checkpoint.bin   the latest checkpoint: run state, pace,
 *                                until, the attached experiment's state,
 *                                the core's checkpoint (sim.h) and the
 *                                CPU budget (its count and limit); the
 *                                one before it as checkpoint.bin.prev
 *
 * Everything else is written by the store's writer (store.c); the worker only
 * serialises, between steps, with the session lock held. They are read
 * back by session_load.c.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "records.h"
#include "session_int.h"
#include "store.h"
#include "util.h"

/* sessions/ID/spec.bin (records.h) */
typedef srv_spec_record spec_record;

void srv_session_file(char *out, size_t len, const char *id, const char *file)
{
	snprintf(out, len, "sessions/%s%s%s", id, file ? "/" : "",
		 file ? file : "");
}

/* Which write of which session a callback is about (malloc'd, freed by
 * written). */
typedef struct write_of {
	char id[SRV_ID_LEN];
	int spec; /* spec.json */
	size_t logged; /* a checkpoint: the control log it accounts for */
} write_of;

/* A write's outcome: a failure puts the session in state "error" with the
 * reason (spec.json's while it is not on disk). A later success clears it,
 * unless spec.json is not on disk: the first success after its failure
 * (space came back) queues it again, and the session reports healthy only
 * once that rewrite is written (lock order: the session's, the store's). */
static void written(void *arg, int err, const char *what)
{
	write_of *w = arg;
	srv_session *s = srv_session_get(w->id);
	int spec = w->spec;
	free(w);
	if (!s)
		return;
	pthread_mutex_lock(&s->lock);
	if (spec) {
		s->persist.spec_unwritten = err != 0;
		s->persist.spec_retrying = 0;
	}
	if (err && (spec || !s->persist.spec_unwritten)) /* the spec's failure shown */
		snprintf(s->persist.store_error, sizeof s->persist.store_error, "%s", what);
	else if (!err && s->persist.spec_unwritten && !s->persist.spec_retrying) {
		s->persist.spec_retrying = 1;
		srv_persist_spec(s, 0);
	} else if (!s->persist.spec_unwritten && what && what[0] == '\0')
		s->persist.store_error[0] = '\0';
	pthread_mutex_unlock(&s->lock);
	srv_session_put(s);
}

/* Before a checkpoint is written: the control log up to what it accounts
 * for is on disk first (control_log.c), so that no checkpoint holds more
 * of the log than the file (a restore replays the log after it). */
static void log_first(void *arg)
{
	write_of *w = arg;
	srv_entry *en = srv_registry_get(&srv_sessions_registry, w->id);
	if (!en)
		return;
	srv_session *s = SRV_CONTAINER(en, srv_session, entry);
	srv_control_log_sync(s, w->logged, 30.0);
	srv_registry_put(&srv_sessions_registry, en);
}

static void queue(const srv_session *s, const char *file, void *buf,
		  size_t len, int keep_prev, size_t logged)
{
	char path[128];
	srv_session_file(path, sizeof path, s->entry.id, file);
	write_of *w = calloc(1, sizeof *w);
	if (w) {
		snprintf(w->id, sizeof w->id, "%s", s->entry.id);
		w->spec = strcmp(file, "spec.json") == 0;
		w->logged = logged;
	}
	srv_store_write_after(path, buf, len, keep_prev, w && logged ? log_first : NULL,
			      w ? written : NULL, w);
}

void srv_persist_spec(srv_session *s, int now)
{
	if (!srv_store_enabled() || s->damaged)
		return;
	char *text = api_spec_file(&s->spec, s->created, s->owned, s->picked ? &s->pick : NULL),
	     path[128];
	srv_session_file(path, sizeof path, s->entry.id, "spec.json");
	if (text && now) /* a creation: answered once it is on disk */
		s->persist.spec_unwritten = srv_store_write_now(path, text, strlen(text),
			s->persist.store_error, sizeof s->persist.store_error) != 0;
	if (text && now)
		free(text);
	else if (text)
		queue(s, "spec.json", text, strlen(text), 0, 0);
	/* spec.bin too, for an earlier build started on this directory */
	spec_record r;
	memset(&r, 0, sizeof r);
	snprintf(r.id, sizeof r.id, "%s", s->entry.id);
	r.spec = s->spec;
	r.created = s->created;
	r.owned = s->owned;
	size_t len;
	void *buf = srv_store_frame(SRV_STORE_SESSION, &r, sizeof r, &len);
	if (buf)
		queue(s, "spec.bin", buf, len, 0, 0);
}

void srv_persist_checkpoint(srv_session *s, int force)
{
	if (!srv_store_enabled() || !s->sim)
		return;
	double now = srv_now();
	int due = now - s->persist.ckpt_wall >= srv_store_interval() &&
		  (s->state == SRV_RUNNING || s->persist.ckpt_dirty);
	if (!due && !(force && s->persist.ckpt_dirty))
		return;
	srv_ckpt_record r;
	memset(&r, 0, sizeof r);
	r.state = s->state;
	r.pace = s->pace;
	r.until = s->until;
	snprintf(r.error, sizeof r.error, "%s", s->error);
	void *exp = NULL;
	if (s->exp && s->exp_started) {
		size_t n = 0;
		exp = srv_exp_save(s->exp, &n);
		r.exp_len = exp ? n : 0;
		r.exp_started = 1;
		snprintf(r.exp_id, sizeof r.exp_id, "%s", srv_exp_id(s->exp));
	}
	r.sim_len = sim_checkpoint_size(s->sim);
	/* the trailer: how much of the control log the checkpoint holds,
	 * its time, and its CPU budget (the count as the worker last read
	 * it: after its last batch of steps, at most 10 ms of stepping ago;
	 * where it stopped, exactly: idle() and a SIGTERM read it first) */
	srv_ckpt_trailer tr = {.logged = s->controls_len, .t = s->st.t,
			       .cpu_seconds = s->budget.cpu_seconds,
			       .cpu_limit = s->budget.cpu_limit,
			       .cpu_paused = s->budget.cpu_paused};
	size_t plen = sizeof r + r.exp_len + r.sim_len + sizeof tr;
	char *payload = malloc(plen);
	if (payload) {
		memcpy(payload, &r, sizeof r);
		if (r.exp_len)
			memcpy(payload + sizeof r, exp, r.exp_len);
		sim_checkpoint(s->sim, payload + sizeof r + r.exp_len,
			       r.sim_len);
		memcpy(payload + plen - sizeof tr, &tr, sizeof tr);
		size_t len;
		void *buf = srv_store_frame(SRV_STORE_CHECKPOINT, payload, plen,
					    &len);
		if (buf)
			queue(s, "checkpoint.bin", buf, len, 1, s->controls_len);
	}
	free(payload);
	free(exp);
	s->persist.ckpt_wall = now;
	s->persist.ckpt_dirty = 0;
}

api_err srv_session_check_removable(const srv_session *s, api_problem *pb)
{
	char path[128];
	srv_session_file(path, sizeof path, s->entry.id, NULL);
	return srv_store_check_removable(path, pb);
}

void srv_persist_remove(const srv_session *s)
{
	char path[128];
	srv_session_file(path, sizeof path, s->entry.id, NULL);
	srv_store_remove(path);
}
