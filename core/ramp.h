/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ramp.h - internal: prescribed C1 motions for the controls (beta ramps,
 * the ideal drive's speed ramps). Units are those of the value: rad, rad/s,
 * rad/s^2 for the controls that use them; times in s.
 */
#ifndef CONVSIM_RAMP_H
#define CONVSIM_RAMP_H

/* A C1 motion with piecewise-constant second derivative: segments that
 * start at ts[i] with value b[i], rate v[i], and constant acceleration a[i];
 * after the last segment the motion continues at rate v_end from b_end. */
typedef struct ramp {
	int n;
	double ts[4], b[4], v[4], a[4];
	double t_end, b_end, v_end;
} ramp;

/* Hold value at t and move on at a constant rate from there. */
void ramp_hold(ramp *r, double t, double value, double rate);
/* Value, rate and acceleration at t (all written). */
void ramp_eval(const ramp *r, double t, double *b, double *bd, double *bdd);
/* Time-optimal move from the state at t to rest at target, |rate| <= vmax,
 * |accel| <= amax. */
void ramp_to_position(ramp *r, double t, double target, double vmax, double amax);
/* Change the rate to v_target at |accel| = amax, then keep it. */
void ramp_to_rate(ramp *r, double t, double v_target, double amax);

#endif
