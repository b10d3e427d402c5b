/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_setup.c - a fit's context made from its request (fit_prepare), and
 * the bounds of the free parameters as a smooth transform:
 * each x in [lo, hi] is x = lo + (hi - lo) (1 + sin z) / 2 over an
 * unbounded z (on log x when lo > 0 and hi / lo >= 1000, so that a
 * stiffness spanning decades moves in proportion); and the multi-start
 * design across them.
 */
#include <math.h>
#include <stdlib.h>

#include "fit_int.h"

static int log_scale(const fit_free *f)
{
	return f->lo > 0 && f->hi / f->lo >= 1000;
}

/* x at u in [0, 1] across the bounds (in log x on a log scale). */
double fit_x_of_u(const fit_free *f, double u)
{
	if (log_scale(f))
		return exp(log(f->lo) + u * (log(f->hi) - log(f->lo)));
	return f->lo + u * (f->hi - f->lo);
}

/* u in [0, 1] of x across the bounds (in log x on a log scale). */
double fit_u_of_x(const fit_free *f, double x)
{
	if (log_scale(f))
		return (log(x) - log(f->lo)) / (log(f->hi) - log(f->lo));
	return (x - f->lo) / (f->hi - f->lo);
}

/* -1 where x lies within 2 BOUND_NEAR of the width from its lower bound,
 * 1 from its upper, else 0; the width in the solver's scale (a stiffness
 * over decades at 1e5 in [1e3, 1e8] is not at its lower bound). */
int fit_bound_side(const fit_free *f, double x)
{
	double u = fit_u_of_x(f, x);
	return u <= 2 * BOUND_NEAR ? -1 : u >= 1 - 2 * BOUND_NEAR ? 1 : 0;
}

double fit_x_of_z(const fit_free *f, double z)
{
	return fit_x_of_u(f, 0.5 * (1 + sin(z)));
}

double fit_dx_dz(const fit_free *f, double z)
{
	double du = 0.5 * cos(z);
	if (log_scale(f))
		return fit_x_of_z(f, z) * (log(f->hi) - log(f->lo)) * du;
	return (f->hi - f->lo) * du;
}

/* z of x; a start on a bound moves BOUND_NEAR of the width inside, where
 * dx/dz is not zero. */
double fit_z_of_x(const fit_free *f, double x)
{
	double u = fit_u_of_x(f, x);
	u = fmin(fmax(u, BOUND_NEAR), 1 - BOUND_NEAR);
	return asin(2 * u - 1);
}

/* Start k of a multi-start fit: the request's start, then the points of a
 * Halton sequence (bases 2, 3, 5, ...) across the bounds, in the solver's
 * scale (log x on a log scale). */
void fit_start_point(const fit_ctx *c, int k, double *x0)
{
	static const int base[FIT_MAX_FREE] = {2, 3, 5, 7, 11, 13, 17, 19};
	for (int j = 0; j < c->p; j++) {
		const fit_free *f = &c->req->free[j];
		double u = 0, scale = 1;
		for (int i = k; i > 0; i /= base[j]) {
			scale /= base[j];
			u += scale * (i % base[j]);
		}
		x0[j] = k == 0 ? f->start : fit_x_of_u(f, u);
	}
}

/* The data, weights and result arrays of c; -1 when out of memory. */
int fit_prepare(fit_ctx *c, const fit_request *r, fit_result *res)
{
	c->req = r;
	c->res = res;
	c->p = r->nfree;
	if (fit_eval_init(&c->ev, r) != 0)
		return -1;
	c->n = c->ev.ndata;
	size_t n = c->n;
	c->q = 0;
	for (int j = 0; j < c->p; j++)
		if (fit_has_prior(&r->prior[j]))
			c->prior_of[c->q++] = j;
	c->w = malloc(sizeof(double) * n);
	c->data = malloc(sizeof(double) * n);
	c->fmodel = malloc(sizeof(double) * n);
	c->fmodel_u = malloc(sizeof(double) * n);
	c->jac_x = malloc(sizeof(double) * (n + (size_t)c->q) * (size_t)c->p);
	c->jmodel = malloc(sizeof(double) * n);
	c->jmodel_u = malloc(sizeof(double) * n);
	c->best_model = malloc(sizeof(double) * n);
	c->best_model_u = malloc(sizeof(double) * n);
	c->best_cost = INFINITY;
	res->ndata = n;
	res->model = malloc(sizeof(double) * n);
	res->model_u = malloc(sizeof(double) * n);
	res->model_start = malloc(sizeof(double) * n);
	if (!c->w || !c->data || !c->fmodel || !c->fmodel_u || !c->jac_x || !c->jmodel ||
	    !c->jmodel_u || !c->best_model || !c->best_model_u || !res->model || !res->model_u ||
	    !res->model_start)
		return -1;
	for (int j = 0; j < FIT_MAX_FREE * FIT_MAX_FREE; j++)
		res->cov[j] = res->corr[j] = NAN;
	for (int j = 0; j < FIT_MAX_FREE; j++)
		res->se[j] = NAN;
	res->chi2 = res->s2 = res->cond = NAN;
	res->sigma_given = 1;
	for (size_t i = 0; i < n; i++) {
		res->model[i] = res->model_u[i] = NAN;
		double s = r->npoints ? r->points[i].sigma : r->peaks[i].sigma;
		c->data[i] = r->npoints ? r->points[i].v : r->peaks[i].beta;
		c->w[i] = isnan(s) ? 1 : s;
		res->sigma_given &= !isnan(s);
		res->model_start[i] = NAN;
	}
	res->nfree = c->p;
	for (int j = 0; j < c->p; j++)
		res->x0[j] = res->x[j] = r->free[j].start;
	return 0;
}
