/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fopdt.c - least squares of a first-order-plus-dead-time step response
 * (fopdt.h): a grid over the time constant and the dead time with the
 * offset and the gain solved linearly at each node, then
 * Levenberg-Marquardt on the four parameters with the analytic Jacobian,
 * and the standard errors from s^2 (J'J)^-1.
 */
#include <math.h>
#include <string.h>

#include "fopdt.h"

#define NP 4 /* y0, k, t, l */
#define GRID 24
#define MAX_ITER 200

/* The step sum S = sum_j d_j h(s_j) and its derivatives by T and by L
 * (without the gain) at time x. */
static void step_sum(const double *ts, const double *d, size_t m, double T, double L,
		     double x, double *S, double *dT, double *dL)
{
	*S = *dT = *dL = 0;
	for (size_t j = 0; j < m; j++) {
		double s = x - ts[j] - L;
		if (s <= 0)
			continue;
		double e = exp(-s / T);
		*S += d[j] * (1 - e);
		*dT -= d[j] * e * s / (T * T);
		*dL -= d[j] * e / T;
	}
}

double fopdt_eval(const fopdt_result *r, const double *ts, const double *d, size_t m,
		  double t)
{
	double S, dT, dL;
	step_sum(ts, d, m, r->t, r->l, t, &S, &dT, &dL);
	return r->y0 + r->k * S;
}

/* Sum of squared residuals at p. */
static double ssr(const double *t, const double *y, size_t n, const double *ts,
		  const double *d, size_t m, const double *p)
{
	double sum = 0;
	for (size_t i = 0; i < n; i++) {
		double S, dT, dL;
		step_sum(ts, d, m, p[2], p[3], t[i], &S, &dT, &dL);
		double r = y[i] - p[0] - p[1] * S;
		sum += r * r;
	}
	return sum;
}

/* y0 and k by linear least squares at fixed T and L; the residual sum. */
static double linear_part(const double *t, const double *y, size_t n, const double *ts,
			  const double *d, size_t m, double *p)
{
	double s1 = 0, ss = 0, sy = 0, sss = 0, ssy = 0;
	for (size_t i = 0; i < n; i++) {
		double S, dT, dL;
		step_sum(ts, d, m, p[2], p[3], t[i], &S, &dT, &dL);
		s1 += 1, ss += S, sy += y[i], sss += S * S, ssy += S * y[i];
	}
	double det = s1 * sss - ss * ss;
	if (!(fabs(det) > 1e-300))
		return INFINITY;
	p[0] = (sy * sss - ss * ssy) / det;
	p[1] = (s1 * ssy - ss * sy) / det;
	return ssr(t, y, n, ts, d, m, p);
}

/* Solve a (NP x NP, overwritten) x = b in place by Gauss-Jordan with
 * partial pivoting; inv (may be NULL) gets a's inverse. 0 or -1. */
static int solve(double a[NP][NP], double *b, double inv[NP][NP])
{
	double w[NP][NP];
	for (int i = 0; i < NP; i++)
		for (int j = 0; j < NP; j++)
			w[i][j] = i == j;
	for (int c = 0; c < NP; c++) {
		int piv = c;
		for (int r = c + 1; r < NP; r++)
			if (fabs(a[r][c]) > fabs(a[piv][c]))
				piv = r;
		if (!(fabs(a[piv][c]) > 1e-300))
			return -1;
		for (int k = 0; k < NP; k++) {
			double x = a[c][k]; a[c][k] = a[piv][k]; a[piv][k] = x;
			x = w[c][k]; w[c][k] = w[piv][k]; w[piv][k] = x;
		}
		double x = b[c]; b[c] = b[piv]; b[piv] = x;
		double f = a[c][c];
		for (int k = 0; k < NP; k++)
			a[c][k] /= f, w[c][k] /= f;
		b[c] /= f;
		for (int r = 0; r < NP; r++)
			if (r != c && a[r][c] != 0) {
				double g = a[r][c];
				for (int k = 0; k < NP; k++)
					a[r][k] -= g * a[c][k], w[r][k] -= g * w[c][k];
				b[r] -= g * b[c];
			}
	}
	if (inv)
		memcpy(inv, w, sizeof w);
	return 0;
}

/* J'J and J'r at p. */
static void normal_eq(const double *t, const double *y, size_t n, const double *ts,
		      const double *d, size_t m, const double *p, double jtj[NP][NP],
		      double *jtr)
{
	memset(jtj, 0, sizeof(double) * NP * NP);
	memset(jtr, 0, sizeof(double) * NP);
	for (size_t i = 0; i < n; i++) {
		double S, dT, dL;
		step_sum(ts, d, m, p[2], p[3], t[i], &S, &dT, &dL);
		double g[NP] = {1, S, p[1] * dT, p[1] * dL};
		double r = y[i] - p[0] - p[1] * S;
		for (int a = 0; a < NP; a++) {
			jtr[a] += g[a] * r;
			for (int b = 0; b < NP; b++)
				jtj[a][b] += g[a] * g[b];
		}
	}
}

/* Levenberg-Marquardt from p (the step kept within T > 0, L >= 0). */
static int refine(const double *t, const double *y, size_t n, const double *ts,
		  const double *d, size_t m, double *p, double tmin)
{
	double lambda = 1e-3, cost = ssr(t, y, n, ts, d, m, p);
	int it;
	for (it = 0; it < MAX_ITER; it++) {
		double jtj[NP][NP], jtr[NP];
		normal_eq(t, y, n, ts, d, m, p, jtj, jtr);
		int better = 0;
		while (lambda < 1e12 && !better) {
			double a[NP][NP], step[NP], q[NP];
			memcpy(a, jtj, sizeof a);
			memcpy(step, jtr, sizeof step);
			for (int k = 0; k < NP; k++)
				a[k][k] += lambda * (jtj[k][k] > 0 ? jtj[k][k] : 1);
			if (solve(a, step, NULL) != 0) {
				lambda *= 10;
				continue;
			}
			for (int k = 0; k < NP; k++)
				q[k] = p[k] + step[k];
			if (q[2] < tmin)
				q[2] = tmin;
			if (q[3] < 0)
				q[3] = 0;
			double c = ssr(t, y, n, ts, d, m, q);
			if (c < cost) {
				double gain = cost - c;
				memcpy(p, q, sizeof q);
				cost = c;
				lambda = lambda > 1e-9 ? lambda / 10 : lambda;
				better = 1;
				if (gain < 1e-14 * (cost + 1e-300))
					return it + 1;
			} else {
				lambda *= 10;
			}
		}
		if (!better)
			break;
	}
	return it;
}

int fopdt_fit(const double *t, const double *y, size_t n, const double *ts,
	      const double *d, size_t m, double span, fopdt_result *r)
{
	memset(r, 0, sizeof *r);
	r->y0 = r->k = r->t = r->l = NAN;
	r->y0_se = r->k_se = r->t_se = r->l_se = r->rms = NAN;
	if (n < 8 || m < 1 || !(span > 0))
		return -1;
	/* the grid: T from span/1000 to span/2 geometrically, L from 0 to
	 * span/2 */
	double best = INFINITY, p[NP] = {0}, tmin = span * 1e-4;
	for (int a = 0; a < GRID; a++)
		for (int b = 0; b < GRID; b++) {
			double q[NP];
			q[2] = span * 1e-3 * pow(500.0, (double)a / (GRID - 1));
			q[3] = 0.5 * span * b / (GRID - 1);
			double c = linear_part(t, y, n, ts, d, m, q);
			if (c < best)
				best = c, memcpy(p, q, sizeof p);
		}
	if (!isfinite(best))
		return -1;
	r->iterations = refine(t, y, n, ts, d, m, p, tmin);
	double jtj[NP][NP], jtr[NP], cov[NP][NP];
	normal_eq(t, y, n, ts, d, m, p, jtj, jtr);
	if (solve(jtj, jtr, cov) != 0)
		return -1;
	double s2 = ssr(t, y, n, ts, d, m, p) / (double)(n - NP);
	r->y0 = p[0], r->k = p[1], r->t = p[2], r->l = p[3];
	r->y0_se = sqrt(s2 * cov[0][0]);
	r->k_se = sqrt(s2 * cov[1][1]);
	r->t_se = sqrt(s2 * cov[2][2]);
	r->l_se = sqrt(s2 * cov[3][3]);
	r->rms = sqrt(s2 * (double)(n - NP) / (double)n);
	r->n = n;
	r->ok = 1;
	return 0;
}

void fopdt_simc(const fopdt_result *r, double tau_c, double *kp, double *ki)
{
	double k = fabs(r->k);
	if (!(k > 0) || !(r->t > 0) || !(tau_c + r->l > 0)) {
		*kp = *ki = NAN;
		return;
	}
	*kp = r->t / (k * (tau_c + r->l));
	double ti = fmin(r->t, 4 * (tau_c + r->l));
	*ki = *kp / ti;
}
