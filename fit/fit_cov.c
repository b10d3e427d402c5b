/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_cov.c - what a fit's optimum is worth: standard errors from the
 * Jacobian J of the weighted residuals in the parameters' own units,
 * cov = (J^T J)^-1 when every datum has its sigma, else s2 (J^T J)^-1 with
 * the residual variance s2 = chi2 / (n - p); the correlation matrix; the
 * condition number of J with its columns scaled to unit length, which
 * flags (and names) a combination of parameters the data cannot fix; and
 * the warnings for bounds reached and parameters as uncertain as their
 * values. By SVD (GSL).
 */
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>

#include "fit_int.h"
#include "units.h"

/* the scaled condition number above which a combination counts as not
 * identifiable: a correlation of 0.9998 between two parameters */
#define COND_WARN 100.0

void fit_warn(fit_result *res, const char *fmt, ...)
{
	if (res->nwarn >= FIT_MAX_WARNINGS)
		return;
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(res->warnings[res->nwarn++], FIT_MSG, fmt, ap);
	va_end(ap);
}

/* The step of the forward differences (the Jacobian's and the band's). */
double fit_fd_step(const fit_ctx *c, int j, double x)
{
	return fit_step(&c->req->free[j], c->req->fd_rel, x);
}

double fit_step(const fit_free *f, double fd_rel, double x)
{
	double h = fd_rel * fmax(fabs(x), 1e-3 * (f->hi - f->lo));
	h = fmin(h, 0.25 * (f->hi - f->lo));
	return x + h <= f->hi ? h : -h;
}

/* The parameter combination the data fix least (the right singular vector
 * of the smallest singular value, as relative changes) into buf. */
static void weak_combination(const fit_ctx *c, const gsl_matrix *V, const double *scale,
			     char *buf, size_t len)
{
	const fit_result *res = c->res;
	size_t last = (size_t)c->p - 1, at = 0;
	double d[FIT_MAX_FREE], norm = 0;
	for (int j = 0; j < c->p; j++) {
		/* direction in x: D^-1 v; as a relative change of x_j */
		d[j] = gsl_matrix_get(V, (size_t)j, last) / scale[j] /
		       fmax(fabs(res->x[j]), 1e-300);
		norm = fmax(norm, fabs(d[j]));
	}
	for (int j = 0; j < c->p && at < len; j++)
		if (fabs(d[j]) > 0.05 * norm)
			at += (size_t)snprintf(buf + at, len - at, "%s%+.2f %s", at ? " " : "",
					       d[j] / norm, c->req->free[j].name);
}

/* Standard errors, correlations, the condition number and the
 * identifiability warnings from J_x (weighted) at the optimum, the priors'
 * rows with the data's (the posterior's covariance). */
void fit_covariance(fit_ctx *c)
{
	fit_result *res = c->res;
	int p = c->p;
	size_t n = c->n + (size_t)c->q;
	gsl_matrix *A = gsl_matrix_alloc(n, (size_t)p), *V = gsl_matrix_alloc((size_t)p, (size_t)p);
	gsl_vector *S = gsl_vector_alloc((size_t)p), *work = gsl_vector_alloc((size_t)p);
	double scale[FIT_MAX_FREE];
	for (int j = 0; j < p * p; j++)
		res->corr[j] = NAN;
	for (int j = 0; j < p; j++)
		res->se[j] = NAN;
	if (!A || !V || !S || !work)
		goto done;
	for (int j = 0; j < p; j++) {
		double s2 = 0;
		for (size_t i = 0; i < n; i++)
			s2 += pow(c->jac_x[i * (size_t)p + (size_t)j], 2);
		scale[j] = sqrt(s2);
		if (!(scale[j] > 0)) {
			fit_warn(res, "'%s' is not identifiable: the data do not change with it",
			     c->req->free[j].name);
			scale[j] = 1;
		}
		for (size_t i = 0; i < n; i++)
			gsl_matrix_set(A, i, (size_t)j, c->jac_x[i * (size_t)p + (size_t)j] / scale[j]);
	}
	gsl_linalg_SV_decomp(A, V, S, work);
	double smax = gsl_vector_get(S, 0), smin = gsl_vector_get(S, (size_t)p - 1);
	res->cond = smin > 0 ? smax / smin : INFINITY;
	if (res->cond > COND_WARN && p > 1) {
		char comb[160] = "";
		weak_combination(c, V, scale, comb, sizeof comb);
		fit_warn(res, "not identifiable from these data: the condition number of the scaled "
			  "Jacobian is %.3g (above %g); the data fix little of the combination %s "
			  "(relative changes)", res->cond, COND_WARN, comb);
	}
	double factor = res->sigma_given ? 1 : res->dof > 0 ? res->s2 : NAN;
	if (!(smin > 1e-12 * smax))
		goto done; /* singular: no standard errors */
	double cov[FIT_MAX_FREE * FIT_MAX_FREE];
	for (int a = 0; a < p; a++)
		for (int b = 0; b < p; b++) {
			double s = 0;
			for (int k = 0; k < p; k++)
				s += gsl_matrix_get(V, (size_t)a, (size_t)k) *
				     gsl_matrix_get(V, (size_t)b, (size_t)k) /
				     pow(gsl_vector_get(S, (size_t)k), 2);
			cov[a * p + b] = factor * s / (scale[a] * scale[b]);
		}
	for (int a = 0; a < p * p; a++)
		res->cov[a] = cov[a];
	for (int a = 0; a < p; a++)
		res->se[a] = sqrt(cov[a * p + a]);
	for (int a = 0; a < p; a++)
		for (int b = 0; b < p; b++)
			res->corr[a * p + b] = cov[a * p + b] / (res->se[a] * res->se[b]);
done:
	gsl_matrix_free(A);
	gsl_matrix_free(V);
	gsl_vector_free(S);
	gsl_vector_free(work);
}

/* Bounds reached, standard errors as large as the value. */
void fit_bound_warnings(fit_ctx *c)
{
	fit_result *res = c->res;
	for (int j = 0; j < c->p; j++) {
		const fit_free *f = &c->req->free[j];
		const sim_setting *t = sim_setting_find(f->name);
		res->at_bound[j] = fit_bound_side(f, res->x[j]);
		if (res->at_bound[j])
			fit_warn(res, "'%s' ends at its %s bound %g %s: the data want it beyond; widen "
				  "the bound or question the model", f->name,
			     res->at_bound[j] < 0 ? "lower" : "upper",
			     sim_setting_from_si(t, res->at_bound[j] < 0 ? f->lo : f->hi),
			     sim_unit_shown(t));
		else if (res->se[j] >= fabs(res->x[j]))
			fit_warn(res, "'%s' is not identifiable: its standard error (%g) is as large as "
				  "its value (%g)", f->name, sim_setting_from_si(t, res->se[j]),
			     sim_setting_from_si(t, res->x[j]));
	}
	if (!res->sigma_given && res->dof == 0)
		fit_warn(res, "as many data as free parameters: no residual variance, so no standard "
			  "errors; give sigma with the data or more data");
}

