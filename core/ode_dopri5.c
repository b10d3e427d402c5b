/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode_dopri5.c - Dormand-Prince 5(4) with PI step-size control and the
 * fourth-order continuous extension for dense output (Dormand & Prince,
 * J. Comput. Appl. Math. 6, 1980; Hairer, Norsett, Wanner, Solving ODEs I,
 * sec. II.4-II.6: coefficients, error estimate, PI controller with
 * beta = 0.04, dense output of Shampine's type).
 *
 * The energy accumulators ride along but do not enter the error norm.
 * Steps are never shorter than hmin = 1e-7 s: the Coulomb and unloading
 * switches of the feed are discontinuities of the right-hand side, and in
 * their sliding modes (resting, sticking layers) no step size satisfies
 * the error estimate; such steps are accepted at hmin.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "ode.h"

typedef struct dopri5 {
	int n, nerr;
	double rtol, atol, h, hmax, hmin, facold;
	uint64_t forced; /* steps accepted at hmin */
	int have_k1;
	double *k[7], *ytmp, *ynew;
	/* dense output of the last step */
	double t_old, h_old;
	double *r1, *r2, *r3, *r4, *r5;
	double *block;
} dopri5;

static const double c2 = 1.0 / 5, c3 = 3.0 / 10, c4 = 4.0 / 5, c5 = 8.0 / 9;
static const double a21 = 1.0 / 5;
static const double a31 = 3.0 / 40, a32 = 9.0 / 40;
static const double a41 = 44.0 / 45, a42 = -56.0 / 15, a43 = 32.0 / 9;
static const double a51 = 19372.0 / 6561, a52 = -25360.0 / 2187, a53 = 64448.0 / 6561,
		    a54 = -212.0 / 729;
static const double a61 = 9017.0 / 3168, a62 = -355.0 / 33, a63 = 46732.0 / 5247,
		    a64 = 49.0 / 176, a65 = -5103.0 / 18656;
static const double a71 = 35.0 / 384, a73 = 500.0 / 1113, a74 = 125.0 / 192,
		    a75 = -2187.0 / 6784, a76 = 11.0 / 84;
static const double e1 = 71.0 / 57600, e3 = -71.0 / 16695, e4 = 71.0 / 1920,
		    e5 = -17253.0 / 339200, e6 = 22.0 / 525, e7 = -1.0 / 40;
static const double d1 = -12715105075.0 / 11282082432.0, d3 = 87487479700.0 / 32700410799.0,
		    d4 = -10690763975.0 / 1880347072.0, d5 = 701980252875.0 / 199316789632.0,
		    d6 = -1453857185.0 / 822651844.0, d7 = 69997945.0 / 29380423.0;

static void dp_free(void *p)
{
	dopri5 *w = p;
	if (!w)
		return;
	free(w->block);
	free(w);
}

static void *dp_alloc(const model *md, const sim_method *cfg)
{
	dopri5 *w = calloc(1, sizeof *w);
	if (!w)
		return NULL;
	w->n = md->n;
	w->nerr = 2 * md->npos;
	w->rtol = cfg->rtol;
	w->atol = cfg->atol;
	w->h = cfg->dt;
	w->hmax = 2e-3;
	w->hmin = 1e-7;
	w->facold = 1e-4;
	w->block = malloc(sizeof(double) * 14 * (size_t)md->n);
	if (!w->block) {
		dp_free(w);
		return NULL;
	}
	double *b = w->block;
	for (int i = 0; i < 7; i++, b += md->n)
		w->k[i] = b;
	w->ytmp = b, b += md->n;
	w->ynew = b, b += md->n;
	w->r1 = b, b += md->n;
	w->r2 = b, b += md->n;
	w->r3 = b, b += md->n;
	w->r4 = b, b += md->n;
	w->r5 = b;
	return w;
}

/* Scaled RMS norm of the embedded error estimate of a step of length h
 * from y to w->ynew (the energy accumulators excluded); 1e10 if not finite. */
static double error_norm(const dopri5 *w, const double *y, double h)
{
	double *const *k = w->k;
	double err = 0.0;
	for (int i = 0; i < w->nerr; i++) {
		double ei = h * (e1 * k[0][i] + e3 * k[2][i] + e4 * k[3][i] + e5 * k[4][i] +
				 e6 * k[5][i] + e7 * k[6][i]);
		double sc = w->atol + w->rtol * fmax(fabs(y[i]), fabs(w->ynew[i]));
		err += (ei / sc) * (ei / sc);
	}
	err = sqrt(err / (double)w->nerr);
	return isfinite(err) ? err : 1e10;
}

/* Dense output coefficients r1..r5 of an accepted step of length h from y
 * to w->ynew. */
static void dense_coefficients(dopri5 *w, const double *y, double h)
{
	double *const *k = w->k;
	for (int i = 0; i < w->n; i++) {
		double dy = w->ynew[i] - y[i];
		double bspl = h * k[0][i] - dy;
		w->r1[i] = y[i];
		w->r2[i] = dy;
		w->r3[i] = bspl;
		w->r4[i] = dy - h * k[6][i] - bspl;
		w->r5[i] = h * (d1 * k[0][i] + d3 * k[2][i] + d4 * k[3][i] + d5 * k[4][i] +
				d6 * k[5][i] + d7 * k[6][i]);
	}
}

static int dp_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	dopri5 *w = p;
	const int n = w->n;
	double **k = w->k;
	(void)t_max;
	if (!w->have_k1) {
		dyn_rhs(sys, *t, y, k[0]);
		w->have_k1 = 1;
	}
	for (;;) {
		double h = fmin(w->h, w->hmax);
		/* the feed's switching laws (sgn friction, the unloading switch)
		 * make the error estimate useless in sliding modes: below hmin
		 * the step is accepted as it is, and counted */
		int floor_step = h <= w->hmin;
		if (floor_step)
			h = w->hmin;
		for (int i = 0; i < n; i++)
			w->ytmp[i] = y[i] + h * a21 * k[0][i];
		dyn_rhs(sys, *t + c2 * h, w->ytmp, k[1]);
		for (int i = 0; i < n; i++)
			w->ytmp[i] = y[i] + h * (a31 * k[0][i] + a32 * k[1][i]);
		dyn_rhs(sys, *t + c3 * h, w->ytmp, k[2]);
		for (int i = 0; i < n; i++)
			w->ytmp[i] = y[i] + h * (a41 * k[0][i] + a42 * k[1][i] + a43 * k[2][i]);
		dyn_rhs(sys, *t + c4 * h, w->ytmp, k[3]);
		for (int i = 0; i < n; i++)
			w->ytmp[i] = y[i] + h * (a51 * k[0][i] + a52 * k[1][i] + a53 * k[2][i] +
						 a54 * k[3][i]);
		dyn_rhs(sys, *t + c5 * h, w->ytmp, k[4]);
		for (int i = 0; i < n; i++)
			w->ytmp[i] = y[i] + h * (a61 * k[0][i] + a62 * k[1][i] + a63 * k[2][i] +
						 a64 * k[3][i] + a65 * k[4][i]);
		dyn_rhs(sys, *t + h, w->ytmp, k[5]);
		for (int i = 0; i < n; i++)
			w->ynew[i] = y[i] + h * (a71 * k[0][i] + a73 * k[2][i] + a74 * k[3][i] +
						 a75 * k[4][i] + a76 * k[5][i]);
		dyn_rhs(sys, *t + h, w->ynew, k[6]);
		double err = error_norm(w, y, h);
		/* PI controller */
		const double beta = 0.04, expo1 = 0.2 - beta * 0.75, safe = 0.9;
		double fac11 = pow(err, expo1);
		if (err <= 1.0 || floor_step) {
			w->forced += floor_step;
			double fac = fac11 / pow(w->facold, beta);
			fac = fmax(0.1, fmin(5.0, fac / safe));
			w->facold = fmax(err, 1e-4);
			dense_coefficients(w, y, h);
			w->t_old = *t;
			w->h_old = h;
			memcpy(y, w->ynew, sizeof(double) * (size_t)n);
			/* FSAL: the last stage is the next step's first */
			double *tmp = k[0];
			k[0] = k[6];
			k[6] = tmp;
			*t += h;
			w->h = h / fac;
			return SIM_OK;
		}
		w->h = h / fmin(10.0, fac11 / safe);
	}
}

static void dp_interpolate(void *p, double t, double *out)
{
	dopri5 *w = p;
	double th = (t - w->t_old) / w->h_old, th1 = 1.0 - th;
	for (int i = 0; i < w->n; i++)
		out[i] = w->r1[i] +
			 th * (w->r2[i] + th1 * (w->r3[i] + th * (w->r4[i] + th1 * w->r5[i])));
}

static void dp_reset(void *p)
{
	dopri5 *w = p;
	w->have_k1 = 0;
}

/* Carried between steps: the controller's step and memory, the FSAL
 * stage k[0] and the last step's dense output (r1..r5 over t_old, h_old).
 * The other stages are scratch. */
typedef struct dp_scalars {
	double h, facold, t_old, h_old;
	uint64_t forced;
	int have_k1;
} dp_scalars;

static size_t dp_state_size(const void *p)
{
	const dopri5 *w = p;
	return sizeof(dp_scalars) + 6 * sizeof(double) * (size_t)w->n;
}

static void dp_save(const void *p, void *buf)
{
	const dopri5 *w = p;
	dp_scalars sc = {w->h, w->facold, w->t_old, w->h_old, w->forced, w->have_k1};
	const double *vec[6] = {w->k[0], w->r1, w->r2, w->r3, w->r4, w->r5};
	size_t len = sizeof(double) * (size_t)w->n;
	char *b = buf;
	memcpy(b, &sc, sizeof sc);
	for (int i = 0; i < 6; i++)
		memcpy(b + sizeof sc + (size_t)i * len, vec[i], len);
}

static void dp_load(void *p, const void *buf)
{
	dopri5 *w = p;
	dp_scalars sc;
	double *vec[6] = {w->k[0], w->r1, w->r2, w->r3, w->r4, w->r5};
	size_t len = sizeof(double) * (size_t)w->n;
	const char *b = buf;
	memcpy(&sc, b, sizeof sc);
	for (int i = 0; i < 6; i++)
		memcpy(vec[i], b + sizeof sc + (size_t)i * len, len);
	w->h = sc.h;
	w->facold = sc.facold;
	w->t_old = sc.t_old;
	w->h_old = sc.h_old;
	w->forced = sc.forced;
	w->have_k1 = sc.have_k1;
}

const ode_method ode_dopri5 = {
	.info = {.name = "dopri5",
		 .order = 5,
		 .adaptive = 1,
		 .doc = "Dormand-Prince 5(4), PI step control, dense output; dt is the first step",
		 .dt_feed = 1e-5, /* the first step */
		 .dt_free = 1e-5,
		 .cost = 1},
	.dense = 1,
	.alloc = dp_alloc,
	.step = dp_step,
	.interpolate = dp_interpolate,
	.reset = dp_reset,
	.free = dp_free,
	.state_size = dp_state_size,
	.save = dp_save,
	.load = dp_load,
};
