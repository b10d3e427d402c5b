/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * api_jobs.h - the JSON face of the daemon's jobs: experiments, sweeps and
 * fits (their requests parsed and checked, their views written as JSON and
 * CSV) and one listing gathered from several replicas. Part of api.h,
 * which includes it at its end: include api.h.
 */
#ifndef CONVSIM_API_JOBS_H
#define CONVSIM_API_JOBS_H

#include "api.h"
#include "fit.h"
#include "study.h"

/* ---- experiments --------------------------------------------------------- */

#define API_EXP_MAX_SEGMENTS 32
/* A segment's state. ABORTED: the experiment ended early (aborted with its
 * session, or interrupted) before this segment was done. */
typedef enum api_seg_state {
	API_SEG_PENDING,
	API_SEG_RUNNING,
	API_SEG_DONE,
	API_SEG_ABORTED,
	API_SEG_NSTATES
} api_seg_state;
/* The state's name in JSON and CSV ("pending" for one out of range). */
const char *api_segment_state(int state);
typedef struct api_segment {
	api_value beta;         /* rad (deg as sent) commanded at the start */
	double until;           /* s after the experiment start */
	/* results, filled by the server */
	int state;              /* api_seg_state */
	int beta_same;          /* 1: beta was already there at the command,
				 * so there is no reversal to time (fills the
				 * padding: saved records keep their size) */
	double t_command;       /* s simulated time of the beta command */
	double t_end;           /* s */
	double steady_velocity; /* m/s mean feed velocity, last half */
	double mean_velocity;   /* m/s transport estimate over the segment */
	double uncertainty;     /* m/s error bar of mean_velocity; NaN if none */
	int steady;             /* the estimate showed no drift at the end */
	double reversal_time;   /* s command -> 90 % of steady; NaN if never or
				 * without a beta change (beta_same) */
	double start_velocity;  /* m/s feed velocity at the command */
} api_segment;

typedef struct api_experiment_req {
	int fresh;              /* 1: create a session from spec */
	api_spec spec;
	char session_id[24];    /* fresh == 0 */
	api_value beta_rate;    /* rad/s (deg/s as sent), 0 = keep */
	int keep_session;       /* a fresh session stays after the end */
	int nseg;
	api_segment seg[API_EXP_MAX_SEGMENTS];
} api_experiment_req;

/* seg as a request leaves it: beta (rad, deg as sent) until s, its
 * results not measured yet (NaN, state pending). */
void api_segment_reset(api_segment *seg, api_value beta, double until);

/* An experiment's kind beyond its schedule (docs/control.md): an
 * identification (steps of beta around operating points, a first-order-
 * plus-dead-time model fitted per point) or a closed loop (a PI controller
 * on beta holding transport-velocity setpoints), with disturbances
 * scheduled on the session. Kept beside api_experiment_req, whose layout
 * the stored records copy (server/store/records.h): a record of a plain
 * schedule is what it was. */
enum { API_EXP_SCHEDULE, API_EXP_IDENTIFY, API_EXP_CONTROL };
#define API_EXP_MAX_POINTS 4    /* operating points of an identification */
#define API_EXP_ID_SEGS 5       /* segments per point: settle, +d, 0, -d, 0 */
#define API_EXP_MAX_DIST 8
#define API_EXP_DIST_LEN 200    /* a disturbance's "set" object as sent */
#define API_FF_NODES 73         /* the v(beta) curve: 0..180 deg by 2.5 */
typedef struct api_fopdt {
	double beta0, step;     /* deg: the operating point and the step */
	double k, k_se;         /* m/s per deg */
	double t, t_se;         /* s: time constant */
	double l, l_se;         /* s: dead time */
	double v0, rms;         /* m/s: velocity at beta0, residual */
	double slope;           /* m/s per deg: the v(beta) curve's secant
				   over beta0 -+ step (NaN: no curve) */
	double t_from;          /* s after the start: the first step */
	int n, ok;              /* samples fitted; 0: no model */
} api_fopdt;
typedef struct api_setpoint {
	double v;               /* m/s */
	double settling_time;   /* s from the segment start until v stays
				   within 2 % of the setpoint; NaN: never */
	double overshoot;       /* beyond the setpoint, a fraction of the
				   step (0 without one) */
	double iae;             /* m: integral of |setpoint - v| dt */
	double steady_error;    /* |mean v over the last quarter - setpoint|
				   / |setpoint| */
} api_setpoint;
typedef struct api_disturbance {
	double at;              /* s after the experiment start */
	char set[API_EXP_DIST_LEN]; /* the "set" object as a PATCH body */
	double t_applied;       /* s simulated; NaN before */
	double recovery_time;   /* s from t_applied until v stays within 2 %
				   of the setpoint again; NaN: never */
	double max_deviation;   /* m/s: the largest |setpoint - v| after it */
	int applied;
	int pad;
} api_disturbance;
#define API_EXP_MAX_CURVES 6   /* curve changes listed (all are counted) */
typedef struct api_curve_change {
	double t;               /* s after the start: taken up at this sample */
	double omega_ss;        /* rad/s: the new scene's */
	int rotation;           /* SIM_CW or SIM_CCW */
	int retuned;            /* 1: "auto" gains re-tuned from the slope */
	double beta0;           /* deg: the operating point, the running
				   setpoint's feedforward on the new curve */
	double slope;           /* m/s per deg: the new curve's secant over
				   beta0 -+ the identification's step */
	double kp, ki;          /* the gains in use from then on */
} api_curve_change;
/* A closed loop's gains after curve changes, in the bytes of an
 * identification's models (a union: a closed loop's are zero in records
 * from before, which read back as no change). */
typedef struct api_loop_gains {
	double kp, ki;          /* in use; 0, 0: the controller's kp, ki */
	int n, pad;             /* entries in curves: the first changes, then
				   the last one in the last entry */
	api_curve_change curves[API_EXP_MAX_CURVES];
} api_loop_gains;
typedef struct api_exp_ext {
	int kind;               /* API_EXP_* */
	int npoints;            /* identify: operating points */
	double id_step, id_hold; /* deg, s */
	union {
		api_fopdt model[API_EXP_MAX_POINTS]; /* identify */
		api_loop_gains gains;                /* control */
	};
	/* control */
	int auto_gains;         /* "controller": "auto" (SIMC) */
	int branch_sign;        /* sign of dv/dbeta on the branch */
	double kp, ki;          /* deg per m/s, deg per m */
	double tau_c;           /* s: SIMC's closed-loop time constant */
	api_fopdt tuned;        /* the identification behind "auto" */
	api_setpoint sp[API_EXP_MAX_SEGMENTS];
	int ndist;
	int nff;                /* nodes of the branch's v(beta) curve */
	api_disturbance dist[API_EXP_MAX_DIST];
	double ff_beta[API_FF_NODES], ff_v[API_FF_NODES]; /* rad, m/s */
	double v_lo, v_hi;      /* m/s: the branch's reachable range */
	double beta_lo, beta_hi; /* rad: the branch's ends */
	/* the sampler's and the controller's state (the server's, kept for a
	 * restore): one sample per excitation period, the mean feed velocity
	 * over the period since the last one */
	double period;          /* s: the last period, the next sample's wait */
	double last_t, last_x, last_psi; /* the last sample: s, m, rad (the
				   rotor's phi - alpha); last_t < 0: none */
	double integ;           /* deg */
	double t_sample;        /* s after the start: the next sample */
	int next_dist;
	int curve_changes;      /* new v(beta) curves taken up while running
				   (rotation or omega_ss changed; was padding:
				   0 in records from before) */
} api_exp_ext;
/* The gains a closed loop x had in use at t (s after its start): its
 * controller's, or the last curve change's at or before t. */
void api_loop_gains_at(const api_exp_ext *x, double t, double *kp, double *ki);

/* Parse POST /experiments: {"session": ID} or {"session": {create body}}
 * (or none: a fresh czubak2016 session at pace "max"), "schedule":
 * [{"beta": DEG, "until": S}, ...] with increasing until, optional
 * "beta_rate" and "keep_session" (a fresh session is removed when the
 * experiment ends unless true). Returns API_OK or the error in *pb. */
api_err api_parse_experiment(const char *body, size_t len,
			     api_experiment_req *req, api_exp_ext *ext, api_problem *pb);


typedef struct api_experiment_view {
	char id[24];
	char session_id[24];
	const char *state;      /* waiting, running, done, aborted,
				   interrupted, error */
	char error[256];
	double t_start, t_now;  /* s simulated */
	double progress;        /* 0..1 */
	int nseg;
	const api_segment *seg; /* borrowed */
	const api_spec *spec;   /* borrowed, may be NULL: the session's scene,
				   each segment's model error at its beta */
	const api_exp_ext *ext; /* borrowed, may be NULL: a plain schedule */
} api_experiment_view;
char *api_experiment_json(const api_experiment_view *v);
/* {"experiments": [...]} of n views. malloc'd text. */
char *api_experiment_list_json(const api_experiment_view *v, size_t n);
/* The segments of n experiments as CSV, one row each (API_EXPERIMENT_CSV
 * columns; the model error's cells empty where the view has no spec).
 * malloc'd text. */
#define API_EXPERIMENT_CSV                                                            \
	"experiment,session,segment,beta,until,state,t_command,t_end,start_velocity,"   \
	"steady_velocity,mean_velocity,uncertainty,steady,reversal_time," SIM_MODEL_ERROR_COLUMNS
/* Experiments that are all identifications add the operating point's model
 * to each of its segments' rows, all closed loops each setpoint's
 * results (a mixed list has the plain columns). */
#define API_EXPERIMENT_CSV_IDENTIFY \
	",operating_point,gain,gain_se,time_constant,time_constant_se,dead_time,dead_time_se"
#define API_EXPERIMENT_CSV_CONTROL ",setpoint,settling_time,overshoot,iae,steady_error,kp,ki"
char *api_experiment_csv(const api_experiment_view *v, size_t n);

/* ---- sweeps --------------------------------------------------------------- */

#define API_SWEEP_MAX_POINTS 2000
#define API_SWEEP_NAME_LEN 24
typedef struct api_sweep_req {
	api_spec spec;
	int nbeta;             /* points per rotation sense */
	api_value *betas;      /* rad (deg as sent), each point's beta (the
				  model's where beta is not varied), malloc'd
				  by the parser (caller frees) */
	int nrot;
	int rotations[2];      /* SIM_CW / SIM_CCW */
	double t_end;          /* s simulated per point */
	/* the varied settings, in their order ("beta" alone for a v(beta)
	 * sweep), each point's values in api_sweep_point.vary */
	int nvary;
	char vary[SIM_STUDY_MAX_AXES][API_SWEEP_NAME_LEN];
	int lhs;               /* a Latin-hypercube sample of lhs points, or 0 */
	uint32_t seed;
	double *values;        /* nbeta x nvary user values, malloc'd by the
				  parser (caller frees; not kept after the
				  points are made) */
	/* bands from a fit ("band_from_fit": its id): the parser keeps the
	 * id; the daemon finds the fit, reads its result into band_src and
	 * prepares spec for it (fit_band_source_prepare: band_skip) */
	char band_fit[API_SWEEP_NAME_LEN];
	int band;              /* 1: every point gets a band */
	fit_band_source band_src;
	int band_skip[FIT_MAX_FREE];
} api_sweep_req;
/* Default simulated time per point after scene.transient, s: after a steady
 * start, a 4-s window keeps all 74 points of the czubak2016 v(beta) within
 * 1 % (docs/MODEL.md's convention). */
#define API_SWEEP_WINDOW 4.0
/* The most simulated time per point, s. */
#define API_SWEEP_T_END_MAX 600.0
/* Parse POST /sweeps: preset/params/scene/integrator as for sessions,
 * "beta": {"from","to","step"} or [DEG, ...], "rotations": ["cw","ccw"],
 * "t_end" (default scene.transient + API_SWEEP_WINDOW; it must exceed
 * scene.transient, each point's where a study varies it); a study: "vary": {"NAME": {"from","to","step"} or
 * [v, ...], ...} over number settings in their user units (beta, when
 * given as "beta", the first), "lhs": N for a Latin-hypercube sample of
 * the ranges, "seed" (core/study.h); "band_from_fit": a fit's id (the
 * daemon resolves it: req->band_fit). A 4xx names the field ("vary.mu")
 * and its range; nothing is kept then. */
api_err api_parse_sweep(const char *body, size_t len, api_sweep_req *req,
			api_problem *pb);

typedef struct api_sweep_point {
	api_value beta;  /* rad (deg as sent) */
	int rotation;    /* SIM_CW / SIM_CCW */
	int state;       /* 0 pending, 1 running, 2 done, 3 failed */
	sim_measurement m; /* when done: v and its error bar (NaN if none),
			      steady, the steps it was measured with, the
			      steps' share of the bar and whether it is
			      within tol (sim.h) */
	int mirrored;       /* the mirror image of another point of the sweep
			       (sim_mirror_plan), not run itself */
	char error[160];
	double vary[SIM_STUDY_MAX_AXES]; /* the varied settings' values, user
					    units (api_sweep_req.vary) */
	double band[2];     /* req.band, when done: the 95 % band, m/s */
} api_sweep_point;
typedef struct api_sweep_view {
	char id[24];
	const char *state;  /* queued, running, done, cancelled, error, damaged */
	const char *error;  /* why "error" (a write failed) or "damaged" (its
			       record is unusable); NULL or "" */
	size_t total, done;
	double t_end;
	const api_sweep_req *req;  /* borrowed: the varied settings */
	const api_sweep_point *pt; /* borrowed, total entries */
} api_sweep_view;
char *api_sweep_json(const api_sweep_view *v);
char *api_sweep_csv(const api_sweep_view *v);
/* n sweeps as CSV, one row each: sweep, state, done, total, t_end. */
char *api_sweep_list_csv(const api_sweep_view *v, size_t n);
/* {"sweeps": [...]} of n views without their points. malloc'd text. */
char *api_sweep_list_json(const api_sweep_view *v, size_t n);

/* ---- listings across replicas (--peers) ------------------------------------ */

/* One listing gathered from several replicas (list_json.c). */
typedef struct api_list api_list;
/* Start from the receiving replica's own listing (borrowed text): JSON
 * with the array member `member` ("sessions", "experiments", "sweeps"),
 * or CSV. NULL when that text is not such a listing or out of memory. */
api_list *api_list_new(const char *member, int csv, const char *local);
/* Append a peer's listing of the same kind (len bytes). Returns 0, or -1
 * if it is not one (nothing appended): report the peer unreachable. */
int api_list_add(api_list *l, const char *body, size_t len);
/* Name a peer whose entries are missing (JSON: the "unreachable" member;
 * CSV carries no such member: the server says it in a header). */
void api_list_unreachable(api_list *l, const char *peer, const char *reason);
/* The merged text (malloc'd; NULL if out of memory); frees l (NULL is
 * accepted). */
char *api_list_finish(api_list *l);

/* ---- fits ------------------------------------------------------------------ */

/* Parse POST /fits: preset/params/scene/integrator as for sessions, "free"
 * (names, or {name, min, max, start} in the setting's unit), the data as
 * "points" [{beta, rotation, v, sigma}], "csv" (text with the header
 * beta,rotation,v[,sigma]) or "peaks" [{rotation, beta, sigma}], and
 * "t_end", "curve_step" (deg), "max_iter", "fd_step". Checked whole with
 * fit_check: a 422 naming the field, nothing started. *points (malloc'd,
 * the caller frees; req->points points into it) holds the points. */
api_err api_parse_fit(const char *body, size_t len, fit_request *req, fit_point **points,
		      api_problem *pb);

typedef struct api_fit_view {
	char id[24];
	const char *state;        /* queued, running, done, failed, cancelled,
				     error */
	const fit_request *req;   /* borrowed */
	fit_progress pr;          /* the last report (phase NULL before one) */
	const char *result;       /* fit_result_json's text when over, or NULL */
	const char *error;        /* why "error" (its record could not be
				     written); NULL or "" */
} api_fit_view;
/* One fit: progress, current values and the result (null until over). */
char *api_fit_json(const api_fit_view *v);
/* {"fits": [...]} without results; CSV: fit,state,phase,iteration,
 * evaluations,cost. malloc'd text. */
char *api_fit_list_json(const api_fit_view *v, size_t n);
char *api_fit_list_csv(const api_fit_view *v, size_t n);

#endif
