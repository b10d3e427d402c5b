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
 * steady value. Fields are guarded by the experiment's lock, taken inside
 * the session lock by the worker's hooks and alone by the handlers (lock
 * order: registry.h).
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "util.h"

enum { EXP_WAITING, EXP_RUNNING, EXP_DONE, EXP_ABORTED };

struct srv_experiment {
	srv_entry entry;         /* id and references: experiment_http.c */
	const char *data_dir;    /* borrowed; NULL: results are not saved */
	pthread_mutex_t lock;
	/* guarded by lock */
	char session_id[SRV_ID_LEN];
	api_experiment_req req;  /* schedule and per-segment results */
	int state;
	int attached;            /* a session worker still refers to it */
	char error[256];
	double t0, t_now;        /* s: start and latest simulated time */
	int cur;                 /* running segment */
	double *rec_t, *rec_v;   /* feed velocity record */
	size_t rec_n, rec_cap, seg_first;
	double rec_spacing;      /* s between records, at least */
	srv_cmd cmd;             /* the running segment's command */
};

#define EXP_RECORDS 50000

static double exp_end(const srv_experiment *e)
{
	return e->req.seg[e->req.nseg - 1].until;
}

srv_experiment *srv_exp_new(const api_experiment_req *req,
			    const char *data_dir, api_problem *pb)
{
	srv_experiment *e = calloc(1, sizeof *e);
	if (!e) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	e->req = *req;
	e->data_dir = data_dir;
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

void srv_exp_free(srv_experiment *e)
{
	if (!e)
		return;
	free(e->rec_t);
	free(e->rec_v);
	pthread_mutex_destroy(&e->lock);
	free(e);
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

/* Start segment i at status st (lock held): its command for the worker. */
static srv_cmd *start_segment(srv_experiment *e, int i, const sim_status *st)
{
	api_segment *seg = &e->req.seg[i];
	srv_cmd *cmd = &e->cmd;
	memset(cmd, 0, sizeof *cmd);
	cmd->c.set = API_C_BETA;
	cmd->c.beta = seg->beta;
	if (e->req.beta_rate.si > 0) {
		cmd->c.set |= API_C_BETA_RATE;
		cmd->c.beta_rate = e->req.beta_rate;
	}
	cmd->restart_transport = 1;
	cmd->from_experiment = 1;
	seg->start_velocity = st->feed_velocity;
	seg->state = 1;
	e->cur = i;
	e->seg_first = e->rec_n;
	return cmd;
}

static void finish_segment(srv_experiment *e, const sim_status *st)
{
	api_segment *seg = &e->req.seg[e->cur];
	seg->t_end = st->t;
	/* the estimator restarted at the segment's command */
	seg->mean_velocity = st->transport_velocity;
	seg->uncertainty = st->transport_velocity_uncertainty;
	seg->steady = st->steady;
	double half = seg->t_command + 0.5 * (seg->t_end - seg->t_command);
	double sum = 0;
	size_t n = 0;
	for (size_t i = e->seg_first; i < e->rec_n; i++)
		if (e->rec_t[i] >= half) {
			sum += e->rec_v[i];
			n++;
		}
	double steady = n ? sum / (double)n : NAN;
	seg->steady_velocity = steady;
	seg->reversal_time = NAN;
	if (isfinite(steady) && steady != 0)
		for (size_t i = e->seg_first; i < e->rec_n; i++) {
			double v = e->rec_v[i];
			if (e->rec_t[i] >= seg->t_command &&
			    (steady > 0 ? v >= 0.9 * steady
					: v <= 0.9 * steady)) {
				seg->reversal_time = e->rec_t[i] - seg->t_command;
				break;
			}
		}
	seg->state = 2;
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
	static const char *const names[] = {"waiting", "running", "done",
					    "aborted"};
	memset(v, 0, sizeof *v);
	snprintf(v->id, sizeof v->id, "%s", e->entry.id);
	snprintf(v->session_id, sizeof v->session_id, "%s", e->session_id);
	v->state = names[e->state];
	snprintf(v->error, sizeof v->error, "%s", e->error);
	v->t_start = e->t0;
	v->t_now = e->t_now;
	double p = e->state == EXP_WAITING ? 0 : (e->t_now - e->t0) / exp_end(e);
	v->progress = e->state == EXP_DONE ? 1 : p < 0 ? 0 : p > 1 ? 1 : p;
	v->nseg = e->req.nseg;
	v->seg = e->req.seg;
}

static void save_results(const srv_experiment *e)
{
	if (!e->data_dir)
		return;
	api_experiment_view v;
	fill_view(e, &v);
	char *text = api_experiment_json(&v);
	char name[64];
	snprintf(name, sizeof name, "experiment-%s.json", e->entry.id);
	srv_write_file(e->data_dir, name, text, 1);
	free(text);
}

void srv_exp_view(srv_experiment *e, api_experiment_view *v,
		  api_segment *seg)
{
	pthread_mutex_lock(&e->lock);
	fill_view(e, v);
	memcpy(seg, e->req.seg, (size_t)e->req.nseg * sizeof *seg);
	pthread_mutex_unlock(&e->lock);
	v->seg = seg;
}

srv_cmd *srv_exp_begin(srv_experiment *e, const sim_status *st,
		       double *t_end)
{
	pthread_mutex_lock(&e->lock);
	e->t0 = e->t_now = st->t;
	e->state = EXP_RUNNING;
	*t_end = e->t0 + exp_end(e);
	srv_cmd *cmd = start_segment(e, 0, st);
	pthread_mutex_unlock(&e->lock);
	return cmd;
}

double srv_exp_boundary(const srv_experiment *e)
{
	if (e->state != EXP_RUNNING)
		return INFINITY;
	return e->t0 + e->req.seg[e->cur].until;
}

srv_cmd *srv_exp_step(srv_experiment *e, const sim_status *st, int *over)
{
	srv_cmd *cmd = NULL;
	*over = 0;
	pthread_mutex_lock(&e->lock);
	e->t_now = st->t;
	if (isfinite(st->feed_velocity) && e->rec_n < e->rec_cap &&
	    (e->rec_n == 0 ||
	     st->t - e->rec_t[e->rec_n - 1] >= e->rec_spacing)) {
		e->rec_t[e->rec_n] = st->t;
		e->rec_v[e->rec_n++] = st->feed_velocity;
	}
	if (st->t >= srv_exp_boundary(e) - 1e-9) {
		finish_segment(e, st);
		if (e->cur + 1 < e->req.nseg) {
			cmd = start_segment(e, e->cur + 1, st);
		} else {
			e->state = EXP_DONE;
			e->attached = 0;
			drop_record(e);
			save_results(e);
			*over = 1;
		}
	}
	pthread_mutex_unlock(&e->lock);
	return cmd;
}

/* Abort (lock held): the state and the error, the record dropped. */
static void abort_locked(srv_experiment *e, const char *why)
{
	if (e->state == EXP_WAITING || e->state == EXP_RUNNING) {
		e->state = EXP_ABORTED;
		snprintf(e->error, sizeof e->error, "%s", why);
	}
	e->attached = 0;
	drop_record(e);
}

int srv_exp_commanded(srv_experiment *e, const srv_cmd *cmd)
{
	pthread_mutex_lock(&e->lock);
	api_segment *seg = &e->req.seg[e->cur];
	int refused = cmd->rc != SIM_OK;
	if (refused) {
		char why[200];
		snprintf(why, sizeof why,
			 "segment %d: the session refused beta = %g deg: %s",
			 e->cur, seg->beta.user, sim_strerror(cmd->rc));
		srv_log(SRV_LOG_WARN, "experiment %s: %s", e->entry.id, why);
		abort_locked(e, why);
	} else {
		seg->t_command = cmd->t_eff;
	}
	pthread_mutex_unlock(&e->lock);
	return refused;
}

void srv_exp_abort(srv_experiment *e, const char *why)
{
	pthread_mutex_lock(&e->lock);
	abort_locked(e, why);
	pthread_mutex_unlock(&e->lock);
}
