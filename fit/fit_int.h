/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_int.h - inside the fit module: the batch evaluator that fit.c's
 * least-squares driver calls (fit_eval.c). Not for callers of fit.h.
 */
#ifndef CONVSIM_FIT_INT_H
#define CONVSIM_FIT_INT_H

#include <pthread.h>

#include "fit.h"

/* Evaluates the model's data (v at the points, or the peaks' beta) for
 * sets of free-parameter values. One sim_measure per unit: a point, or
 * one beta of a peak's scan grid. */
typedef struct fit_eval {
	const fit_request *req;
	size_t ndata;            /* points or peaks */
	size_t nunits;           /* units per parameter set */
	int ngrid;               /* peaks: grid points per scan */
	double *ubeta;           /* rad, nunits */
	int *urot;
	pthread_mutex_t lock;
	long evaluations;        /* lock */
	double cpu_seconds;      /* lock */
	int failed;              /* lock: 1 failed (error), 2 cancelled */
	char error[FIT_MSG];     /* lock */
} fit_eval;

/* Prepare the units of req (borrowed for ev's life). 0, or -1 when out of
 * memory. */
int fit_eval_init(fit_eval *ev, const fit_request *req);
void fit_eval_free(fit_eval *ev);

/* The data for nsets parameter sets xs[s * nfree + j] (SI), in one
 * parallel batch: out[s * ndata + d] (m/s, or rad for peaks) and its
 * uncertainty out_u (may be NULL). 0, or -1: ev->failed says why. */
int fit_eval_data(fit_eval *ev, size_t nsets, const double *xs, double *out, double *out_u);

/* v and its error bar at n (beta, rotation) for nsets parameter sets, in
 * one batch: v[s * n + i]. 0 or -1 as fit_eval_data. */
int fit_eval_curve(fit_eval *ev, size_t nsets, const double *xs, size_t n, const double *beta,
		   const int *rotation, double *v, double *u);

/* ---- the solver's state (fit.c), its statistics (fit_cov.c) ---------- */

/* A start on a bound moves this fraction of the width inside; a fit
 * within twice it of a bound "ends at the bound". */
#define BOUND_NEAR 1e-3

typedef struct fit_ctx {
	const fit_request *req;
	fit_eval ev;
	fit_result *res;
	int p;
	size_t n;
	int q;                /* priors: the residuals' rows n .. n + q - 1 */
	int prior_of[FIT_MAX_FREE]; /* the free parameter of prior row n + k */
	double *w;            /* per datum: sigma or 1 */
	double *data;         /* per datum: v or peak beta */
	/* the last f evaluation at an x, and the last Jacobian */
	double fx[FIT_MAX_FREE], *fmodel, *fmodel_u;
	int fvalid;
	double jx[FIT_MAX_FREE], *jac_x; /* (n + q) x p, weighted, in x: the
					  * data's rows, then the priors' */
	double *jmodel, *jmodel_u;       /* the model at jx */
	int jvalid;
	int iteration;
	int trials, stalled;  /* f evaluations in this iteration; gave up */
	/* the lowest cost seen at any f evaluation, where, and the model there */
	double best_cost, best_x[FIT_MAX_FREE], *best_model, *best_model_u;
	char why[FIT_MSG];    /* the last reason a set could not be evaluated */
} fit_ctx;

/* (fit_try.c) The data at nsets parameter sets xs[s * p + j] (SI) in one batch, as
 * fit_eval_data, but a set that cannot be evaluated (the model fails, a
 * peak is not found, the request's veto) is not the end: ok[s] = 0 for
 * it (its out NaN) and c->why says why. 0, or -1 when cancelled or out of
 * memory (c->ev.failed, c->ev.error). */
int fit_evaluate(fit_ctx *c, size_t nsets, const double *xs, double *out, double *out_u, int *ok);
/* (fit_cov.c) The forward-difference step of parameter j at x (signed: backwards
 * when x + h passes the upper bound). */
double fit_fd_step(const fit_ctx *c, int j, double x);

/* The context of request r with its result res (fit_setup.c): data,
 * weights and every buffer allocated, the result's fields set to NaN or
 * the start; -1 when out of memory (the caller frees either way). */
int fit_prepare(fit_ctx *c, const fit_request *r, fit_result *res);
/* The bounds' transform (fit_setup.c): x at u in [0, 1] across free
 * parameter f's bounds (in log x on a log scale), x at z and dx/dz, and z
 * of x (a start on a bound moves BOUND_NEAR of the width inside); start k
 * of a multi-start fit into x0. */
double fit_x_of_u(const fit_free *f, double u);
double fit_u_of_x(const fit_free *f, double x);
/* -1 at free parameter f's lower bound, 1 at its upper, 0 between (within
 * 2 BOUND_NEAR of the width in the solver's scale, log x on a log scale). */
int fit_bound_side(const fit_free *f, double x);
double fit_x_of_z(const fit_free *f, double z);
double fit_dx_dz(const fit_free *f, double z);
double fit_z_of_x(const fit_free *f, double x);
void fit_start_point(const fit_ctx *c, int k, double *x0);
/* The curves at the fit and at the start on the grid, per rotation of the
 * data, and the fitted curve's 95 % band from res->cov (fit_band.c).
 * 0, or -1 (c->ev.failed says why). */
int fit_curves(fit_ctx *c);

/* One more warning into res (at most FIT_MAX_WARNINGS). */
void fit_warn(fit_result *res, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
/* Standard errors, correlation, condition number and identifiability
 * warnings of res from c->jac_x (the weighted J in x at res->x). */
void fit_covariance(fit_ctx *c);
/* Warnings for bounds reached, standard errors as large as the value, and
 * no residual variance. */
void fit_bound_warnings(fit_ctx *c);

#endif
