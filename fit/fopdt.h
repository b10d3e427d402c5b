/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fopdt.h - a first-order-plus-dead-time model fitted to a step response:
 * the system identification behind the daemon's "identify" experiments and
 * the "auto" gains of its closed loop (docs/control.md).
 *
 * A response y(t) to steps of size d_j (any unit, e.g. deg of beta) at
 * times t_j is modelled as the superposition
 *
 *   y(t) = y0 + K sum_j d_j h(t - t_j - L),  h(s) = 1 - exp(-s/T) for s > 0,
 *   0 otherwise,
 *
 * so that steps that follow each other before the response settled are
 * still one model. Least squares over (y0, K, T, L): a grid over T and L
 * with y0 and K solved linearly at each node (variable projection), then
 * Levenberg-Marquardt on all four from the best node. Plain C, libm only.
 */
#ifndef CONVSIM_FOPDT_H
#define CONVSIM_FOPDT_H

#include <stddef.h>

typedef struct fopdt_result {
	double y0, k, t, l;          /* offset, gain, time constant (s), dead
					time (s) */
	double y0_se, k_se, t_se, l_se; /* standard errors, s^2 (J'J)^-1 */
	double rms;                  /* residual root mean square */
	size_t n;                    /* samples fitted */
	int iterations;
	int ok;                      /* 0: too few samples or no steps */
} fopdt_result;

/* Fit n samples (t[i] s, y[i]) to m steps (ts[j] s, d[j]). span (s) sets
 * the grid of T and L (the longest time a step's response is given to
 * settle). Returns 0, or -1 when the data cannot determine the model (fewer
 * than 8 samples, no step, or a singular problem): then r->ok is 0. */
int fopdt_fit(const double *t, const double *y, size_t n, const double *ts,
	      const double *d, size_t m, double span, fopdt_result *r);

/* The model's value at time t (s). */
double fopdt_eval(const fopdt_result *r, const double *ts, const double *d, size_t m,
		  double t);

/* PI gains by Skogestad's SIMC rule (J. Process Control 13 (2003) 291)
 * for the model r with closed-loop time constant tau_c (s): *kp = T / (|K|
 * (tau_c + L)) and *ki = *kp / min(T, 4 (tau_c + L)), in the inverse of K's
 * unit (and per s). NaN when the model has no gain. */
void fopdt_simc(const fopdt_result *r, double tau_c, double *kp, double *ki);

#endif
