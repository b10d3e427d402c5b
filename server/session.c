/*
 * session.c - sessions: registry, lifetime, views, the control queue
 * entry point and read access to the record ring and history.
 *
 * Sessions live in a registry (a list under reg_lock) and are reference
 * counted: the registry, each handler while it works and each stream
 * hold one. Handlers never call the core: controls go through the
 * worker's command queue (worker.c) and wait for its acknowledgement;
 * everything else is read from what the worker publishes under the
 * session lock. Lock order: registry lock before any session lock.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "session_int.h"

static pthread_mutex_t reg_lock = PTHREAD_MUTEX_INITIALIZER;
static srv_session *reg_head;
static size_t reg_count; /* sessions in the registry or being created */

void srv_sessions_init(void)
{
	reg_head = NULL;
	reg_count = 0;
}

int srv_sample_alloc(api_sample *rec, int columns, int layers)
{
	size_t n = (size_t)columns + 2 * (size_t)columns * (size_t)layers;
	memset(rec, 0, sizeof *rec);
	rec->column_disp = calloc(n ? n : 1, sizeof(double));
	if (!rec->column_disp)
		return -1;
	rec->columns = columns;
	rec->layers = layers;
	rec->xi = rec->column_disp + columns;
	rec->eta = rec->xi + (size_t)columns * (size_t)layers;
	return 0;
}

void srv_sample_free(api_sample *rec)
{
	if (!rec)
		return;
	free(rec->column_disp);
	rec->column_disp = rec->xi = rec->eta = NULL;
}

static void copy_record(api_sample *dst, const api_sample *src)
{
	size_t n = (size_t)src->columns +
		   2 * (size_t)src->columns * (size_t)src->layers;
	dst->index = src->index;
	dst->kind = src->kind;
	dst->st = src->st;
	dst->columns = src->columns;
	dst->layers = src->layers;
	if (src->kind == API_REC_SAMPLE && n)
		memcpy(dst->column_disp, src->column_disp, n * sizeof(double));
	memcpy(dst->event_type, src->event_type, sizeof dst->event_type);
	if (src->kind == API_REC_EVENT)
		memcpy(dst->event, src->event, sizeof dst->event);
}

/* ---- lifetime ---------------------------------------------------------- */

static void session_free(srv_session *s)
{
	if (!s)
		return;
	sim_free(s->sim);
	srv_sample_free(&s->scratch);
	free(s->ring);
	free(s->ring_store);
	free(s->hist);
	pthread_mutex_destroy(&s->lock);
	pthread_cond_destroy(&s->wake);
	pthread_cond_destroy(&s->data);
	free(s);
}

static void stop_worker(srv_session *s)
{
	pthread_mutex_lock(&s->lock);
	s->stop = 1;
	pthread_cond_broadcast(&s->wake);
	pthread_cond_broadcast(&s->data);
	pthread_mutex_unlock(&s->lock);
	if (s->worker_started) {
		pthread_join(s->worker, NULL);
		s->worker_started = 0;
	}
}

static int alloc_buffers(srv_session *s)
{
	size_t per = (size_t)s->columns +
		     2 * (size_t)s->columns * (size_t)s->layers;
	s->ring_cap = srv_cfg.ring > 16 ? (size_t)srv_cfg.ring : 16;
	s->ring = calloc(s->ring_cap, sizeof *s->ring);
	s->ring_store = calloc(per ? s->ring_cap * per : 1, sizeof(double));
	s->hist_cap = srv_cfg.history > 16 ? (size_t)srv_cfg.history : 16;
	s->hist = calloc(s->hist_cap * API_HISTORY_COLS, sizeof(double));
	if (!s->ring || !s->ring_store || !s->hist ||
	    srv_sample_alloc(&s->scratch, s->columns, s->layers))
		return -1;
	for (size_t i = 0; i < s->ring_cap; i++) {
		api_sample *r = &s->ring[i];
		r->columns = s->columns;
		r->layers = s->layers;
		r->column_disp = s->ring_store + i * per;
		r->xi = r->column_disp + s->columns;
		r->eta = r->xi + (size_t)s->columns * (size_t)s->layers;
	}
	s->hist_stride = 1.0 / s->spec.sample_rate;
	if (s->hist_stride < 0.01)
		s->hist_stride = 0.01;
	return 0;
}

srv_session *srv_session_create(const api_spec *spec, srv_experiment *exp,
				api_problem *pb)
{
	pthread_mutex_lock(&reg_lock);
	if (reg_count >= (size_t)srv_cfg.max_sessions) {
		pthread_mutex_unlock(&reg_lock);
		api_fail(pb, API_LIMIT, NULL,
			 "%d sessions exist, the limit (--max-sessions); "
			 "delete one first", srv_cfg.max_sessions);
		return NULL;
	}
	reg_count++;
	pthread_mutex_unlock(&reg_lock);

	char msg[256] = "";
	int err = SIM_OK;
	srv_session *s = calloc(1, sizeof *s);
	if (!s) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		goto fail_count;
	}
	s->spec = *spec;
	s->created = srv_unix_time();
	s->pace = spec->pace;
	s->until = spec->until;
	s->state = SRV_RUNNING;
	pthread_mutex_init(&s->lock, NULL);
	pthread_cond_init(&s->wake, NULL);
	pthread_cond_init(&s->data, NULL);
	s->sim = sim_new(&spec->params, &spec->scene, &spec->method, &err, msg,
			 sizeof msg);
	if (!s->sim) {
		api_fail(pb, api_from_sim(err ? err : SIM_ENOMEM), NULL, "%s",
			 msg[0] ? msg : sim_strerror(err));
		goto fail;
	}
	/* the worker has not run yet: publish the initial state ourselves so
	 * that the 201 answer shows beta, rotation and the equilibrium */
	sim_get_status(s->sim, &s->st);
	if (spec->scene.feed) {
		s->columns = sim_columns(s->sim);
		s->layers = sim_layers(s->sim);
	}
	if (alloc_buffers(s)) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		goto fail;
	}
	s->exp = exp;
	s->refs = 2; /* the registry's and the caller's */

	pthread_mutex_lock(&reg_lock);
	for (;;) { /* an id no live session has */
		srv_new_id(s->id);
		srv_session *o = reg_head;
		while (o && strcmp(o->id, s->id) != 0)
			o = o->next;
		if (!o)
			break;
	}
	s->next = reg_head;
	reg_head = s;
	pthread_mutex_unlock(&reg_lock);

	if (pthread_create(&s->worker, NULL, srv_worker_main, s) != 0) {
		pthread_mutex_lock(&reg_lock);
		srv_session **pp = &reg_head;
		while (*pp != s)
			pp = &(*pp)->next;
		*pp = s->next;
		reg_count--;
		pthread_mutex_unlock(&reg_lock);
		api_fail(pb, API_UNAVAILABLE, NULL,
			 "cannot start the session's worker thread");
		session_free(s);
		return NULL;
	}
	s->worker_started = 1;
	atomic_fetch_add(&srv_stats.sessions_created, 1);
	srv_log(SRV_LOG_INFO, "session %s created", s->id);
	return s;
fail:
	session_free(s);
fail_count:
	pthread_mutex_lock(&reg_lock);
	reg_count--;
	pthread_mutex_unlock(&reg_lock);
	return NULL;
}

srv_session *srv_session_get(const char *id)
{
	pthread_mutex_lock(&reg_lock);
	srv_session *s = reg_head;
	while (s && strcmp(s->id, id) != 0)
		s = s->next;
	if (s)
		s->refs++;
	pthread_mutex_unlock(&reg_lock);
	return s;
}

void srv_session_put(srv_session *s)
{
	if (!s)
		return;
	pthread_mutex_lock(&reg_lock);
	int last = --s->refs == 0;
	pthread_mutex_unlock(&reg_lock);
	if (last) {
		stop_worker(s);
		session_free(s);
	}
}

/* Unlink from the registry; 0 if someone already did. */
static int unlink_session(srv_session *s)
{
	pthread_mutex_lock(&reg_lock);
	if (s->removed) {
		pthread_mutex_unlock(&reg_lock);
		return 0;
	}
	s->removed = 1;
	srv_session **pp = &reg_head;
	while (*pp && *pp != s)
		pp = &(*pp)->next;
	if (*pp)
		*pp = s->next;
	reg_count--;
	pthread_mutex_unlock(&reg_lock);
	return 1;
}

void srv_session_delete(srv_session *s)
{
	if (!unlink_session(s))
		return;
	stop_worker(s);
	atomic_fetch_add(&srv_stats.sessions_deleted, 1);
	srv_log(SRV_LOG_INFO, "session %s deleted", s->id);
	srv_session_put(s); /* the registry's reference */
}

void srv_sessions_shutdown(void)
{
	/* stop all workers first (in parallel), then drop the references */
	pthread_mutex_lock(&reg_lock);
	for (srv_session *s = reg_head; s; s = s->next) {
		pthread_mutex_lock(&s->lock);
		s->stop = 1;
		pthread_cond_broadcast(&s->wake);
		pthread_cond_broadcast(&s->data);
		pthread_mutex_unlock(&s->lock);
	}
	pthread_mutex_unlock(&reg_lock);
	for (;;) {
		pthread_mutex_lock(&reg_lock);
		srv_session *s = reg_head;
		if (s)
			s->refs++;
		pthread_mutex_unlock(&reg_lock);
		if (!s)
			break;
		srv_session_delete(s);
		srv_session_put(s);
	}
}

/* ---- queries --------------------------------------------------------------- */

const char *srv_session_id(const srv_session *s)
{
	return s->id;
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
	snprintf(v->id, sizeof v->id, "%s", s->id);
	v->spec = &s->spec;
	v->created = s->created;
	v->columns = s->columns;
	v->layers = s->layers;
	pthread_mutex_lock(&s->lock);
	v->state = state_name(s->state);
	snprintf(v->error, sizeof v->error, "%s", s->error);
	v->pace = s->pace;
	v->until = s->until;
	v->has_status = 1;
	v->st = s->st;
	v->steps_per_s = s->steps_per_s;
	v->rtf = s->rtf;
	v->samples = s->head;
	v->streams = s->streams;
	if (s->exp)
		snprintf(v->experiment, sizeof v->experiment, "%s",
			 srv_exp_id(s->exp));
	pthread_mutex_unlock(&s->lock);
}

size_t srv_session_count(void)
{
	pthread_mutex_lock(&reg_lock);
	size_t n = 0;
	for (srv_session *s = reg_head; s; s = s->next)
		n++;
	pthread_mutex_unlock(&reg_lock);
	return n;
}

double srv_sessions_steps_per_s(void)
{
	double sum = 0;
	pthread_mutex_lock(&reg_lock);
	for (srv_session *s = reg_head; s; s = s->next) {
		pthread_mutex_lock(&s->lock);
		sum += s->steps_per_s;
		pthread_mutex_unlock(&s->lock);
	}
	pthread_mutex_unlock(&reg_lock);
	return sum;
}

size_t srv_sessions_all(srv_session ***out)
{
	pthread_mutex_lock(&reg_lock);
	size_t n = 0;
	for (srv_session *s = reg_head; s; s = s->next)
		n++;
	srv_session **arr = calloc(n ? n : 1, sizeof *arr);
	size_t k = 0;
	for (srv_session *s = reg_head; arr && s; s = s->next) {
		s->refs++;
		arr[k++] = s;
	}
	pthread_mutex_unlock(&reg_lock);
	*out = arr;
	return arr ? k : 0;
}

api_err srv_session_control(srv_session *s, const api_control *c,
			    double timeout_s, double *t_eff, api_problem *pb)
{
	srv_cmd cmd = {.c = *c};
	pthread_mutex_lock(&s->lock);
	api_err e = API_OK;
	if (s->stop)
		e = api_fail(pb, API_NOTFOUND, NULL,
			     "the session is being deleted");
	else if (s->state == SRV_FAILED)
		e = api_fail(pb, API_CONFLICT, NULL,
			     "the session has failed (%s); it takes no more "
			     "controls", s->error);
	else if ((c->set & API_C_UNTIL) && c->until > 0 && c->until <= s->st.t)
		e = api_fail(pb, API_CONFLICT, "until",
			     "until (%g s) lies in the past: the session is at "
			     "t = %g s", c->until, s->st.t);
	else if ((c->set & API_C_RUNNING) && c->running &&
		 s->state == SRV_FINISHED && !(c->set & API_C_UNTIL))
		e = api_fail(pb, API_CONFLICT, "running",
			     "the session finished at until = %g s; raise "
			     "until to run on", s->until);
	if (e != API_OK) {
		pthread_mutex_unlock(&s->lock);
		return e;
	}
	if (s->cmd_tail)
		s->cmd_tail->next = &cmd;
	else
		s->cmd_head = &cmd;
	s->cmd_tail = &cmd;
	pthread_cond_broadcast(&s->wake);
	struct timespec until = srv_deadline(timeout_s);
	while (!cmd.done && !s->stop)
		if (pthread_cond_timedwait(&s->data, &s->lock, &until) ==
		    ETIMEDOUT)
			break;
	if (!cmd.done) { /* take it back: nothing changes */
		srv_cmd **pp = &s->cmd_head, *prev = NULL;
		while (*pp && *pp != &cmd) {
			prev = *pp;
			pp = &(*pp)->next;
		}
		if (*pp)
			*pp = cmd.next;
		if (s->cmd_tail == &cmd)
			s->cmd_tail = prev;
		pthread_mutex_unlock(&s->lock);
		return api_fail(pb, API_UNAVAILABLE, NULL,
				"the session's worker did not take the change "
				"within %g s; nothing was changed", timeout_s);
	}
	pthread_mutex_unlock(&s->lock);
	if (cmd.rc != SIM_OK)
		return api_fail(pb, api_from_sim(cmd.rc), NULL, "%s",
				sim_strerror(cmd.rc));
	*t_eff = cmd.t_eff;
	return API_OK;
}

api_err srv_session_attach(srv_session *s, srv_experiment *e,
			   api_problem *pb)
{
	api_err rc = API_OK;
	pthread_mutex_lock(&s->lock);
	if (s->stop)
		rc = api_fail(pb, API_NOTFOUND, "session",
			      "the session is being deleted");
	else if (s->state == SRV_FAILED)
		rc = api_fail(pb, API_CONFLICT, "session",
			      "the session has failed (%s)", s->error);
	else if (s->exp)
		rc = api_fail(pb, API_CONFLICT, "session",
			      "the session already runs experiment %s",
			      srv_exp_id(s->exp));
	else {
		s->exp = e;
		s->exp_started = 0;
		pthread_cond_broadcast(&s->wake);
	}
	pthread_mutex_unlock(&s->lock);
	return rc;
}

void srv_session_extend(srv_session *s, double t_end)
{
	if (s->until > 0 && s->until < t_end)
		s->until = t_end;
	if (s->state == SRV_FINISHED && s->st.t < t_end)
		s->state = SRV_RUNNING;
}

/* ---- stream access -------------------------------------------------------- */

pthread_mutex_t *srv_session_lock(srv_session *s)
{
	return &s->lock;
}

pthread_cond_t *srv_session_data_cond(srv_session *s)
{
	return &s->data;
}

srv_ring_view srv_session_ring(srv_session *s)
{
	srv_ring_view v = {s->head,
			   s->head > s->ring_cap ? s->head - s->ring_cap : 0};
	return v;
}

void srv_session_copy(srv_session *s, uint64_t idx, api_sample *dst)
{
	copy_record(dst, &s->ring[idx % s->ring_cap]);
}

int srv_session_state(srv_session *s, int *removed)
{
	*removed = s->stop;
	return s->state;
}

double srv_session_time(srv_session *s)
{
	return s->st.t;
}

void srv_session_stream_count(srv_session *s, int delta)
{
	pthread_mutex_lock(&s->lock);
	s->streams += delta;
	pthread_mutex_unlock(&s->lock);
}

void srv_session_feed_size(const srv_session *s, int *columns, int *layers)
{
	*columns = s->columns;
	*layers = s->layers;
}

size_t srv_session_history(srv_session *s, double from, double to,
			   double **rows, double *stride)
{
	pthread_mutex_lock(&s->lock);
	size_t first = 0, last = s->hist_n;
	while (first < s->hist_n && s->hist[first * API_HISTORY_COLS] < from)
		first++;
	while (last > first && s->hist[(last - 1) * API_HISTORY_COLS] > to)
		last--;
	size_t n = last - first;
	*rows = malloc((n ? n : 1) * API_HISTORY_COLS * sizeof(double));
	if (*rows && n)
		memcpy(*rows, s->hist + first * API_HISTORY_COLS,
		       n * API_HISTORY_COLS * sizeof(double));
	*stride = s->hist_stride;
	pthread_mutex_unlock(&s->lock);
	return *rows ? n : 0;
}
