/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_eval.c - the model evaluations of a fit. Each unit is one fresh
 * sim_measure (steady start, window up to t_end) at a set of free-parameter
 * values, one beta and one rotation; a batch of them runs through the
 * caller's map function (the daemon's pool) or on the library's (pmap.h).
 * A measured peak's model value comes from a scan of v(beta) on a fixed
 * grid around the measured beta (the grid point of the largest |v|) and a
 * least-squares parabola through that point and two neighbours each side,
 * with its uncertainty propagated from the error bars of those velocities.
 * A batch takes the mirror reduction (sim_mirror_plan) within each
 * parameter set: a unit that is the mirror image of another of the same
 * set is not run but taken from it, v negated.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit_int.h"
#include "pmap.h"
#include "units.h"

int fit_eval_init(fit_eval *ev, const fit_request *req)
{
	memset(ev, 0, sizeof *ev);
	ev->req = req;
	if (req->npoints) {
		ev->ndata = ev->nunits = req->npoints;
	} else {
		int half = (int)lround(req->peak_halfwidth / req->peak_step);
		ev->ngrid = 2 * half + 1;
		ev->ndata = (size_t)req->npeaks;
		ev->nunits = (size_t)req->npeaks * (size_t)ev->ngrid;
	}
	ev->ubeta = malloc(sizeof *ev->ubeta * ev->nunits);
	ev->urot = malloc(sizeof *ev->urot * ev->nunits);
	if (!ev->ubeta || !ev->urot) {
		fit_eval_free(ev);
		return -1;
	}
	pthread_mutex_init(&ev->lock, NULL);
	for (size_t i = 0; i < req->npoints; i++) {
		ev->ubeta[i] = req->points[i].beta;
		ev->urot[i] = req->points[i].rotation;
	}
	for (int k = 0; k < req->npeaks; k++) {
		double half = (ev->ngrid / 2) * req->peak_step;
		/* the scan stays within [0, 180] deg */
		double c = fmin(fmax(req->peaks[k].beta, half), SIM_PI - half);
		for (int i = 0; i < ev->ngrid; i++) {
			size_t u = (size_t)k * (size_t)ev->ngrid + (size_t)i;
			ev->ubeta[u] = c + (i - ev->ngrid / 2) * req->peak_step;
			ev->urot[u] = req->peaks[k].rotation;
		}
	}
	return 0;
}

void fit_eval_free(fit_eval *ev)
{
	if (ev->ubeta && ev->urot)
		pthread_mutex_destroy(&ev->lock);
	free(ev->ubeta);
	free(ev->urot);
	ev->ubeta = NULL;
	ev->urot = NULL;
}

/* ---- one batch ----------------------------------------------------------- */

typedef struct batch {
	fit_eval *ev;
	const double *xs;
	size_t n;             /* units per set */
	const double *beta;
	const int *rotation;
	double *v, *u;
	const size_t *run;    /* the units that run (the others are images) */
} batch;

/* The model of parameter set `set`: the request's with the set's free
 * values. SIM_OK, or sim_set's code with msg. */
static int set_model(const batch *b, size_t set, sim_params *p, sim_scene *sc, sim_method *m,
		     char *msg, size_t msglen)
{
	const fit_request *r = b->ev->req;
	*p = r->p;
	*sc = r->sc;
	*m = r->m;
	for (int j = 0; j < r->nfree; j++) {
		int e = sim_set(p, sc, m, r->free[j].name, b->xs[set * (size_t)r->nfree + (size_t)j],
				msg, msglen);
		if (e != SIM_OK)
			return e;
	}
	return SIM_OK;
}

static void fail(fit_eval *ev, int why, const char *fmt, double beta, int rot, const char *msg)
{
	pthread_mutex_lock(&ev->lock);
	if (!ev->failed) {
		ev->failed = why;
		snprintf(ev->error, sizeof ev->error, fmt, beta * DEG_PER_RAD,
			 rot == SIM_CW ? "cw" : "ccw", msg);
	}
	pthread_mutex_unlock(&ev->lock);
}

static void run_unit(void *arg, size_t k)
{
	batch *b = arg;
	fit_eval *ev = b->ev;
	const fit_request *r = ev->req;
	size_t set = k / b->n, i = k % b->n;
	b->v[k] = b->u[k] = NAN;
	pthread_mutex_lock(&ev->lock);
	int stop = ev->failed || (r->cancelled && r->cancelled(r->ctx));
	if (stop && !ev->failed)
		ev->failed = 2;
	pthread_mutex_unlock(&ev->lock);
	if (stop)
		return;
	sim_params p;
	sim_scene sc;
	sim_method m;
	char msg[160] = "";
	if (set_model(b, set, &p, &sc, &m, msg, sizeof msg) != SIM_OK) {
		fail(ev, 1, "beta %g deg %s: %s", b->beta[i], b->rotation[i], msg);
		return;
	}
	p.beta = b->beta[i];
	p.rotation = b->rotation[i];
	sim_measurement ms;
	int rc = sim_measure(&p, &sc, &m, r->t_end, &ms, msg, sizeof msg);
	pthread_mutex_lock(&ev->lock);
	ev->evaluations++;
	ev->cpu_seconds += ms.cpu_seconds;
	pthread_mutex_unlock(&ev->lock);
	if (rc != SIM_OK)
		fail(ev, 1, "the model failed at beta %g deg %s: %s", b->beta[i], b->rotation[i],
		     msg[0] ? msg : sim_strerror(rc));
	else if (!isfinite(ms.transport_velocity))
		fail(ev, 1, "no transport velocity at beta %g deg %s%s", b->beta[i], b->rotation[i],
		     ": t_end leaves less than one excitation period to measure");
	b->v[k] = ms.transport_velocity;
	b->u[k] = ms.uncertainty;
}

static void run_listed(void *arg, size_t k)
{
	batch *b = arg;
	run_unit(b, b->run[k]);
}

/* The mirror reduction's plan of each set: the units to run into run
 * (their count returned), image[k] = the unit whose image unit k is, or
 * (size_t)-1. A set whose values cannot be set runs every unit (and
 * fails there with the reason). */
static size_t plan(const batch *b, size_t nsets, size_t *run, size_t *image, long *source)
{
	size_t nrun = 0;
	for (size_t set = 0; set < nsets; set++) {
		sim_params p;
		sim_scene sc;
		sim_method m;
		char msg[160];
		if (set_model(b, set, &p, &sc, &m, msg, sizeof msg) == SIM_OK)
			sim_mirror_plan(&p, &sc, b->n, b->beta, b->rotation, source);
		else
			for (size_t i = 0; i < b->n; i++)
				source[i] = -1;
		for (size_t i = 0; i < b->n; i++) {
			size_t k = set * b->n + i;
			image[k] = source[i] < 0 ? (size_t)-1 : set * b->n + (size_t)source[i];
			if (source[i] < 0)
				run[nrun++] = k;
		}
	}
	return nrun;
}

int fit_eval_curve(fit_eval *ev, size_t nsets, const double *xs, size_t n, const double *beta,
		   const int *rotation, double *v, double *u)
{
	const fit_request *r = ev->req;
	size_t total = nsets * n;
	double *ubuf = u ? NULL : malloc(sizeof *ubuf * total);
	size_t *run = malloc(sizeof *run * (total ? total : 1)),
	       *image = malloc(sizeof *image * (total ? total : 1));
	long *source = malloc(sizeof *source * (n ? n : 1));
	if ((!u && !ubuf) || !run || !image || !source) {
		free(ubuf);
		free(run);
		free(image);
		free(source);
		return -1;
	}
	batch b = {ev, xs, n, beta, rotation, v, u ? u : ubuf, run};
	size_t nrun = plan(&b, nsets, run, image, source);
	if (r->map)
		r->map(r->map_ctx, nrun, run_listed, &b);
	else
		pmap_run(r->threads, nrun, run_listed, &b, NULL);
	for (size_t k = 0; k < total; k++)
		if (image[k] != (size_t)-1) {
			b.v[k] = -b.v[image[k]];
			b.u[k] = b.u[image[k]];
		}
	free(ubuf);
	free(run);
	free(image);
	free(source);
	if (!ev->failed && r->cancelled && r->cancelled(r->ctx))
		ev->failed = 2;
	return ev->failed ? -1 : 0;
}

/* ---- peaks ---------------------------------------------------------------- */

/* The vertex (rad) of the least-squares parabola through the n velocities
 * v at beta (the extremum of |v|: a maximum of v where v > 0, a minimum
 * where v < 0), and its uncertainty from the error bars u. Returns -1 when
 * the points show no extremum (the parabola opens the wrong way). */
static int parabola(const double *beta, const double *v, const double *u, int n, double sign,
		    double *peak, double *peak_u)
{
	double c = beta[n / 2], s[5] = {0}, t[3] = {0};
	for (int i = 0; i < n; i++) {
		double x = beta[i] - c, pw = 1;
		for (int k = 0; k < 5; k++, pw *= x)
			s[k] += pw;
		t[0] += sign * v[i], t[1] += sign * v[i] * x, t[2] += sign * v[i] * x * x;
	}
	/* normal equations N a = t, N[j][k] = s[j + k]; N^-1 by cofactors */
	double N[3][3] = {{s[0], s[1], s[2]}, {s[1], s[2], s[3]}, {s[2], s[3], s[4]}}, inv[3][3];
	double det = N[0][0] * (N[1][1] * N[2][2] - N[1][2] * N[2][1]) -
		     N[0][1] * (N[1][0] * N[2][2] - N[1][2] * N[2][0]) +
		     N[0][2] * (N[1][0] * N[2][1] - N[1][1] * N[2][0]);
	for (int j = 0; j < 3; j++)
		for (int k = 0; k < 3; k++) {
			int j1 = (k + 1) % 3, j2 = (k + 2) % 3, k1 = (j + 1) % 3, k2 = (j + 2) % 3;
			inv[j][k] = (N[j1][k1] * N[j2][k2] - N[j1][k2] * N[j2][k1]) / det;
		}
	double a[3];
	for (int j = 0; j < 3; j++)
		a[j] = inv[j][0] * t[0] + inv[j][1] * t[1] + inv[j][2] * t[2];
	if (!(a[2] < 0))
		return -1;
	/* within the points, so that the least squares see a finite value */
	double x = fmin(fmax(-a[1] / (2 * a[2]), beta[0] - c), beta[n - 1] - c);
	*peak = c + x;
	double g1 = -1 / (2 * a[2]), g2 = a[1] / (2 * a[2] * a[2]), var = 0;
	for (int i = 0; i < n; i++) {
		double xi = beta[i] - c, d = 0;
		for (int j = 0; j < 3; j++)
			d += (g1 * inv[1][j] + g2 * inv[2][j]) * (j == 0 ? 1 : j == 1 ? xi : xi * xi);
		var += d * d * u[i] * u[i];
	}
	*peak_u = sqrt(var);
	return 0;
}

/* The peak of a scan: the grid point of the largest |v| and the
 * least-squares parabola through it and up to two neighbours each side. */
static int vertex(const double *beta, const double *v, const double *u, int n, double *peak,
		  double *peak_u)
{
	double mean = 0;
	for (int i = 0; i < n; i++)
		mean += v[i];
	double sign = mean < 0 ? -1 : 1;
	int best = 0;
	for (int i = 1; i < n; i++)
		if (sign * v[i] > sign * v[best])
			best = i;
	int lo = best - 2 < 0 ? 0 : best - 2, hi = best + 2 >= n ? n - 1 : best + 2;
	if (hi - lo < 2)
		lo = hi - 2 < 0 ? 0 : hi - 2, hi = lo + 2;
	return parabola(beta + lo, v + lo, u + lo, hi - lo + 1, sign, peak, peak_u);
}

int fit_eval_data(fit_eval *ev, size_t nsets, const double *xs, double *out, double *out_u)
{
	const fit_request *r = ev->req;
	size_t nu = ev->nunits;
	double *v = malloc(sizeof *v * nsets * nu), *u = malloc(sizeof *u * nsets * nu);
	int rc = v && u ? fit_eval_curve(ev, nsets, xs, nu, ev->ubeta, ev->urot, v, u) : -1;
	if (!v || !u)
		snprintf(ev->error, sizeof ev->error, "out of memory"), ev->failed = 1;
	for (size_t s = 0; rc == 0 && s < nsets; s++)
		for (size_t d = 0; d < ev->ndata; d++) {
			size_t o = s * ev->ndata + d;
			if (r->npoints) {
				out[o] = v[s * nu + d];
				if (out_u)
					out_u[o] = u[s * nu + d];
				continue;
			}
			size_t at = s * nu + d * (size_t)ev->ngrid;
			double pu;
			if (vertex(ev->ubeta + d * (size_t)ev->ngrid, v + at, u + at, ev->ngrid,
				   &out[o], &pu) != 0) {
				fail(ev, 1, "no peak of v near beta %g deg %s: %s", r->peaks[d].beta,
				     r->peaks[d].rotation,
				     "v(beta) over the scan has no maximum of |v|");
				rc = -1;
				break;
			}
			if (out_u)
				out_u[o] = pu;
		}
	free(v);
	free(u);
	return rc;
}
