/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_eval.c - the model evaluations of a fit. Each unit is one fresh
 * sim_measure (steady start, window up to t_end) at a set of free-parameter
 * values, one beta and one rotation; a batch of them runs through the
 * caller's map function (the daemon's pool) or on the library's (pmap.h).
 * A measured peak's model value comes from a scan of v(beta) on a fixed
 * grid around the measured beta (the grid point of the largest |v|) and a
 * least-squares parabola through that point and two neighbours each side,
 * with its uncertainty propagated from the error bars of those velocities;
 * when the largest |v| is on an end of the scan (or next to it), the scan
 * follows the peak beyond it (follow_peak).
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
#include "sim_mirror.h"
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

/* The grid point of the largest sign * v. */
static int best_of(const double *v, int n, double sign)
{
	int best = 0;
	for (int i = 1; i < n; i++)
		if (sign * v[i] > sign * v[best])
			best = i;
	return best;
}

/* The peak of a scan: the grid point of the largest sign * v and the
 * least-squares parabola through it and up to two neighbours each side;
 * when those show no extremum (a kink of v(beta) near the peak), the
 * parabola through it and one neighbour each side. */
static int vertex(const double *beta, const double *v, const double *u, int n, double sign,
		  double *peak, double *peak_u)
{
	int best = best_of(v, n, sign);
	for (int reach = 2; reach >= 1; reach--) {
		int lo = best - reach < 0 ? 0 : best - reach;
		int hi = best + reach >= n ? n - 1 : best + reach;
		if (hi - lo < 2)
			lo = hi - 2 < 0 ? 0 : hi - 2, hi = lo + 2;
		if (parabola(beta + lo, v + lo, u + lo, hi - lo + 1, sign, peak, peak_u) == 0)
			return 0;
	}
	return -1;
}

/* The scan of peak d at the free values x, followed past its ends: while
 * the largest |v| sits on an end of the scan or next to it (the peak may
 * lie beyond, and the parabola wants two neighbours each side), half a
 * scan more on that side, as far as [0, 180] deg allows, each in one more
 * batch. The vertex of the whole. 0, -1 with ev->failed when a
 * run fails, 1 when there is no peak. */
static int follow_peak(fit_eval *ev, const double *x, size_t d, const double *v0,
		       const double *u0, double *peak, double *peak_u)
{
	const fit_request *r = ev->req;
	int ng = ev->ngrid, cap = (int)floor(SIM_PI / r->peak_step + 1e-9) + 1 + ng, n = ng,
	    more = ng / 2 > 0 ? ng / 2 : 1, rc = 0;
	double *beta = malloc(sizeof(double) * (size_t)cap * 3), *v = beta + cap, *u = v + cap;
	if (!beta)
		return -1;
	memcpy(beta, ev->ubeta + d * (size_t)ng, sizeof(double) * (size_t)ng);
	memcpy(v, v0, sizeof(double) * (size_t)ng);
	memcpy(u, u0, sizeof(double) * (size_t)ng);
	double mean = 0;
	for (int i = 0; i < ng; i++)
		mean += v[i];
	double sign = mean < 0 ? -1 : 1;
	for (;;) {
		int best = best_of(v, n, sign), left = best < 2, k = 0;
		double nb[64], nv[64], nu[64];
		int rot[64];
		for (; k < more && k < 64 && n + k < cap; k++) {
			nb[k] = left ? beta[0] - (k + 1) * r->peak_step
				     : beta[n - 1] + (k + 1) * r->peak_step;
			if (nb[k] < -1e-9 || nb[k] > SIM_PI + 1e-9)
				break;
			rot[k] = r->peaks[d].rotation;
		}
		if ((best >= 2 && best <= n - 3) || k == 0)
			break;
		if (fit_eval_curve(ev, 1, x, (size_t)k, nb, rot, nv, nu) != 0) {
			rc = -1;
			break;
		}
		if (left) {
			memmove(beta + k, beta, sizeof(double) * (size_t)n);
			memmove(v + k, v, sizeof(double) * (size_t)n);
			memmove(u + k, u, sizeof(double) * (size_t)n);
		}
		for (int i = 0; i < k; i++) {
			int at = left ? k - 1 - i : n + i;
			beta[at] = nb[i], v[at] = nv[i], u[at] = nu[i];
		}
		n += k;
	}
	if (rc == 0 && vertex(beta, v, u, n, sign, peak, peak_u) != 0)
		rc = 1;
	free(beta);
	return rc;
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
			int found = follow_peak(ev, xs + s * (size_t)r->nfree, d, v + at, u + at,
						&out[o], &pu);
			if (found == 1)
				fail(ev, 1, "no peak of v near beta %g deg %s: %s", r->peaks[d].beta,
				     r->peaks[d].rotation,
				     "v(beta) has no maximum of |v| there, even followed to 0 or 180 deg");
			if (found != 0) {
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
