/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit.c - the least-squares driver of a calibration: Levenberg-Marquardt in
 * a trust region (GSL's gsl_multifit_nlinear, trs_lm, More scaling) on the
 * residuals r_i = (model_i - data_i) / sigma_i (sigma_i = 1 when the data
 * give none).
 *
 * Bounds by a smooth transform (fit_setup.c): the solver works in an
 * unbounded z and never leaves the bounds.
 *
 * Jacobian by forward differences in x, all columns in one parallel batch:
 * step h_j = fd_rel * max(|x_j|, 1e-3 (hi_j - lo_j)) (5 % by default),
 * backwards when x_j + h_j passes hi_j. The steady-state measure is not
 * smooth at the 0.3 % level (its 4-s window sees whole periods only, and
 * the feed's contact pattern shifts), so the step must move v well beyond
 * that: 5 % of e moves v by about 12 %, 40 times the jitter (docs/calibration.md
 * "Calibration"). Then J_z = J_x dx/dz.
 *
 * A trial point the model cannot be evaluated at (fit_try.c finds it) is a
 * rejected step: residuals far above any real cost, so that the trust
 * region shrinks. Multi-start: the request's start, then a Halton design
 * over the bounds; the lowest cost wins.
 *
 * A free parameter's prior (fit_prior.c) is one more residual after the
 * data's, with its analytic row of the Jacobian.
 *
 * Standard errors, correlations and warnings at the optimum: fit_cov.c;
 * the curves and their band: fit_band.c.
 */
#include <gsl/gsl_blas.h>
#include <gsl/gsl_errno.h>
#include <gsl/gsl_linalg.h>
#include <gsl/gsl_multifit_nlinear.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "fit_int.h"
#include "units.h"



/* trial steps per iteration: past this many rejections the cost is at the
 * measure's jitter and the iterate stands */
#define MAX_TRIALS 8

static void xs_of(const fit_ctx *c, const gsl_vector *z, double *x)
{
	for (int j = 0; j < c->p; j++)
		x[j] = fit_x_of_z(&c->req->free[j], gsl_vector_get(z, (size_t)j));
}

static void report(fit_ctx *c, const char *phase, const double *x, double cost)
{
	if (!c->req->progress)
		return;
	fit_progress pr = {phase, c->iteration, 0, cost, {0}};
	pthread_mutex_lock(&c->ev.lock);
	pr.evaluations = c->ev.evaluations;
	pthread_mutex_unlock(&c->ev.lock);
	for (int j = 0; x && j < c->p; j++)
		pr.x[j] = x[j];
	c->req->progress(c->req->ctx, &pr);
}

/* The residuals of a trial point the model cannot be evaluated at: a cost
 * far above any real one, so that the solver rejects the step and shrinks
 * its trust region, as for a step that made things worse. */
#define FAILED_RESIDUAL 1e30

static int cb_f(const gsl_vector *z, void *arg, gsl_vector *f)
{
	fit_ctx *c = arg;
	double x[FIT_MAX_FREE];
	int ok;
	xs_of(c, z, x);
	if (c->iteration > 0 && ++c->trials > MAX_TRIALS) {
		c->stalled = 1;
		return GSL_EBADFUNC;
	}
	if (fit_evaluate(c, 1, x, c->fmodel, c->fmodel_u, &ok) != 0)
		return GSL_EBADFUNC;
	if (!ok) {
		/* the start itself: this run cannot begin */
		if (c->iteration == 0)
			return GSL_EBADFUNC;
		c->res->rejected++;
		c->fvalid = 0;
		gsl_vector_set_all(f, FAILED_RESIDUAL);
		report(c, "fitting", x, NAN);
		return GSL_SUCCESS;
	}
	memcpy(c->fx, x, sizeof x);
	c->fvalid = 1;
	double cost = 0;
	for (size_t i = 0; i < c->n; i++) {
		double r = (c->fmodel[i] - c->data[i]) / c->w[i];
		gsl_vector_set(f, i, r);
		cost += r * r;
	}
	for (int k = 0; k < c->q; k++) {
		int j = c->prior_of[k];
		double r = fit_prior_residual(&c->req->prior[j], x[j]);
		gsl_vector_set(f, c->n + (size_t)k, r);
		cost += r * r;
	}
	if (cost < c->best_cost) {
		c->best_cost = cost;
		memcpy(c->best_x, x, sizeof x);
		memcpy(c->best_model, c->fmodel, sizeof(double) * c->n);
		memcpy(c->best_model_u, c->fmodel_u, sizeof(double) * c->n);
	}
	report(c, "fitting", x, cost);
	return GSL_SUCCESS;
}

static int same_x(const double *a, const double *b, int p)
{
	return memcmp(a, b, sizeof *a * (size_t)p) == 0;
}

/* J_x (weighted) at x into c->jac_x: the base set (unless f has it) and
 * one perturbed set per parameter, in one batch; a perturbed set the
 * model cannot be evaluated at is tried once more with the step reversed
 * (where that stays within the bounds). 0, or -1 (c->why or c->ev say
 * why). */
static int jacobian_x(fit_ctx *c, const double *x)
{
	int p = c->p, base = !(c->fvalid && same_x(c->fx, x, p));
	size_t sets = (size_t)p + (size_t)base, n = c->n;
	double *xs = malloc(sizeof *xs * sets * (size_t)p), *out = malloc(sizeof *out * sets * n),
	       *out_u = malloc(sizeof *out_u * sets * n);
	double h[FIT_MAX_FREE];
	int ok[FIT_MAX_FREE + 1], rc = xs && out && out_u ? 0 : -1;
	for (size_t s = 0; rc == 0 && s < sets; s++)
		for (int j = 0; j < p; j++) {
			int pert = (int)s - base;
			if (pert == j)
				h[j] = fit_fd_step(c, j, x[j]);
			xs[s * (size_t)p + (size_t)j] = x[j] + (pert == j ? h[j] : 0);
		}
	if (rc == 0)
		rc = fit_evaluate(c, sets, xs, out, out_u, ok);
	for (int j = 0; rc == 0 && j < p; j++) {
		size_t s = (size_t)j + (size_t)base;
		const fit_free *f = &c->req->free[j];
		double *xj = xs + s * (size_t)p;
		if (ok[s] || x[j] - h[j] < f->lo || x[j] - h[j] > f->hi)
			continue;
		h[j] = -h[j];
		xj[j] = x[j] + h[j];
		rc = fit_evaluate(c, 1, xj, out + s * n, out_u + s * n, &ok[s]);
	}
	for (size_t s = 0; rc == 0 && s < sets; s++)
		if (!ok[s])
			rc = -1;
	const double *f0 = base ? out : c->fmodel;
	for (size_t i = 0; rc == 0 && i < n; i++)
		for (int j = 0; j < p; j++)
			c->jac_x[i * (size_t)p + (size_t)j] =
				(out[((size_t)j + (size_t)base) * n + i] - f0[i]) / h[j] / c->w[i];
	/* a prior's row: its slope, exact, in its own parameter's column */
	for (int k = 0; rc == 0 && k < c->q; k++)
		for (int j = 0; j < p; j++)
			c->jac_x[(n + (size_t)k) * (size_t)p + (size_t)j] =
				j == c->prior_of[k] ? fit_prior_slope(&c->req->prior[j], x[j]) : 0.0;
	if (rc == 0) {
		memcpy(c->jx, x, sizeof *x * (size_t)p);
		memcpy(c->jmodel, f0, sizeof(double) * n);
		memcpy(c->jmodel_u, base ? out_u : c->fmodel_u, sizeof(double) * n);
		c->jvalid = 1;
	}
	free(xs);
	free(out);
	free(out_u);
	return rc;
}

static int cb_df(const gsl_vector *z, void *arg, gsl_matrix *J)
{
	fit_ctx *c = arg;
	double x[FIT_MAX_FREE];
	xs_of(c, z, x);
	if (jacobian_x(c, x) != 0)
		return GSL_EBADFUNC;
	for (size_t i = 0; i < c->n + (size_t)c->q; i++)
		for (int j = 0; j < c->p; j++)
			gsl_matrix_set(J, i, (size_t)j,
				       c->jac_x[i * (size_t)c->p + (size_t)j] *
					       fit_dx_dz(&c->req->free[j], gsl_vector_get(z, (size_t)j)));
	return GSL_SUCCESS;
}

static double wall_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Rough standard errors (SI) from the last Jacobian and the cost at the
 * current iterate, for the stopping test: 0, or -1 when J^T J is singular
 * or there is no residual variance. */
static int rough_se(const fit_ctx *c, double cost, double *se)
{
	int p = c->p, rc = -1;
	gsl_matrix *A = gsl_matrix_calloc((size_t)p, (size_t)p);
	for (size_t i = 0; A && i < c->n + (size_t)c->q; i++)
		for (int a = 0; a < p; a++)
			for (int b = 0; b < p; b++)
				*gsl_matrix_ptr(A, (size_t)a, (size_t)b) +=
					c->jac_x[i * (size_t)p + (size_t)a] *
					c->jac_x[i * (size_t)p + (size_t)b];
	double s2 = c->res->sigma_given ? 1 : cost / ((double)c->n - p);
	/* without sigma and with as many data as parameters there is no
	 * residual variance: the misfit itself would pass for the error */
	if (A && isfinite(s2) && s2 >= 0 && gsl_linalg_cholesky_decomp1(A) == GSL_SUCCESS &&
	    gsl_linalg_cholesky_invert(A) == GSL_SUCCESS) {
		for (int j = 0; j < p; j++)
			se[j] = sqrt(s2 * gsl_matrix_get(A, (size_t)j, (size_t)j));
		rc = 0;
	}
	gsl_matrix_free(A);
	return rc;
}

/* The iterations; the status. Converged when the last step moved every
 * parameter by less than xtol of its scale, or by less than a tenth of its
 * (rough) standard error: the data cannot tell such steps apart. */
static int iterate(fit_ctx *c, gsl_multifit_nlinear_workspace *w)
{
	const fit_request *r = c->req;
	double prev[FIT_MAX_FREE];
	xs_of(c, gsl_multifit_nlinear_position(w), prev);
	for (c->iteration = 1; c->iteration <= r->max_iter; c->iteration++) {
		c->trials = 0;
		c->stalled = 0;
		int rc = gsl_multifit_nlinear_iterate(w);
		if (c->ev.failed)
			return c->ev.failed == 2 ? FIT_CANCELLED : FIT_FAILED;
		if (c->stalled) {
			fit_warn(c->res, "stopped in iteration %d: %d trial steps in a row did not lower "
				     "the cost (the steady-state measure's jitter limits the fit here)",
			     c->iteration, MAX_TRIALS);
			c->iteration--;
			return FIT_CONVERGED;
		}
		double x[FIT_MAX_FREE], se[FIT_MAX_FREE], step = 0, step_se = 0;
		xs_of(c, gsl_multifit_nlinear_position(w), x);
		double cost;
		gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w), &cost);
		int have_se = c->jvalid && rough_se(c, cost, se) == 0;
		for (int j = 0; j < c->p; j++) {
			const fit_free *f = &r->free[j];
			step = fmax(step, fabs(x[j] - prev[j]) /
						  fmax(fabs(x[j]), 1e-3 * (f->hi - f->lo)));
			step_se = fmax(step_se, have_se ? fabs(x[j] - prev[j]) / se[j] : INFINITY);
		}
		memcpy(prev, x, sizeof x);
		if (rc == GSL_ENOPROG) {
			fit_warn(c->res, "stopped after %d iterations: no step lowers the cost further "
				     "(the steady-state measure's jitter limits the fit here)",
			     c->iteration);
			return FIT_CONVERGED;
		}
		if (rc != GSL_SUCCESS) {
			/* the Jacobian at an accepted point failed both ways */
			snprintf(c->res->error, FIT_MSG, "no Jacobian in iteration %d: %.200s", c->iteration,
				 c->why[0] ? c->why : gsl_strerror(rc));
			return FIT_FAILED;
		}
		int info;
		if (step < r->xtol || step_se < 0.1 ||
		    gsl_multifit_nlinear_test(r->xtol, 1e-8, 0, &info, w) == GSL_SUCCESS)
			return FIT_CONVERGED;
	}
	c->iteration = r->max_iter;
	fit_warn(c->res, "no convergence in %d iterations: the values are the last iterate",
	     r->max_iter);
	return FIT_MAXITER;
}

/* One Levenberg-Marquardt run from x0 (SI) into *run: where it ended, its
 * cost and status. */
static void solve(fit_ctx *c, const double *x0, fit_start *run)
{
	int p = c->p;
	gsl_multifit_nlinear_parameters par = gsl_multifit_nlinear_default_parameters();
	par.trs = gsl_multifit_nlinear_trs_lm;
	par.scale = gsl_multifit_nlinear_scale_more;
	size_t rows = c->n + (size_t)c->q; /* the data's residuals, then the priors' */
	gsl_multifit_nlinear_fdf fdf = {cb_f, cb_df, NULL, rows, (size_t)p, c, 0, 0, 0};
	gsl_multifit_nlinear_workspace *w =
		gsl_multifit_nlinear_alloc(gsl_multifit_nlinear_trust, &par, rows, (size_t)p);
	gsl_vector *z0 = gsl_vector_alloc((size_t)p);
	memcpy(run->x0, x0, sizeof(double) * (size_t)p);
	memcpy(run->x, x0, sizeof(double) * (size_t)p);
	run->chi2 = NAN;
	run->status = FIT_FAILED;
	c->iteration = 0;
	c->why[0] = '\0';
	c->res->error[0] = '\0';
	if (!w || !z0) {
		snprintf(c->res->error, FIT_MSG, "out of memory");
		goto done;
	}
	for (int j = 0; j < p; j++)
		gsl_vector_set(z0, (size_t)j, fit_z_of_x(&c->req->free[j], x0[j]));
	int rc = gsl_multifit_nlinear_init(z0, &fdf, w);
	if (rc == GSL_SUCCESS && run == &c->res->starts[0])
		memcpy(c->res->model_start, c->fmodel, sizeof(double) * c->n);
	if (rc == GSL_SUCCESS)
		run->status = iterate(c, w);
	else if (c->ev.failed == 2)
		run->status = FIT_CANCELLED;
	else
		snprintf(c->res->error, FIT_MSG, "the run cannot begin at its start: %.200s",
			 c->why[0] ? c->why : c->ev.failed ? c->ev.error : gsl_strerror(rc));
	if (rc == GSL_SUCCESS && run->status != FIT_CANCELLED) {
		xs_of(c, gsl_multifit_nlinear_position(w), run->x);
		gsl_blas_ddot(gsl_multifit_nlinear_residual(w), gsl_multifit_nlinear_residual(w),
			      &run->chi2);
	}
	run->iterations = c->iteration;
done:
	gsl_multifit_nlinear_free(w);
	gsl_vector_free(z0);
}

/* Every run of the request; the result is the run of the lowest cost,
 * with its warnings (a failed run counts only when all failed: then the
 * status is FIT_FAILED with the best point seen, the last reason and the
 * last run's warnings). */
static int multistart(fit_ctx *c)
{
	fit_result *res = c->res;
	int n = c->req->starts > 1 ? c->req->starts : 1, best = -1, nwarn = 0;
	char error[FIT_MSG] = "", warnings[FIT_MAX_WARNINGS][FIT_MSG];
	res->nstarts = 0;
	for (int k = 0; k < n; k++) {
		double x0[FIT_MAX_FREE];
		fit_start_point(c, k, x0);
		fit_start *run = &res->starts[res->nstarts++];
		res->nwarn = 0;
		solve(c, x0, run);
		if (run->status == FIT_CANCELLED)
			return FIT_CANCELLED;
		if (run->status == FIT_FAILED)
			snprintf(error, sizeof error, "%s%.200s", n > 1 ? "every start failed; the last: " : "",
				 res->error);
		if ((run->status != FIT_FAILED && (best < 0 || run->chi2 < res->starts[best].chi2)) ||
		    (best < 0 && k == n - 1)) {
			best = run->status != FIT_FAILED ? k : best;
			nwarn = res->nwarn;
			memcpy(warnings, res->warnings, sizeof warnings);
		}
	}
	res->nwarn = nwarn;
	memcpy(res->warnings, warnings, sizeof warnings);
	res->best_start = best;
	if (best >= 0) {
		memcpy(res->x, res->starts[best].x, sizeof res->x);
		res->iterations = res->starts[best].iterations;
		res->error[0] = '\0';
		return res->starts[best].status;
	}
	/* no run came through: its best point, no standard errors */
	snprintf(res->error, FIT_MSG, "%s", error);
	res->best_start = 0;
	res->iterations = res->starts[0].iterations;
	if (isfinite(c->best_cost)) {
		memcpy(res->x, c->best_x, sizeof res->x);
		memcpy(res->model, c->best_model, sizeof(double) * c->n);
		memcpy(res->model_u, c->best_model_u, sizeof(double) * c->n);
		res->chi2_prior = fit_prior_cost(c->req, c->best_x);
		res->chi2 = c->best_cost - res->chi2_prior;
	}
	return FIT_FAILED;
}

/* Model, residual statistics, Jacobian and covariance at res->x. -1 when
 * cancelled or the model there cannot be evaluated; a Jacobian that cannot
 * be had leaves the standard errors undetermined, with a warning. */
static int at_optimum(fit_ctx *c)
{
	fit_result *res = c->res;
	int ok = 1;
	if (c->jvalid && same_x(c->jx, res->x, c->p)) {
		/* the Jacobian's base: the model at the optimum */
		memcpy(c->fmodel, c->jmodel, sizeof(double) * c->n);
		memcpy(c->fmodel_u, c->jmodel_u, sizeof(double) * c->n);
	} else if (!(c->fvalid && same_x(c->fx, res->x, c->p)) &&
		   (fit_evaluate(c, 1, res->x, c->fmodel, c->fmodel_u, &ok) != 0 || !ok)) {
		if (!ok)
			snprintf(res->error, FIT_MSG, "the fit's point cannot be evaluated: %.190s", c->why);
		return -1;
	}
	c->fvalid = 1;
	memcpy(c->fx, res->x, sizeof(double) * (size_t)c->p);
	memcpy(res->model, c->fmodel, sizeof(double) * c->n);
	memcpy(res->model_u, c->fmodel_u, sizeof(double) * c->n);
	res->chi2 = 0;
	for (size_t i = 0; i < c->n; i++)
		res->chi2 += pow((res->model[i] - c->data[i]) / c->w[i], 2);
	res->chi2_prior = fit_prior_cost(c->req, res->x);
	res->dof = (int)c->n - c->p;
	res->s2 = res->dof > 0 ? res->chi2 / res->dof : NAN;
	report(c, "covariance", res->x, res->chi2);
	if (!(c->jvalid && same_x(c->jx, res->x, c->p)) && jacobian_x(c, res->x) != 0) {
		if (c->ev.failed)
			return -1;
		fit_warn(res, "no standard errors: the Jacobian at the fit cannot be evaluated (%.160s)",
			 c->why);
	} else {
		fit_covariance(c);
	}
	fit_bound_warnings(c);
	return 0;
}

int fit_run(const fit_request *req, fit_result *res)
{
	memset(res, 0, sizeof *res);
	gsl_set_error_handler_off();
	double w0 = wall_now();
	fit_ctx c;
	memset(&c, 0, sizeof c);
	if (fit_prepare(&c, req, res) != 0) {
		res->status = FIT_FAILED;
		snprintf(res->error, FIT_MSG, "out of memory");
		goto done;
	}
	res->status = multistart(&c);
	if (res->status != FIT_FAILED && res->status != FIT_CANCELLED && at_optimum(&c) != 0)
		res->status = c.ev.failed == 2 ? FIT_CANCELLED : FIT_FAILED;
	if (res->status == FIT_FAILED && !res->error[0])
		snprintf(res->error, FIT_MSG, "%s", c.ev.error);
	if (res->rejected)
		fit_warn(res, "%d trial point%s could not be evaluated (%.170s): rejected steps", res->rejected,
			 res->rejected > 1 ? "s" : "", c.why[0] ? c.why : "see the error");
	if ((res->status == FIT_CONVERGED || res->status == FIT_MAXITER) && req->curve_step > 0) {
		report(&c, "curve", res->x, res->chi2);
		if (fit_curves(&c) != 0) {
			if (c.ev.failed == 2)
				res->status = FIT_CANCELLED;
			else
				fit_warn(res, "no curve: %s", c.ev.error);
			res->ncurve = 0;
		}
	}
done:
	res->evaluations = c.ev.evaluations;
	res->cpu_seconds = c.ev.cpu_seconds;
	res->wall_seconds = wall_now() - w0;
	report(&c, "done", res->x, res->chi2);
	fit_eval_free(&c.ev);
	free(c.w);
	free(c.data);
	free(c.fmodel);
	free(c.fmodel_u);
	free(c.jac_x);
	free(c.jmodel);
	free(c.jmodel_u);
	free(c.best_model);
	free(c.best_model_u);
	return res->status;
}

void fit_result_free(fit_result *res)
{
	if (!res)
		return;
	free(res->model);
	free(res->model_u);
	free(res->model_start);
	free(res->curve_beta);
	free(res->curve_fit);
	free(res->curve_fit_u);
	free(res->curve_start);
	free(res->band_lo);
	free(res->band_hi);
	memset(res, 0, sizeof *res);
}
