/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode_euler.c - semi-implicit (symplectic) Euler with a fixed step:
 * v_{n+1} = v_n + h a(q_n, v_n), q_{n+1} = q_n + h v_{n+1}
 * (Hairer, Lubich, Wanner, Geometric Numerical Integration, sec. I.1.2).
 * First order; the usual baseline of discrete-element codes.
 */
#include <stdlib.h>

#include "ode.h"

typedef struct euler {
	double dt;
	double *f;
} euler;

static void euler_free(void *p)
{
	euler *w = p;
	if (!w)
		return;
	free(w->f);
	free(w);
}

static void *euler_alloc(const model *md, const sim_method *cfg)
{
	euler *w = calloc(1, sizeof *w);
	if (!w)
		return NULL;
	w->dt = cfg->dt;
	w->f = malloc(sizeof(double) * (size_t)md->n);
	if (!w->f) {
		euler_free(w);
		return NULL;
	}
	return w;
}

static int euler_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	euler *w = p;
	const model *md = sys->md;
	const int np = md->npos;
	double h = ode_fixed_step(*t, w->dt, t_max);
	dyn_rhs(sys, *t, y, w->f);
	for (int i = 0; i < np; i++) {
		y[np + i] += h * w->f[np + i];
		y[i] += h * y[np + i];
	}
	for (int i = 2 * np; i < md->n; i++)
		y[i] += h * w->f[i];
	*t = (h == t_max - *t) ? t_max : *t + h;
	return SIM_OK;
}

static void euler_reset(void *p)
{
	(void)p;
}

const ode_method ode_euler = {
	.info = {.name = "euler",
		 .order = 1,
		 .adaptive = 0,
		 .real_limit = 2.0,
		 /* on x'' = -k x - c x' it holds h |lambda| <= 2 undamped but
		  * only 2 (sqrt 2 - 1) = 0.828 at critical damping */
		 .radius_limit = 0.82,
		 .doc = "semi-implicit (symplectic) Euler, fixed step dt",
		 .dt_feed = 5e-6,
		 .dt_free = 1e-5,
		 .cost = 0.25}, /* one right-hand side a step, not four */
	.dense = 0,
	.alloc = euler_alloc,
	.step = euler_step,
	.interpolate = NULL,
	.reset = euler_reset,
	.free = euler_free,
};
