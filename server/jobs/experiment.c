/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment.c - the beta-schedule experiment (POST /api/v1/experiments)
 * as its session's worker runs it.
 *
 * At each segment start the experiment hands the worker a command: the
 * segment's beta, then a restart of the core's transport estimator
 * (sim_restart_transport); the worker applies it between steps like any
 * PATCH and reports sim_effective_time() as the command time, or the
 * core's refusal, which aborts the experiment with that error. After every
 * advance it records the per-period feed velocity (sim_status.
 * feed_velocity). When a segment ends, its steady velocity is the mean
 * feed velocity over the segment's second half and its reversal time runs
 * from the command until the feed velocity first reaches 90 % of that
 * steady value (none when the segment's beta was already set: nothing
 * reverses). Fields are guarded by the experiment's lock, taken inside
 * the session lock by the worker's hooks and alone by the handlers (lock
 * order: registry.h). A segment's start and its measurements at its end
 * are experiment_segment.c.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "experiment_int.h"
#include "records.h"
#include "store.h"
#include "util.h"

static double exp_end(const srv_experiment *e)
{
	return e->req.seg[e->req.nseg - 1].until;
}

srv_experiment *srv_exp_new(const api_experiment_req *req, const api_exp_ext *ext,
			    const char *data_dir, api_problem *pb)
{
	srv_experiment *e = calloc(1, sizeof *e);
	if (!e) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	e->req = *req;
	if (ext)
		e->ext = *ext;
	e->beta_sent = INFINITY;
	e->data_dir = data_dir && srv_store_enabled() ? data_dir : NULL;
	e->attached = 1;
	pthread_mutex_init(&e->lock, NULL);
	double dur = exp_end(e);
	e->rec_cap = EXP_RECORDS;
	e->rec_spacing = dur / EXP_RECORDS;
	e->rec_t = malloc(e->rec_cap * sizeof(double));
	e->rec_v = malloc(e->rec_cap * sizeof(double));
	if (!e->rec_t || !e->rec_v) {
		srv_exp_free(e);
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	return e;
}

static void exp_release(srv_experiment *e)
{
	free(e->rec_t);
	free(e->rec_v);
	pthread_mutex_destroy(&e->lock);
	free(e);
}

void srv_exp_free(srv_experiment *e)
{
	if (!e)
		return;
	pthread_mutex_lock(&e->lock);
	int later = e->writes > 0; /* the last write's callback frees it */
	e->freed = 1;
	pthread_mutex_unlock(&e->lock);
	if (!later)
		exp_release(e);
}

srv_entry *srv_exp_entry(srv_experiment *e)
{
	return &e->entry;
}

srv_experiment *srv_exp_from_entry(srv_entry *en)
{
	return SRV_CONTAINER(en, srv_experiment, entry);
}

const char *srv_exp_id(const srv_experiment *e)
{
	return e->entry.id;
}

const api_experiment_req *srv_exp_request(const srv_experiment *e)
{
	return &e->req;
}

int srv_exp_keeps_session(const srv_experiment *e)
{
	return e->req.keep_session || !e->req.fresh;
}

void srv_exp_set_spec(srv_experiment *e, const api_spec *spec)
{
	pthread_mutex_lock(&e->lock);
	e->req.spec = *spec;
	pthread_mutex_unlock(&e->lock);
}

void srv_exp_set_session(srv_experiment *e, const char *session_id)
{
	pthread_mutex_lock(&e->lock);
	snprintf(e->session_id, sizeof e->session_id, "%s", session_id);
	pthread_mutex_unlock(&e->lock);
}

int srv_exp_finished(srv_experiment *e)
{
	pthread_mutex_lock(&e->lock);
	int over = !e->attached && e->state >= EXP_DONE;
	pthread_mutex_unlock(&e->lock);
	return over;
}

/* The feed-velocity record is only needed while running (lock held). */
static void drop_record(srv_experiment *e)
{
	free(e->rec_t);
	free(e->rec_v);
	e->rec_t = e->rec_v = NULL;
	e->rec_n = e->rec_cap = 0;
}

/* The view of e (lock held); v->seg borrows e's segments. */
static void fill_view(const srv_experiment *e, api_experiment_view *v)
{
	static const char *const names[EXP_NSTATES] = {"waiting", "running", "done",     "aborted",
							"interrupted", "error", "damaged"};
	memset(v, 0, sizeof *v);
	snprintf(v->id, sizeof v->id, "%s", e->entry.id);
	snprintf(v->session_id, sizeof v->session_id, "%s", e->session_id);
	v->state = names[e->state];
	snprintf(v->error, sizeof v->error, "%s", e->error);
	v->t_start = e->t0;
	v->t_now = e->t_now;
	double p = e->state == EXP_WAITING || e->req.nseg < 1 ? 0 : (e->t_now - e->t0) / exp_end(e);
	v->progress = e->state == EXP_DONE ? 1 : p < 0 ? 0 : p > 1 ? 1 : p;
	v->nseg = e->req.nseg;
	v->seg = e->req.seg;
	v->spec = &e->req.spec; /* set at creation, never changed after */
	v->ext = &e->ext;
}

/* ---- persistence (store.h) ---------------------------------------------
 *
 * experiments/ID.bin holds the record below: written at creation and when
 * the experiment ends, enough to serve it again. While it runs, its
 * progress (the record and the feed-velocity record) rides in its
 * session's checkpoint (srv_exp_save), so that both continue from the same
 * moment. */
typedef srv_exp_record exp_record; /* records.h */

static void record_of(const srv_experiment *e, exp_record *r)
{
	memset(r, 0, sizeof *r);
	snprintf(r->id, sizeof r->id, "%s", e->entry.id);
	snprintf(r->session_id, sizeof r->session_id, "%s", e->session_id);
	r->req = e->req;
	r->state = e->state;
	r->cur = e->cur;
	snprintf(r->error, sizeof r->error, "%s", e->error);
	r->t0 = e->t0;
	r->t_now = e->t_now;
	r->seg_first = e->seg_first;
	r->rec_n = e->rec_n;
	r->rec_spacing = e->rec_spacing;
}

/* A write's outcome for e (its writes count keeps it alive). */
static void written(void *arg, int err, const char *what)
{
	srv_experiment *e = arg;
	if (err)
		srv_exp_write_failed(e, what);
	pthread_mutex_lock(&e->lock);
	int gone = --e->writes == 0 && e->freed;
	pthread_mutex_unlock(&e->lock);
	if (gone)
		exp_release(e);
}

/* Queue a write for e (lock held). */
static void queue_write(srv_experiment *e, const char *path, void *buf,
			size_t len)
{
	e->writes++;
	srv_store_write(path, buf, len, 0, written, e);
}

/* experiments/ID.bin (lock held): queued, or now (its creation) written here. Not while the
 * daemon stops: an experiment its session's worker lets go then is resumed next time; nor
 * once deleted: its files are being removed. */
static void persist_locked(srv_experiment *e, int now)
{
	if (!e->data_dir || srv_stopping() || e->deleted)
		return;
	size_t tail = srv_exp_tail_len(e), len;
	char *rec = malloc(sizeof(exp_record) + tail);
	if (!rec)
		return;
	exp_record r;
	record_of(e, &r);
	memcpy(rec, &r, sizeof r);
	memcpy(rec + sizeof r, &e->ext, tail);
	void *buf = srv_store_frame(SRV_STORE_EXPERIMENT, rec, sizeof r + tail, &len);
	free(rec);
	char path[64], msg[256];
	snprintf(path, sizeof path, "experiments/%s.bin", e->entry.id);
	if (buf && now) { /* a failure is logged (store.c); its end's write says it */
		srv_store_write_now(path, buf, len, msg, sizeof msg);
		free(buf);
	} else if (buf) {
		queue_write(e, path, buf, len);
	}
}

void srv_exp_persist(srv_experiment *e)
{
	pthread_mutex_lock(&e->lock);
	persist_locked(e, 1);
	pthread_mutex_unlock(&e->lock);
}

void srv_exp_write_failed(srv_experiment *e, const char *what)
{
	pthread_mutex_lock(&e->lock);
	if (e->freed) {
		pthread_mutex_unlock(&e->lock);
		return;
	}
	if (e->state != EXP_RUNNING && e->state != EXP_WAITING) {
		e->state = EXP_ERROR;
		snprintf(e->error, sizeof e->error, "%s", what);
	}
	pthread_mutex_unlock(&e->lock);
}

void *srv_exp_save(srv_experiment *e, size_t *len)
{
	pthread_mutex_lock(&e->lock);
	exp_record r;
	record_of(e, &r);
	size_t vec = e->rec_n * sizeof(double), tail = srv_exp_tail_len(e);
	char *buf = malloc(sizeof r + 2 * vec + tail);
	if (buf) {
		memcpy(buf, &r, sizeof r);
		if (vec) {
			memcpy(buf + sizeof r, e->rec_t, vec);
			memcpy(buf + sizeof r + vec, e->rec_v, vec);
		}
		memcpy(buf + sizeof r + 2 * vec, &e->ext, tail);
		*len = sizeof r + 2 * vec + tail;
	}
	pthread_mutex_unlock(&e->lock);
	return buf;
}

int srv_exp_resume(srv_experiment *e, const void *buf, size_t len)
{
	exp_record r;
	if (len < sizeof r)
		return -1;
	memcpy(&r, buf, sizeof r);
	size_t head = sizeof r + 2 * r.rec_n * sizeof(double);
	if (r.rec_n > EXP_RECORDS || len < head || srv_exp_tail_ok((const char *)buf + head, len - head) ||
	    r.state != EXP_RUNNING || r.seg_first > r.rec_n)
		return -1;
	char why[160];
	if (srv_exp_req_check(&r.req, r.cur, why, sizeof why) != 0)
		return -1;
	int rc = -1;
	pthread_mutex_lock(&e->lock);
	if (!e->rec_t) {
		e->rec_t = malloc(EXP_RECORDS * sizeof(double));
		e->rec_v = malloc(EXP_RECORDS * sizeof(double));
	}
	if (e->rec_t && e->rec_v) {
		size_t vec = r.rec_n * sizeof(double);
		const char *b = (const char *)buf + sizeof r;
		memcpy(e->rec_t, b, vec);
		memcpy(e->rec_v, b + vec, vec);
		e->rec_cap = EXP_RECORDS;
		e->rec_n = r.rec_n;
		e->seg_first = r.seg_first;
		e->rec_spacing = r.rec_spacing;
		e->req = r.req;
		if (len > head)
			memcpy(&e->ext, (const char *)buf + head, sizeof e->ext);
		e->state = EXP_RUNNING;
		e->cur = r.cur;
		e->t0 = r.t0;
		e->t_now = r.t_now;
		e->attached = 1;
		e->error[0] = '\0';
		rc = 0;
	}
	pthread_mutex_unlock(&e->lock);
	return rc;
}

srv_experiment *srv_exp_damaged(const char *id, const char *why)
{
	srv_experiment *e = calloc(1, sizeof *e);
	if (!e)
		return NULL;
	pthread_mutex_init(&e->lock, NULL);
	snprintf(e->entry.id, sizeof e->entry.id, "%.23s", id);
	e->state = EXP_DAMAGED;
	snprintf(e->error, sizeof e->error, "damaged: %.200s", why);
	return e;
}

srv_experiment *srv_exp_load(void *payload, size_t len, char *why, size_t whylen)
{
	exp_record *r = payload;
	int bad = len < sizeof *r || srv_exp_tail_ok((const char *)payload + sizeof *r,
						      len - sizeof *r) ||
		  r->state < 0 || r->state >= EXP_NSTATES;
	if (bad)
		snprintf(why, whylen, "inconsistent");
	if (bad || srv_exp_req_check(&r->req, r->cur, why, whylen) != 0) {
		free(r);
		return NULL;
	}
	r->id[SRV_ID_LEN - 1] = r->session_id[SRV_ID_LEN - 1] = '\0';
	r->error[sizeof r->error - 1] = '\0';
	api_problem pb;
	api_exp_ext *ext = NULL;
	if (len > sizeof *r)
		ext = (api_exp_ext *)((char *)payload + sizeof *r); /* copied by srv_exp_new */
	srv_experiment *e = srv_exp_new(&r->req, ext, srv_store_enabled() ? "" : NULL, &pb);
	if (e) {
		snprintf(e->entry.id, sizeof e->entry.id, "%s", r->id);
		snprintf(e->session_id, sizeof e->session_id, "%s",
			 r->session_id);
		e->state = r->state;
		e->cur = r->cur;
		snprintf(e->error, sizeof e->error, "%s", r->error);
		e->t0 = r->t0;
		e->t_now = r->t_now;
		e->attached = 0;
		drop_record(e);
		/* a record of a build before the segments' own end */
		if (e->state == EXP_ABORTED || e->state == EXP_INTERRUPTED)
			srv_exp_end_segments(e);
	} else {
		snprintf(why, whylen, "%s", pb.detail);
	}
	free(r);
	return e;
}

int srv_exp_interrupt(srv_experiment *e)
{
	pthread_mutex_lock(&e->lock);
	int hit = !e->attached &&
		  (e->state == EXP_RUNNING || e->state == EXP_WAITING);
	if (hit) {
		e->state = EXP_INTERRUPTED;
		snprintf(e->error, sizeof e->error,
			 "the daemon stopped before it ended and its session "
			 "could not resume it; the segments done are kept");
		srv_exp_end_segments(e);
		persist_locked(e, 0);
	}
	pthread_mutex_unlock(&e->lock);
	return hit;
}

/* The results file DIR/experiment-ID.json and the record (lock held). */
static void save_results(srv_experiment *e)
{
	if (!e->data_dir || e->deleted)
		return;
	persist_locked(e, 0);
	api_experiment_view v;
	fill_view(e, &v);
	char *text = api_experiment_json(&v);
	size_t n = text ? strlen(text) : 0;
	char *file = text ? malloc(n + 1) : NULL;
	char name[64];
	snprintf(name, sizeof name, "experiment-%s.json", e->entry.id);
	if (file) {
		memcpy(file, text, n);
		file[n] = '\n';
		queue_write(e, name, file, n + 1);
	}
	free(text);
}

void srv_exp_view(srv_experiment *e, api_experiment_view *v, srv_exp_scratch *sc)
{
	pthread_mutex_lock(&e->lock);
	fill_view(e, v);
	memcpy(sc->seg, e->req.seg, (size_t)e->req.nseg * sizeof *sc->seg);
	sc->ext = e->ext;
	pthread_mutex_unlock(&e->lock);
	v->seg = sc->seg;
	v->ext = &sc->ext;
}

double srv_exp_end(const srv_experiment *e)
{
	return e->state == EXP_RUNNING ? e->t0 + exp_end(e) : NAN;
}

srv_cmd *srv_exp_begin(srv_experiment *e, const sim_status *st,
		       double *t_end)
{
	pthread_mutex_lock(&e->lock);
	e->t0 = e->t_now = st->t;
	e->state = EXP_RUNNING;
	*t_end = srv_exp_end(e);
	if (e->ext.kind != API_EXP_SCHEDULE)
		srv_exp_clock_start(e, st);
	srv_cmd *cmd = srv_exp_start_segment(e, 0, st);
	pthread_mutex_unlock(&e->lock);
	return cmd;
}

srv_cmd *srv_exp_step(srv_experiment *e, const sim_status *st, int *over)
{
	srv_cmd *cmd = NULL;
	*over = 0;
	pthread_mutex_lock(&e->lock);
	e->t_now = st->t;
	double y;
	int sampled = srv_exp_sample(e, st, &y);
	srv_exp_follow_curve(e, st);
	if (st->t >= srv_exp_segment_end(e) - 1e-9) {
		srv_exp_finish_segment(e, st);
		if (e->cur + 1 < e->req.nseg) {
			cmd = srv_exp_start_segment(e, e->cur + 1, st);
		} else {
			e->state = EXP_DONE;
			e->attached = 0;
			drop_record(e);
			save_results(e);
			*over = 1;
		}
	} else {
		cmd = srv_exp_control(e, st, sampled, y);
	}
	pthread_mutex_unlock(&e->lock);
	return cmd;
}

/* Abort (lock held): the state and the error, the segments not done
 * ended with it, the record dropped. */
static void abort_locked(srv_experiment *e, const char *why)
{
	if (e->state == EXP_WAITING || e->state == EXP_RUNNING) {
		e->state = EXP_ABORTED;
		snprintf(e->error, sizeof e->error, "%s", why);
		srv_exp_end_segments(e);
	}
	e->attached = 0;
	drop_record(e);
	persist_locked(e, 0);
}

int srv_exp_commanded(srv_experiment *e, const srv_cmd *cmd)
{
	char why[200];
	pthread_mutex_lock(&e->lock);
	int refused = srv_exp_segment_commanded(e, cmd, why, sizeof why);
	if (refused) {
		srv_log(SRV_LOG_WARN, "experiment %s: %s", e->entry.id, why);
		abort_locked(e, why);
	}
	srv_exp_dist_commanded(e, cmd, refused);
	pthread_mutex_unlock(&e->lock);
	return refused;
}

void srv_exp_abort(srv_experiment *e, const char *why)
{
	pthread_mutex_lock(&e->lock);
	abort_locked(e, why);
	pthread_mutex_unlock(&e->lock);
}
