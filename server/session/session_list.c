/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_list.c - the registry of sessions and what reads it: lookups,
 * snapshots, views and counts. Nothing here changes a session but its
 * last access; session.c owns their lifetime (it sets the registry's
 * destroy function at start-up).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "session_int.h"
#include "util.h"

srv_registry srv_sessions_registry = SRV_REGISTRY_INIT(NULL);
#define sessions srv_sessions_registry

srv_session *srv_session_get(const char *id)
{
	srv_entry *en = srv_registry_get(&sessions, id);
	if (!en)
		return NULL;
	srv_session *s = SRV_CONTAINER(en, srv_session, entry);
	pthread_mutex_lock(&s->lock);
	s->last_access = srv_now();
	pthread_mutex_unlock(&s->lock);
	return s;
}

void srv_session_put(srv_session *s)
{
	if (s)
		srv_registry_put(&sessions, &s->entry);
}

/* ---- queries --------------------------------------------------------------- */

const api_spec *srv_session_spec(const srv_session *s)
{
	return &s->spec;
}

const char *srv_session_id(const srv_session *s)
{
	return s->entry.id;
}

static const char *state_name(int state)
{
	static const char *const names[] = {"running", "paused", "finished",
					    "failed"};
	return state >= 0 && state <= 3 ? names[state] : "failed";
}

void srv_session_view(srv_session *s, api_view *v)
{
	memset(v, 0, sizeof *v);
	snprintf(v->id, sizeof v->id, "%s", s->entry.id);
	v->spec = &s->spec;
	v->created = s->created;
	v->columns = s->columns;
	v->layers = s->layers;
	pthread_mutex_lock(&s->lock);
	v->state = s->damaged ? "damaged"
		   : s->persist.store_error[0] && s->state != SRV_FAILED
			   ? "error"
			   : state_name(s->state);
	snprintf(v->error, sizeof v->error, "%s",
		 s->persist.store_error[0] && !s->damaged ? s->persist.store_error : s->error);
	v->pace = s->pace;
	v->until = s->until;
	v->has_status = !(s->restore.catch_up_t > 0); /* a past the clients left */
	v->st = s->st;
	v->steps_per_s = s->steps_per_s;
	v->rtf = s->rtf;
	v->samples = s->ring.head;
	v->streams = s->streams;
	v->cpu_seconds = s->budget.cpu_seconds;
	v->cpu_limit = s->budget.cpu_limit;
	v->pause_reason = s->state != SRV_PAUSED ? NULL
			  : s->budget.cpu_paused      ? "cpu-budget"
					       : "client";
	v->waiting_for_cpu = s->budget.waiting_for_cpu;
	v->replayed = s->restore.rebuilt;
	v->replay_seconds = s->restore.replay_seconds;
	v->has_bed = srv_dem_wanted(&s->spec);
	v->bed = s->dem.bed;
	v->pick = s->picked ? &s->pick : NULL;
	if (s->exp)
		snprintf(v->experiment, sizeof v->experiment, "%s",
			 srv_exp_id(s->exp));
	pthread_mutex_unlock(&s->lock);
}

/* The 503 for a session that replays (lock held). */
static api_err replaying(const srv_session *s, api_problem *pb)
{
	if (!(s->restore.catch_up_t > 0))
		return API_OK;
	double now = srv_now(), done = s->st.t - s->restore.replay_t0;
	double rate = now > s->restore.replay_wall && done > 0 ? done / (now - s->restore.replay_wall) : 0;
	double left = rate > 0 ? (s->restore.catch_up_t - s->st.t) / rate : 1;
	api_fail(pb, API_UNAVAILABLE, NULL,
		 "session %s is replaying its control log after a restart: at t = %.6g s of "
		 "%.6g s; it answers once it is back where it was",
		 s->entry.id, s->st.t, s->restore.catch_up_t);
	pb->retry_after = left < 1 ? 1 : left > 60 ? 60 : (int)ceil(left);
	return API_UNAVAILABLE;
}

api_err srv_session_replaying(srv_session *s, api_problem *pb)
{
	pthread_mutex_lock(&s->lock);
	api_err e = replaying(s, pb);
	pthread_mutex_unlock(&s->lock);
	return e;
}

size_t srv_session_count(void)
{
	return srv_registry_count(&sessions);
}

size_t srv_sessions_all(srv_session ***out)
{
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(&sessions, &all);
	srv_session **arr = calloc(n ? n : 1, sizeof *arr);
	if (!arr) {
		srv_registry_release(&sessions, all, n);
		n = 0;
	}
	for (size_t i = 0; i < n; i++)
		arr[i] = SRV_CONTAINER(all[i], srv_session, entry);
	if (arr)
		free(all);
	*out = arr;
	return n;
}

void srv_sessions_release(srv_session **all, size_t n)
{
	for (size_t i = 0; i < n; i++)
		srv_session_put(all[i]);
	free(all);
}

double srv_sessions_steps_per_s(void)
{
	double sum = 0;
	srv_session **all = NULL;
	size_t n = srv_sessions_all(&all);
	for (size_t i = 0; i < n; i++) {
		pthread_mutex_lock(&all[i]->lock);
		sum += all[i]->steps_per_s;
		pthread_mutex_unlock(&all[i]->lock);
	}
	srv_sessions_release(all, n);
	return sum;
}
