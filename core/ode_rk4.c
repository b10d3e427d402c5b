/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode_rk4.c - classical fourth-order Runge-Kutta with a fixed step
 * (Kutta 1901; Hairer, Norsett, Wanner, Solving ODEs I, sec. II.1).
 * The whole state, machine and feed, takes the same step.
 */
#include <stdlib.h>

#include "ode.h"

typedef struct rk4 {
	int n;
	double dt;
	double *k1, *k2, *k3, *k4, *tmp;
} rk4;

static void rk4_free(void *p)
{
	rk4 *w = p;
	if (!w)
		return;
	free(w->k1);
	free(w);
}

static void *rk4_alloc(const model *md, const sim_method *cfg)
{
	rk4 *w = calloc(1, sizeof *w);
	if (!w)
		return NULL;
	w->n = md->n;
	w->dt = cfg->dt;
	w->k1 = malloc(sizeof(double) * 5 * (size_t)md->n);
	if (!w->k1) {
		rk4_free(w);
		return NULL;
	}
	w->k2 = w->k1 + md->n;
	w->k3 = w->k2 + md->n;
	w->k4 = w->k3 + md->n;
	w->tmp = w->k4 + md->n;
	return w;
}

static int rk4_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	rk4 *w = p;
	const int n = w->n;
	double h = ode_fixed_step(*t, w->dt, t_max);
	dyn_rhs(sys, *t, y, w->k1);
	for (int i = 0; i < n; i++)
		w->tmp[i] = y[i] + 0.5 * h * w->k1[i];
	dyn_rhs(sys, *t + 0.5 * h, w->tmp, w->k2);
	for (int i = 0; i < n; i++)
		w->tmp[i] = y[i] + 0.5 * h * w->k2[i];
	dyn_rhs(sys, *t + 0.5 * h, w->tmp, w->k3);
	for (int i = 0; i < n; i++)
		w->tmp[i] = y[i] + h * w->k3[i];
	dyn_rhs(sys, *t + h, w->tmp, w->k4);
	for (int i = 0; i < n; i++)
		y[i] += h / 6.0 * (w->k1[i] + 2.0 * (w->k2[i] + w->k3[i]) + w->k4[i]);
	*t = (h == t_max - *t) ? t_max : *t + h;
	return SIM_OK;
}

static void rk4_reset(void *p)
{
	(void)p;
}

const ode_method ode_rk4 = {
	.info = {.name = "rk4",
		 .order = 4,
		 .adaptive = 0,
		 .real_limit = RK4_REAL_LIMIT,
		 .radius_limit = RK4_RADIUS_LIMIT,
		 .doc = "classical Runge-Kutta, fixed step dt, whole state",
		 .dt_feed = 1e-5,
		 .dt_free = 1e-3,
		 .cost = 1},
	.dense = 0,
	.alloc = rk4_alloc,
	.step = rk4_step,
	.interpolate = NULL,
	.reset = rk4_reset,
	.free = rk4_free,
};
