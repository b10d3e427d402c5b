/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_int.h - an experiment as experiment.c and
 * experiment_segment.c see it (the rest of the daemon has experiment.h).
 */
#ifndef CONVSIM_EXPERIMENT_INT_H
#define CONVSIM_EXPERIMENT_INT_H

#include <pthread.h>

#include "experiment.h"

/* Feed-velocity records an experiment keeps at most. */
#define EXP_RECORDS 50000

enum {
	EXP_WAITING,
	EXP_RUNNING,
	EXP_DONE,
	EXP_ABORTED,
	EXP_INTERRUPTED, /* running when the daemon died, not resumed */
	EXP_ERROR,       /* its result could not be written */
	EXP_DAMAGED,     /* its record could not be read back */
	EXP_NSTATES
};

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
	int cmd_starts;          /* cmd starts a segment (else a controller
				    sample or a disturbance) */
	int dist_from, dist_to;  /* cmd carries disturbances [from, to) */
	double beta_sent;        /* rad: the last beta commanded */
	api_exp_ext ext;         /* identify or control (experiment_kind.c,
				    experiment_loop.c) */
	int curve_rot;           /* control: the rotation and omega_ss (rad/s) */
	double curve_omega;      /* ext's v(beta) curve is for (0 after a
				    restore: looked up at the next step) */
	int writes;              /* queued store writes (they refer to e) */
	int freed;               /* srv_exp_free came while writes > 0 */
	int deleted;             /* a DELETE came (srv_exp_cancel) */
	double measured_cpu;     /* CPU s its request's thread spent measuring
				    (srv_exp_ready; not stored) */
};

/* The worker's answer to e's command (lock held): a command that starts a
 * segment sets its t_command and the end of the one before; a refusal
 * writes why (the segment or disturbance refused) and returns 1. */
int srv_exp_segment_commanded(srv_experiment *e, const srv_cmd *cmd, char *why, size_t whylen);
/* An experiment that ends early (aborted, interrupted) ends every segment
 * not done with it, so that none shows pending or running for ever (lock
 * held, or e not yet shared). */
void srv_exp_end_segments(srv_experiment *e);
/* Start segment i at status st (lock held): its command for the worker. */
srv_cmd *srv_exp_start_segment(srv_experiment *e, int i, const sim_status *st);
/* The running segment ends at status st (lock held): its mean and steady
 * velocity and its reversal time from the feed-velocity record. */
void srv_exp_finish_segment(srv_experiment *e, const sim_status *st);

/* A stored request read back (experiments/ID.bin, or a session's
 * checkpoint), with the segment it was at, before anything reads it: the
 * session's model as api_check_model has it, 1 to API_EXP_MAX_SEGMENTS
 * segments, each a finite beta, a state and an end after the one before,
 * cur one of them, the beta rate finite and not negative; its strings cut
 * at their size. 0, or -1 with the reason in why. */
int srv_exp_req_check(api_experiment_req *req, int cur, char *why, size_t whylen);
/* The running segment's end (s, simulated; INFINITY when not running). */
double srv_exp_segment_end(const srv_experiment *e);
/* The bytes of e's kind that follow its stored record (0 for a plain
 * schedule: its record is what it was before there were kinds), and a
 * tail read back checked: 0 when it is one (or len is 0). */
size_t srv_exp_tail_len(const srv_experiment *e);
int srv_exp_tail_ok(const void *tail, size_t len);
/* The disturbances e's command carried were applied (unless refused). */
void srv_exp_dist_commanded(srv_experiment *e, const srv_cmd *cmd, int refused);

/* ---- identify and control (experiment_kind.c, experiment_loop.c) ---- */

/* s measured per point of a v(beta) curve (and per slope) after the
 * transient; s per segment of the identification behind "auto" gains
 * (settle, +d, back, -d, back: five). */
#define SRV_EXP_CURVE_WINDOW 2.0
#define SRV_EXP_SCRATCH_HOLD 1.5
/* Whether the v(beta) curve of spec's scene is in the cache now; whether
 * a and b have the same curve (experiment_kind.c). */
int srv_exp_curve_cached(const api_spec *spec);
int srv_exp_same_curve(const api_spec *a, const api_spec *b);
/* The scenes x's scheduled disturbances of rotation or omega_ss lead to,
 * in their order (each from the one before), into out (room for
 * API_EXP_MAX_DIST); their count. */
int srv_exp_dist_specs(const api_exp_ext *x, const api_spec *spec, api_spec *out);
/* What e's measurements before it runs would cost the request's thread
 * (experiment_cost.c: the runs srv_exp_prepare makes that the curve cache
 * does not spare, estimated as budget_cost.c's), into *estimate (CPU s).
 * With a fresh session's settling after them (its estimate) beyond
 * --max-cpu-seconds: 422 budget "cpu" naming identify.beta (the
 * most operating points that fit as max), session.scene.columns (a fresh
 * session: the most columns that fit, where any does) or session (a
 * running one's scene), nothing measured or changed. */
api_err srv_exp_measuring_check(const srv_experiment *e, const api_spec *spec, double *estimate,
				api_problem *pb);

/* Before the experiment runs (the request's thread, spec: its session's
 * scene): the v(beta) curve and its branch, the setpoints checked and
 * their feedforward beta, "auto" gains; an identification's comparison
 * slopes; each measurement stopped once this thread's CPU clock passes
 * deadline (srv_thread_cpu; the scheduled disturbances' curves are then
 * left to the worker). API_OK or the problem (422 naming the field;
 * srv_exp_stopped's where a measurement was stopped). */
api_err srv_exp_prepare(srv_experiment *e, const api_spec *spec, double deadline,
			api_problem *pb);
/* The refusal of e's measurements stopped at --max-cpu-seconds
 * (deadline: where the request's thread reached it): 422 budget "cpu"
 * with the CPU spent and the limit, naming session.integrator.method
 * (a fresh session; the methods of a fixed step as choices) or session
 * where the method is adaptive (no estimate knows its steps), else
 * identify.beta, session.scene.columns or session as
 * srv_exp_measuring_check; nothing started. Returns API_RANGE. */
api_err srv_exp_stopped(const srv_experiment *e, const api_spec *spec, double deadline,
			api_problem *pb);
/* A closed loop whose session's rotation or omega_ss (status st) is no
 * longer its curve's (lock held): the curve of the scene as it is now,
 * from the cache or measured, its branch taken up (the integral reset,
 * the pending setpoints' feedforward redone). */
void srv_exp_follow_curve(srv_experiment *e, const sim_status *st);
/* A curve just taken up at status st (lock held): the operating point
 * (the running setpoint's feedforward on it) and the curve's slope there,
 * "auto" gains re-tuned by SIMC from that slope with the identification's
 * T and L (given gains kept), listed in curves. */
void srv_exp_retune(srv_experiment *e, const sim_status *st);
/* The feedforward beta (rad) of velocity v on the branch (clamped to its
 * ends). */
double srv_exp_feedforward(const api_exp_ext *ext, double v);
/* A FOPDT model of the per-period feed velocity record (t, v: n samples,
 * one value held per period; NaN skipped) from t_from on, for m steps at
 * ts of d deg, span the hold (s): into *out (gain, time constant, dead
 * time, their errors, v0, rms, samples, ok). */
void srv_exp_fit(const double *t, const double *v, size_t n, double t_from, const double *ts,
		 const double *d, int m, double span, api_fopdt *out);
/* The period clock of identify and control (experiment_loop.c): the
 * excitation period of status st (s); one tick: the mean feed velocity
 * since the last tick last[0..2] (t s, feed displacement m, rotor phase
 * rad; last[0] < 0: none, NaN returned), *period re-measured, last
 * updated. */
double srv_exp_period_of(const sim_status *st);
double srv_exp_clock_tick(double *period, double *last, const sim_status *st);
/* The clock starts at the experiment's start (lock held). */
void srv_exp_clock_start(srv_experiment *e, const sim_status *st);
/* After each advance (lock held): a schedule records the core's feed
 * velocity (0); identify and control at a sample time: 1, the sample in
 * *v and in the record. */
int srv_exp_sample(srv_experiment *e, const sim_status *st, double *v);
/* The controller at status st (lock held), y the sample when sampled: the
 * command to send (beta, with a disturbance due) or NULL. */
srv_cmd *srv_exp_control(srv_experiment *e, const sim_status *st, int sampled, double y);
/* The next time (s, simulated) a sample or a disturbance needs the worker
 * to stop at, or INFINITY. */
double srv_exp_control_boundary(const srv_experiment *e);
/* A segment of a closed loop ends (lock held): its setpoint's results and
 * those of the disturbances applied within it. */
void srv_exp_control_results(srv_experiment *e);
/* An identification's operating point whose last segment just ended (lock
 * held): its model. */
void srv_exp_identify_results(srv_experiment *e);

#endif
