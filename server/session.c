/*
 * session.c - sessions: the registry, the worker thread and its command
 * queue, the record ring and the trajectory history.
 *
 * A sim instance is not thread-safe, so each session's worker thread is
 * the only one that touches it. HTTP handlers never call the core: they
 * queue controls (mutex-protected list of commands that live on the
 * handler's stack) and wait for the worker's acknowledgement, which
 * carries sim_effective_time() read when the control was applied. The
 * worker publishes what others read under the session lock: a status
 * snapshot, a bounded ring of stream records (samples every
 * 1/sample_rate simulated seconds and control events, indexed by a
 * sequence number that never repeats) and a downsampled history whose
 * stride doubles whenever it fills. Pacing holds simulated time to
 * pace x wall time, or runs flat out for pace "max" up to "until".
 * Lock order: registry lock before any session lock, never the reverse.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "srv.h"

#define DEG (180.0 / M_PI)

typedef struct srv_cmd {
	api_control c;
	int done, rc;
	double t_eff;
	struct srv_cmd *next;
} srv_cmd;

struct srv_session {
	char id[24];
	int refs;                 /* registry lock */
	int removed;              /* registry lock */
	srv_session *next;        /* registry list */
	api_spec spec;            /* immutable */
	double created;
	int columns, layers;      /* feed size, 0 without feed */
	sim *sim;                 /* worker only */
	pthread_t worker;
	int worker_started;
	api_sample scratch;       /* worker only */

	pthread_mutex_t lock;
	pthread_cond_t wake;      /* worker: commands, stop */
	pthread_cond_t data;      /* streams and waiting handlers */
	/* guarded by lock */
	int stop;
	int state;
	char error[256];
	double pace, until;
	srv_cmd *cmd_head, *cmd_tail;
	sim_status st;
	double steps_per_s, rtf;
	api_sample *ring;
	double *ring_store;
	size_t ring_cap;
	uint64_t head;
	double *hist;
	size_t hist_cap, hist_n;
	double hist_stride, hist_next;
	int streams;
	srv_experiment *exp;
	int exp_started;
};

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

/* ---- ring and history (lock held) ---------------------------------- */

static api_sample *push_slot(srv_session *s)
{
	api_sample *slot = &s->ring[s->head % s->ring_cap];
	slot->index = s->head++;
	return slot;
}

void srv_session_push_event(srv_session *s, const char *type,
			    const char *json)
{
	api_sample *slot = push_slot(s);
	slot->kind = API_REC_EVENT;
	slot->st = s->st;
	snprintf(slot->event_type, sizeof slot->event_type, "%s", type);
	snprintf(slot->event, sizeof slot->event, "%s", json);
}

static void push_event_reason(srv_session *s, const char *type,
			      const char *detail)
{
	char json[API_EVENT_MAX], t[40];
	api_fmt_double(t, sizeof t, s->st.t);
	snprintf(json, sizeof json, "{\"t\":%s%s%s}", t, detail ? "," : "",
		 detail ? detail : "");
	srv_session_push_event(s, type, json);
}

static void record_history(srv_session *s)
{
	if (s->st.t < s->hist_next - 1e-12 || !s->hist_cap)
		return;
	if (s->hist_n == s->hist_cap) {
		/* full: keep every other row, double the stride */
		size_t k = 0;
		for (size_t i = 0; i < s->hist_n; i += 2, k++)
			memmove(s->hist + k * API_HISTORY_COLS,
				s->hist + i * API_HISTORY_COLS,
				API_HISTORY_COLS * sizeof(double));
		s->hist_n = k;
		s->hist_stride *= 2;
	}
	api_history_row(&s->st, s->hist + s->hist_n * API_HISTORY_COLS);
	s->hist_n++;
	s->hist_next = s->st.t + s->hist_stride;
}

static void record_sample(srv_session *s)
{
	api_sample *slot = push_slot(s);
	slot->kind = API_REC_SAMPLE;
	slot->st = s->st;
	slot->event_type[0] = '\0';
	size_t n = (size_t)s->columns +
		   2 * (size_t)s->columns * (size_t)s->layers;
	if (n)
		memcpy(slot->column_disp, s->scratch.column_disp,
		       n * sizeof(double));
	record_history(s);
}

/* Copy the feed arrays out of the instance (worker, no lock needed). */
static void gather_feed(srv_session *s)
{
	if (!s->columns)
		return;
	sim_column_displacement(s->sim, s->scratch.column_disp);
	sim_feed_state(s->sim, s->scratch.xi, s->scratch.eta);
}

/* ---- worker ----------------------------------------------------------- */

/* Apply queued controls (lock held). Returns 1 if pacing must restart. */
static int apply_commands(srv_session *s)
{
	int reanchor = 0;
	srv_cmd *cmd;
	while ((cmd = s->cmd_head)) {
		s->cmd_head = cmd->next;
		if (!s->cmd_head)
			s->cmd_tail = NULL;
		const api_control *c = &cmd->c;
		double t_eff = sim_effective_time(s->sim);
		int rc = SIM_OK;
		if (c->set & (API_C_BETA | API_C_BETA_RATE)) {
			double target = (c->set & API_C_BETA)
						? c->beta
						: s->st.beta_target * DEG;
			double rate =
				(c->set & API_C_BETA_RATE) ? c->beta_rate : 0;
			rc = sim_set_beta(s->sim, target, rate);
		}
		if (rc == SIM_OK && (c->set & API_C_ROTATION))
			rc = sim_set_rotation(s->sim, c->rotation);
		if (rc == SIM_OK && (c->set & API_C_OMEGA_SS))
			rc = sim_set_omega_ss(s->sim, c->omega_ss);
		if (rc == SIM_OK && (c->set & API_C_PACE)) {
			s->pace = c->pace;
			reanchor = 1;
		}
		if (rc == SIM_OK && (c->set & API_C_UNTIL)) {
			s->until = c->until;
			if (s->state == SRV_FINISHED &&
			    (s->until == 0 || s->until > s->st.t))
				s->state = SRV_RUNNING;
		}
		if (rc == SIM_OK && (c->set & API_C_RUNNING)) {
			if (!c->running && s->state == SRV_RUNNING)
				s->state = SRV_PAUSED;
			else if (c->running && s->state == SRV_PAUSED)
				s->state = SRV_RUNNING;
			reanchor = 1;
		}
		if (s->pace == API_PACE_MAX && s->until == 0)
			s->until = s->st.t + API_DEFAULT_MAX_UNTIL;
		if (rc == SIM_OK) {
			char json[API_EVENT_MAX];
			api_control_event(json, sizeof json, c, t_eff);
			srv_session_push_event(s, "control", json);
		}
		cmd->rc = rc;
		cmd->t_eff = t_eff;
		cmd->done = 1;
	}
	pthread_cond_broadcast(&s->data);
	return reanchor;
}

/* Next simulated time to advance to (lock held). */
static double next_time(srv_session *s)
{
	double t = s->st.t;
	double dt = 1.0 / s->spec.sample_rate;
	double t_next = (floor(t / dt + 1e-6) + 1) * dt;
	if (s->until > 0 && t_next > s->until)
		t_next = s->until;
	if (s->exp) {
		double b = srv_exp_boundary(s->exp);
		if (b > t && b < t_next)
			t_next = b;
	}
	return t_next;
}

static void *worker_main(void *arg)
{
	srv_session *s = arg;
	double anchor_wall = srv_now(), anchor_t = 0;
	double rate_wall = anchor_wall, rate_t = 0;
	uint64_t rate_steps = 0;
	sim_status st;

	gather_feed(s);
	pthread_mutex_lock(&s->lock);
	sim_get_status(s->sim, &s->st);
	record_sample(s);
	pthread_cond_broadcast(&s->data);
	for (;;) {
		if (s->cmd_head && apply_commands(s)) {
			anchor_wall = rate_wall = srv_now();
			anchor_t = rate_t = s->st.t;
			rate_steps = s->st.steps;
		}
		if (s->stop)
			break;
		if (s->exp && !s->exp_started && s->state != SRV_FAILED) {
			srv_exp_begin(s->exp, s->sim, &s->st, s);
			s->exp_started = 1;
			pthread_cond_broadcast(&s->data);
		}
		if (s->state == SRV_RUNNING && s->until > 0 &&
		    s->st.t >= s->until) {
			s->state = SRV_FINISHED;
			push_event_reason(s, "finished", NULL);
			pthread_cond_broadcast(&s->data);
		}
		if (s->state != SRV_RUNNING) {
			s->steps_per_s = s->rtf = 0;
			pthread_cond_wait(&s->wake, &s->lock);
			anchor_wall = rate_wall = srv_now();
			anchor_t = rate_t = s->st.t;
			rate_steps = s->st.steps;
			continue;
		}
		double t_next = next_time(s);
		if (s->pace != API_PACE_MAX) {
			double due = anchor_wall + (t_next - anchor_t) / s->pace;
			double now = srv_now();
			if (now < due - 1e-4) {
				struct timespec ts = srv_deadline(due - now);
				pthread_cond_timedwait(&s->wake, &s->lock, &ts);
				continue;
			}
			if (now - due > 0.25) { /* behind: do not catch up */
				anchor_wall = now;
				anchor_t = s->st.t;
			}
		}
		pthread_mutex_unlock(&s->lock);
		int rc = sim_advance(s->sim, t_next);
		sim_get_status(s->sim, &st);
		gather_feed(s);
		pthread_mutex_lock(&s->lock);
		if (st.steps > s->st.steps)
			atomic_fetch_add(&srv_stats.steps, st.steps - s->st.steps);
		s->st = st;
		record_sample(s);
		if (s->exp && s->exp_started &&
		    srv_exp_step(s->exp, s->sim, &s->st, s)) {
			s->exp = NULL;
			s->exp_started = 0;
		}
		if (rc != SIM_OK) {
			s->state = SRV_FAILED;
			snprintf(s->error, sizeof s->error, "%s: %s",
				 sim_strerror(rc),
				 sim_last_error(s->sim) ? sim_last_error(s->sim)
							: "");
			push_event_reason(s, "failed", NULL);
			if (s->exp) {
				srv_exp_abort(s->exp, s->error);
				s->exp = NULL;
			}
			srv_log(SRV_LOG_WARN, "session %s failed: %s", s->id,
				s->error);
		}
		double now = srv_now();
		if (now - rate_wall >= 0.5) {
			s->steps_per_s = (double)(st.steps - rate_steps) /
					 (now - rate_wall);
			s->rtf = (st.t - rate_t) / (now - rate_wall);
			rate_wall = now;
			rate_t = st.t;
			rate_steps = st.steps;
		}
		pthread_cond_broadcast(&s->data);
	}
	if (s->exp) {
		srv_exp_abort(s->exp, "the session was deleted or the daemon "
				      "stopped");
		s->exp = NULL;
	}
	pthread_cond_broadcast(&s->data);
	pthread_mutex_unlock(&s->lock);
	return NULL;
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

	if (pthread_create(&s->worker, NULL, worker_main, s) != 0) {
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
