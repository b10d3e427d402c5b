/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peer_gsl.c - GSL's odeiv2 steppers as a core integrator descriptor
 * (peer.h; GSL Reference Manual, "Ordinary Differential Equations"): the
 * driver's stepper, control and evolve objects, one gsl_odeiv2_evolve_apply
 * a step, with the standard control on y (eps_abs = atol, eps_rel = rtol,
 * a_y = 1, a_dydt = 0) scaled per component so that the energy
 * accumulators are outside it (gsl_odeiv2_control_scaled_new). GSL's
 * evolve has no smallest step: in a sliding mode of the feed's switching
 * laws it shrinks the step until the error test passes. msadams and msbdf
 * are multistep: a reset (after the settling, a control) restarts them
 * from the current state. msbdf needs a Jacobian: forward differences
 * (peer_fd_jacobian), df/dt likewise.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_odeiv2.h>

#include "peer.h"

#define PEER_HMAX 2e-3

typedef struct gsl_peer {
	peer_ws pw; /* first: peer_of reads it */
	gsl_odeiv2_system gsys;
	gsl_odeiv2_driver *drv;
	double h;
	double *scale_abs, *f0, *work;
} gsl_peer;

static int gsl_rhs(double t, const double y[], double dydt[], void *params)
{
	gsl_peer *w = params;
	dyn_rhs(w->pw.sys, t, y, dydt);
	return GSL_SUCCESS;
}

static int gsl_jac(double t, const double y[], double *dfdy, double dfdt[], void *params)
{
	gsl_peer *w = params;
	const int n = w->pw.n;
	dyn_rhs(w->pw.sys, t, y, w->f0);
	peer_fd_jacobian(&w->pw, t, y, w->f0, dfdy, w->work);
	double dt = 1e-8;
	dyn_rhs(w->pw.sys, t + dt, y, w->work);
	for (int i = 0; i < n; i++)
		dfdt[i] = (w->work[i] - w->f0[i]) / dt;
	return GSL_SUCCESS;
}

static const gsl_odeiv2_step_type *gsl_type(const char *name)
{
	if (strcmp(name, "gsl-rk8pd") == 0)
		return gsl_odeiv2_step_rk8pd;
	if (strcmp(name, "gsl-rkf45") == 0)
		return gsl_odeiv2_step_rkf45;
	if (strcmp(name, "gsl-msadams") == 0)
		return gsl_odeiv2_step_msadams;
	if (strcmp(name, "gsl-msbdf") == 0)
		return gsl_odeiv2_step_msbdf;
	return NULL;
}

static void gsl_peer_free(void *p)
{
	gsl_peer *w = p;
	if (!w)
		return;
	if (w->drv)
		gsl_odeiv2_driver_free(w->drv);
	free(w->scale_abs);
	free(w);
}

static void *gsl_peer_alloc(const model *md, const sim_method *cfg)
{
	const gsl_odeiv2_step_type *T = gsl_type(cfg->name);
	gsl_peer *w = T ? calloc(1, sizeof *w) : NULL;
	if (!w)
		return NULL;
	gsl_set_error_handler_off();
	const size_t n = (size_t)md->n;
	w->pw = (peer_ws){.n = md->n, .nerr = 2 * md->npos, .rtol = cfg->rtol,
			  .atol = cfg->atol, .need_init = 1};
	w->scale_abs = malloc(sizeof(double) * 4 * n);
	if (!w->scale_abs)
		goto fail;
	w->f0 = w->scale_abs + n;
	w->work = w->f0 + n; /* 2 n */
	peer_atol_vector(&w->pw, w->scale_abs);
	for (size_t i = 0; i < n; i++)
		w->scale_abs[i] /= w->pw.atol; /* 1, or huge for the accumulators */
	w->gsys = (gsl_odeiv2_system){gsl_rhs, gsl_jac, n, w};
	w->h = 1e-5;
	w->drv = gsl_odeiv2_driver_alloc_scaled_new(&w->gsys, T, w->h, w->pw.atol, w->pw.rtol,
						    1.0, 0.0, w->scale_abs);
	if (!w->drv)
		goto fail;
	return w;
fail:
	gsl_peer_free(w);
	return NULL;
}

static int gsl_peer_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	gsl_peer *w = p;
	w->pw.sys = sys;
	if (w->pw.need_init) {
		gsl_odeiv2_driver_reset(w->drv);
		w->pw.need_init = 0;
	}
	if (peer_budget_check(&w->pw, *t) != SIM_OK)
		return SIM_ESTEP;
	double t1 = isfinite(t_max) ? t_max : *t + 1e3;
	unsigned long failed0 = w->drv->e->failed_steps;
	w->h = fmin(w->h, PEER_HMAX);
	int st = gsl_odeiv2_evolve_apply(w->drv->e, w->drv->c, w->drv->s, &w->gsys, t, t1, &w->h,
					 y);
	w->pw.rejected += w->drv->e->failed_steps - failed0;
	if (st != GSL_SUCCESS) {
		snprintf(w->pw.msg, sizeof w->pw.msg, "gsl_odeiv2_evolve_apply: %s at t = %.9g s",
			 gsl_strerror(st), *t);
		return SIM_ESTEP;
	}
	w->pw.steps++;
	return SIM_OK;
}

const ode_method peer_gsl = {
	.info = {.name = "gsl", .order = 0, .adaptive = 1, .doc = "GSL odeiv2 (benchmark peer)"},
	.dense = 1,
	.alloc = gsl_peer_alloc,
	.step = gsl_peer_step,
	.interpolate = peer_no_interpolation,
	.reset = peer_reset,
	.free = gsl_peer_free,
};
