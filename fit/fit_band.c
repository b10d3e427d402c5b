/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_band.c - the fitted curve and how sure it is: v(beta) on a grid at
 * the fit and at the start, and the 95 % band of the fitted curve from the
 * parameters' covariance C by the delta method,
 *
 *     v(beta) +- q sqrt(g^T C g + u^2),  g_j = dv(beta)/dx_j,
 *
 * g by forward differences with the Jacobian's steps (fit_fd_step), all
 * in the same batch as the curves (Bard, "Nonlinear Parameter
 * Estimation", 1974, ch. 7; Seber & Wild, "Nonlinear Regression", 1989,
 * sec. 5.1). q is the normal 97.5 % quantile when every datum has its
 * sigma, Student's t with the fit's degrees of freedom when C comes from
 * the residual variance. u is the curve point's own error bar (the
 * steady-state measure's jitter and step error), which is all there is
 * where v hardly depends on the parameters (where the curves of nearby
 * parameter values cross). The band is of the model's curve at the true
 * parameters, not of a new measurement (which adds its own sigma).
 *
 * fit_band_sampled checks it: parameter sets drawn from N(x, C), their
 * curves, the 2.5 and 97.5 percentiles at each grid point; where v is
 * close to linear in x over the band the two agree.
 */
#include <gsl/gsl_cdf.h>
#include <gsl/gsl_linalg.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "fit_int.h"
#include "units.h"

double fit_band_quantile(int sigma_given, int dof)
{
	if (sigma_given)
		return gsl_cdf_ugaussian_Pinv(0.975);
	return dof > 0 ? gsl_cdf_tdist_Pinv(0.975, dof) : NAN;
}

/* 97.5 % quantile for res's band. */
static double band_quantile(const fit_result *res)
{
	return fit_band_quantile(res->sigma_given, res->dof);
}

double fit_delta_half(int p, const double *cov, double q, double v, const double *vp,
		      const double *h, double u)
{
	double g[FIT_MAX_FREE], var = 0;
	for (int j = 0; j < p; j++)
		g[j] = (vp[j] - v) / h[j];
	for (int a = 0; a < p; a++)
		for (int b = 0; b < p; b++)
			var += g[a] * cov[a * p + b] * g[b];
	return q * sqrt(fmax(var, 0) + (isfinite(u) ? u * u : 0));
}

/* The rotations of the data into res (in order of first use). */
static void curve_rotations(const fit_request *r, size_t ndata, fit_result *res)
{
	res->nrot = 0;
	for (size_t d = 0; d < ndata; d++) {
		int rot = r->npoints ? r->points[d].rotation : r->peaks[d].rotation;
		if (!(res->nrot > 0 && res->rotations[0] == rot) &&
		    !(res->nrot > 1 && res->rotations[1] == rot))
			res->rotations[res->nrot++] = rot;
	}
}

/* The grid of res's curves: beta and rotation per point ([rot * n + k]). */
static void curve_grid(const fit_result *res, double *beta, int *rot)
{
	for (size_t k = 0; k < res->ncurve * (size_t)res->nrot; k++) {
		beta[k] = res->curve_beta[k % res->ncurve];
		rot[k] = res->rotations[k / res->ncurve];
	}
}

/* The delta method's band from the curve at the fit (v, its error bar
 * u), at the perturbed sets (vp[j * total + k]) and their steps h. */
static void delta_band(fit_result *res, int p, size_t total, const double *v, const double *u,
		       const double *vp, const double *h)
{
	res->band_quantile = band_quantile(res);
	for (size_t k = 0; k < total; k++) {
		double vk[FIT_MAX_FREE];
		for (int j = 0; j < p; j++)
			vk[j] = vp[(size_t)j * total + k];
		double half = fit_delta_half(p, res->cov, res->band_quantile, v[k], vk, h, u[k]);
		res->band_lo[k] = isfinite(half) ? v[k] - half : NAN;
		res->band_hi[k] = isfinite(half) ? v[k] + half : NAN;
	}
}

int fit_curves(fit_ctx *c)
{
	const fit_request *r = c->req;
	fit_result *res = c->res;
	int p = c->p;
	size_t n = (size_t)floor(SIM_PI / r->curve_step + 1e-9) + 1;
	curve_rotations(r, c->n, res);
	size_t total = n * (size_t)res->nrot, sets = 2 + (size_t)p;
	res->ncurve = n;
	res->curve_beta = malloc(sizeof(double) * n);
	res->curve_fit = malloc(sizeof(double) * total);
	res->curve_fit_u = malloc(sizeof(double) * total);
	res->curve_start = malloc(sizeof(double) * total);
	res->band_lo = malloc(sizeof(double) * total);
	res->band_hi = malloc(sizeof(double) * total);
	double *beta = malloc(sizeof(double) * total), *v = malloc(sizeof(double) * sets * total),
	       *u = malloc(sizeof(double) * sets * total), xs[(2 + FIT_MAX_FREE) * FIT_MAX_FREE],
	       h[FIT_MAX_FREE];
	int *rot = malloc(sizeof(int) * total), rc = -1;
	if (beta && v && u && rot && res->curve_beta && res->curve_fit && res->curve_fit_u &&
	    res->curve_start && res->band_lo && res->band_hi) {
		for (size_t k = 0; k < n; k++)
			res->curve_beta[k] = fmin((double)k * r->curve_step, SIM_PI);
		curve_grid(res, beta, rot);
		/* the fit, the start, and the fit with x_j + h_j for each j */
		for (size_t s = 0; s < sets; s++)
			for (int j = 0; j < p; j++)
				xs[s * (size_t)p + (size_t)j] = s == 1 ? res->x0[j] : res->x[j];
		for (int j = 0; j < p; j++) {
			h[j] = fit_fd_step(c, j, res->x[j]);
			xs[(2 + (size_t)j) * (size_t)p + (size_t)j] += h[j];
		}
		rc = fit_eval_curve(&c->ev, sets, xs, total, beta, rot, v, u);
		for (size_t k = 0; rc == 0 && k < total; k++) {
			res->curve_fit[k] = v[k];
			res->curve_fit_u[k] = u[k];
			res->curve_start[k] = v[total + k];
		}
		if (rc == 0)
			delta_band(res, p, total, v, u, v + 2 * total, h);
	}
	free(beta);
	free(v);
	free(u);
	free(rot);
	return rc;
}

/* ---- the check by sampling ------------------------------------------------ */

double fit_normal(unsigned long long *s)
{
	double w[2];
	for (int k = 0; k < 2; k++) {
		*s ^= *s >> 12, *s ^= *s << 25, *s ^= *s >> 27;
		w[k] = ((double)((*s * 2685821657736338717ULL) >> 11) + 0.5) / 9007199254740992.0;
	}
	return sqrt(-2 * log(w[0])) * cos(2 * SIM_PI * w[1]);
}

static int by_value(const void *a, const void *b)
{
	double x = *(const double *)a, y = *(const double *)b;
	return (x > y) - (x < y);
}

/* nsamples parameter sets from N(res->x, (q / z) C) (z the normal
 * quantile, so that the spread matches the delta band's quantile q),
 * clamped to the bounds, into xs. -1 when C is not positive definite. */
static int draw(const fit_request *req, const fit_result *res, int nsamples,
		unsigned long long seed, double *xs)
{
	int p = res->nfree;
	gsl_matrix *L = gsl_matrix_alloc((size_t)p, (size_t)p);
	double scale = band_quantile(res) / gsl_cdf_ugaussian_Pinv(0.975);
	int rc = L ? 0 : -1;
	for (int a = 0; rc == 0 && a < p; a++)
		for (int b = 0; b < p; b++) {
			double cab = res->cov[a * p + b] * scale * scale;
			rc = isfinite(cab) ? 0 : -1;
			gsl_matrix_set(L, (size_t)a, (size_t)b, cab);
		}
	if (rc == 0 && gsl_linalg_cholesky_decomp1(L) != GSL_SUCCESS)
		rc = -1;
	unsigned long long s = seed ? seed : 1;
	for (int k = 0; rc == 0 && k < nsamples; k++) {
		double xi[FIT_MAX_FREE];
		for (int j = 0; j < p; j++)
			xi[j] = fit_normal(&s);
		for (int a = 0; a < p; a++) {
			double x = res->x[a];
			for (int b = 0; b <= a; b++)
				x += gsl_matrix_get(L, (size_t)a, (size_t)b) * xi[b];
			xs[(size_t)k * (size_t)p + (size_t)a] =
				fmin(fmax(x, req->free[a].lo), req->free[a].hi);
		}
	}
	gsl_matrix_free(L);
	return rc;
}

int fit_band_sampled(const fit_request *req, const fit_result *res, int nsamples,
		     unsigned long long seed, double *lo, double *hi)
{
	size_t total = res->ncurve * (size_t)res->nrot, ns = (size_t)(nsamples > 0 ? nsamples : 0);
	if (!total || nsamples < 2)
		return -1;
	fit_eval ev;
	if (fit_eval_init(&ev, req) != 0)
		return -1;
	double *xs = malloc(sizeof(double) * ns * (size_t)res->nfree),
	       *v = malloc(sizeof(double) * ns * total), *col = malloc(sizeof(double) * ns),
	       *beta = malloc(sizeof(double) * total);
	int *rot = malloc(sizeof(int) * total), rc = -1;
	if (xs && v && col && beta && rot && draw(req, res, nsamples, seed, xs) == 0) {
		curve_grid(res, beta, rot);
		rc = fit_eval_curve(&ev, ns, xs, total, beta, rot, v, NULL);
	}
	for (size_t k = 0; rc == 0 && k < total; k++) {
		for (size_t s = 0; s < ns; s++)
			col[s] = v[s * total + k];
		qsort(col, ns, sizeof *col, by_value);
		/* the order statistics nearest the 2.5 and 97.5 percentiles */
		lo[k] = col[(size_t)lround(0.025 * (double)(ns - 1))];
		hi[k] = col[(size_t)lround(0.975 * (double)(ns - 1))];
	}
	fit_eval_free(&ev);
	free(xs);
	free(v);
	free(col);
	free(beta);
	free(rot);
	return rc;
}
