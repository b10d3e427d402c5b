/*
 * experiment.c - the beta-schedule experiment (POST /api/v1/experiments).
 *
 * An experiment rides on one session's worker: at each segment start the
 * worker commands the segment's beta, restarts the core's transport
 * estimator (sim_restart_transport) and notes sim_effective_time() as the
 * command time; after every advance it records the per-period feed
 * velocity (sim_status.feed_velocity). When a segment ends, its steady
 * velocity is the mean feed velocity over the segment's second half and
 * its reversal time runs from the command until the feed velocity first
 * reaches 90 % of that steady value. Fields the worker writes are guarded
 * by exp_lock, taken after the session lock; handlers read under
 * exp_lock only. Experiments are kept until shutdown (the oldest finished
 * ones are evicted beyond --max-experiments).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "srv.h"
#include "units.h"

enum { EXP_WAITING, EXP_RUNNING, EXP_DONE, EXP_ABORTED };

struct srv_experiment {
	char id[24];
	char session_id[24];
	api_experiment_req req;  /* schedule and per-segment results */
	int state;
	int attached;            /* a session worker still refers to it */
	char error[256];
	double t0, t_now;        /* s: start and latest simulated time */
	int cur;                 /* running segment */
	double *rec_t, *rec_v;   /* feed velocity record */
	size_t rec_n, rec_cap, seg_first;
	double rec_spacing;      /* s between records, at least */
	srv_experiment *next;
};

#define EXP_RECORDS 50000

static pthread_mutex_t exp_lock = PTHREAD_MUTEX_INITIALIZER;
static srv_experiment *exp_head;
static int exp_count;

void srv_experiments_init(void)
{
	exp_head = NULL;
	exp_count = 0;
}

static void exp_free(srv_experiment *e)
{
	if (!e)
		return;
	free(e->rec_t);
	free(e->rec_v);
	free(e);
}

void srv_experiments_shutdown(void)
{
	pthread_mutex_lock(&exp_lock);
	while (exp_head) {
		srv_experiment *e = exp_head;
		exp_head = e->next;
		exp_free(e);
	}
	exp_count = 0;
	pthread_mutex_unlock(&exp_lock);
}

const char *srv_exp_id(const srv_experiment *e)
{
	return e->id;
}

static double exp_end(const srv_experiment *e)
{
	return e->req.seg[e->req.nseg - 1].until;
}

static void start_segment(srv_experiment *e, int i, sim *sm,
			  const sim_status *st, srv_session *s)
{
	api_segment *seg = &e->req.seg[i];
	api_control c = {.set = API_C_BETA, .beta = seg->beta};
	if (e->req.beta_rate > 0) {
		c.set |= API_C_BETA_RATE;
		c.beta_rate = e->req.beta_rate;
	}
	seg->t_command = sim_effective_time(sm);
	sim_set_beta(sm, sim_rad_from_deg(seg->beta),
		     sim_rad_from_deg(e->req.beta_rate));
	sim_restart_transport(sm);
	seg->start_velocity = st->feed_velocity;
	seg->state = 1;
	e->cur = i;
	e->seg_first = e->rec_n;
	char json[API_EVENT_MAX];
	api_control_event(json, sizeof json, &c, seg->t_command);
	srv_session_push_event(s, "control", json);
}

static void finish_segment(srv_experiment *e, const sim_status *st)
{
	api_segment *seg = &e->req.seg[e->cur];
	seg->t_end = st->t;
	seg->mean_velocity = st->transport_velocity;
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

/* The feed-velocity record is only needed while running (exp_lock held). */
static void drop_record(srv_experiment *e)
{
	free(e->rec_t);
	free(e->rec_v);
	e->rec_t = e->rec_v = NULL;
	e->rec_n = e->rec_cap = 0;
}

static void fill_view(const srv_experiment *e, api_experiment_view *v)
{
	static const char *const names[] = {"waiting", "running", "done",
					    "aborted"};
	memset(v, 0, sizeof *v);
	snprintf(v->id, sizeof v->id, "%s", e->id);
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
	if (!srv_cfg.data_dir)
		return;
	api_experiment_view v;
	fill_view(e, &v);
	char *text = api_experiment_json(&v);
	char path[4096];
	snprintf(path, sizeof path, "%s/experiment-%s.json", srv_cfg.data_dir,
		 e->id);
	FILE *f = text ? fopen(path, "w") : NULL;
	if (f) {
		fputs(text, f);
		fputc('\n', f);
		fclose(f);
	} else {
		srv_log(SRV_LOG_WARN, "cannot write %s", path);
	}
	free(text);
}

void srv_exp_begin(srv_experiment *e, sim *sm, const sim_status *st,
		   srv_session *s)
{
	pthread_mutex_lock(&exp_lock);
	e->t0 = e->t_now = st->t;
	e->state = EXP_RUNNING;
	srv_session_extend(s, e->t0 + exp_end(e));
	start_segment(e, 0, sm, st, s);
	pthread_mutex_unlock(&exp_lock);
}

double srv_exp_boundary(const srv_experiment *e)
{
	if (e->state != EXP_RUNNING)
		return INFINITY;
	return e->t0 + e->req.seg[e->cur].until;
}

int srv_exp_step(srv_experiment *e, sim *sm, const sim_status *st,
		 srv_session *s)
{
	int over = 0;
	pthread_mutex_lock(&exp_lock);
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
			start_segment(e, e->cur + 1, sm, st, s);
		} else {
			e->state = EXP_DONE;
			e->attached = 0;
			drop_record(e);
			save_results(e);
			over = 1;
		}
	}
	pthread_mutex_unlock(&exp_lock);
	return over;
}

void srv_exp_abort(srv_experiment *e, const char *why)
{
	pthread_mutex_lock(&exp_lock);
	if (e->state == EXP_WAITING || e->state == EXP_RUNNING) {
		e->state = EXP_ABORTED;
		snprintf(e->error, sizeof e->error, "%s", why);
	}
	e->attached = 0;
	drop_record(e);
	pthread_mutex_unlock(&exp_lock);
}

/* Make room for one more (exp_lock held): evict the oldest finished. */
static int make_room(void)
{
	if (exp_count < srv_cfg.max_experiments)
		return 1;
	srv_experiment **pp = &exp_head, **victim = NULL;
	for (; *pp; pp = &(*pp)->next)
		if (!(*pp)->attached && (*pp)->state >= EXP_DONE)
			victim = pp; /* list is newest first: last is oldest */
	if (!victim)
		return 0;
	srv_experiment *v = *victim;
	*victim = v->next;
	exp_free(v);
	exp_count--;
	return 1;
}

enum MHD_Result srv_h_experiments_create(srv_req *r)
{
	enum MHD_Result res;
	api_problem pb;
	if (!srv_need_json(r, 0, &res))
		return res;
	srv_experiment *e = calloc(1, sizeof *e);
	if (!e)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	if (api_parse_experiment(r->body, r->body_len, &e->req, &pb) !=
	    API_OK) {
		exp_free(e);
		return srv_reply_problem(r, &pb, NULL);
	}
	double dur = exp_end(e);
	e->rec_cap = EXP_RECORDS;
	e->rec_spacing = dur / EXP_RECORDS;
	e->rec_t = malloc(e->rec_cap * sizeof(double));
	e->rec_v = malloc(e->rec_cap * sizeof(double));
	pthread_mutex_lock(&exp_lock);
	int room = make_room();
	if (room)
		exp_count++; /* reserve */
	pthread_mutex_unlock(&exp_lock);
	if (!room) {
		exp_free(e);
		return srv_fail(r, API_LIMIT, NULL,
				"%d experiments are running or kept "
				"(--max-experiments)", srv_cfg.max_experiments);
	}
	if (!e->rec_t || !e->rec_v) {
		api_fail(&pb, API_UNAVAILABLE, NULL, "out of memory");
		goto fail;
	}
	srv_new_id(e->id);
	e->attached = 1;
	srv_session *s;
	if (e->req.fresh) {
		s = srv_session_create(&e->req.spec, e, &pb);
		if (!s)
			goto fail;
	} else {
		s = srv_session_get(e->req.session_id);
		if (!s) {
			api_fail(&pb, API_NOTFOUND, "session",
				 "no session with id \"%.40s\"",
				 e->req.session_id);
			goto fail;
		}
		if (srv_session_attach(s, e, &pb) != API_OK) {
			srv_session_put(s);
			goto fail;
		}
	}
	snprintf(e->session_id, sizeof e->session_id, "%s",
		 srv_session_id(s));
	srv_session_put(s);
	atomic_fetch_add(&srv_stats.experiments, 1);
	api_experiment_view v;
	char location[96];
	pthread_mutex_lock(&exp_lock);
	e->next = exp_head;
	exp_head = e;
	fill_view(e, &v);
	char *text = api_experiment_json(&v);
	pthread_mutex_unlock(&exp_lock);
	snprintf(location, sizeof location, "/api/v1/experiments/%s", e->id);
	return srv_reply(r, 201, "application/json", text,
			 MHD_HTTP_HEADER_LOCATION, location);
fail:
	pthread_mutex_lock(&exp_lock);
	exp_count--;
	pthread_mutex_unlock(&exp_lock);
	exp_free(e);
	return srv_reply_problem(r, &pb, NULL);
}

enum MHD_Result srv_h_experiment_get(srv_req *r)
{
	char *text = NULL;
	int found = 0;
	pthread_mutex_lock(&exp_lock);
	for (srv_experiment *e = exp_head; e; e = e->next)
		if (strcmp(e->id, r->arg[0]) == 0) {
			api_experiment_view v;
			fill_view(e, &v);
			text = api_experiment_json(&v);
			found = 1;
			break;
		}
	pthread_mutex_unlock(&exp_lock);
	if (!found)
		return srv_fail(r, API_NOTFOUND, NULL,
				"no experiment with id \"%.40s\"", r->arg[0]);
	return srv_reply_json(r, 200, text);
}

enum MHD_Result srv_h_experiments_list(srv_req *r)
{
	pthread_mutex_lock(&exp_lock);
	api_experiment_view *v = calloc((size_t)exp_count + 1, sizeof *v);
	size_t n = 0;
	for (srv_experiment *e = exp_head; v && e; e = e->next)
		fill_view(e, &v[n++]);
	char *text = v ? api_experiment_list_json(v, n) : NULL;
	pthread_mutex_unlock(&exp_lock);
	free(v);
	return srv_reply_json(r, 200, text);
}
