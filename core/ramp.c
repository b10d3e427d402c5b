/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ramp.c - prescribed C1 motions for the controls: beta ramps (time-optimal
 * with bounded rate and acceleration, so beta' is continuous and beta'' is
 * bounded and piecewise constant) and the ideal drive's speed ramps.
 * A new command replans from the current value and rate, so a change in the
 * middle of a ramp stays continuous.
 */
#include <math.h>

#include "ramp.h"

void ramp_hold(ramp *r, double t, double value, double rate)
{
	r->n = 0;
	r->t_end = t;
	r->b_end = value;
	r->v_end = rate;
}

void ramp_eval(const ramp *r, double t, double *b, double *bd, double *bdd)
{
	for (int i = r->n - 1; i >= 0; i--) {
		if (t >= r->ts[i] && t < (i + 1 < r->n ? r->ts[i + 1] : r->t_end)) {
			double tau = t - r->ts[i];
			*b = r->b[i] + tau * (r->v[i] + 0.5 * r->a[i] * tau);
			*bd = r->v[i] + r->a[i] * tau;
			*bdd = r->a[i];
			return;
		}
	}
	if (r->n > 0 && t < r->ts[0]) { /* before the plan: hold its start */
		*b = r->b[0];
		*bd = r->v[0];
		*bdd = 0.0;
		return;
	}
	*b = r->b_end + r->v_end * (t - r->t_end);
	*bd = r->v_end;
	*bdd = 0.0;
}

/* Append a segment of constant acceleration a lasting dur from (b, v). */
static void push(ramp *r, double *t, double *b, double *v, double a, double dur)
{
	if (!(dur > 0.0))
		return;
	int i = r->n++;
	r->ts[i] = *t;
	r->b[i] = *b;
	r->v[i] = *v;
	r->a[i] = a;
	*b += dur * (*v + 0.5 * a * dur);
	*v += a * dur;
	*t += dur;
}

void ramp_to_position(ramp *r, double t, double target, double vmax, double amax)
{
	double b, v, a;
	ramp_eval(r, t, &b, &v, &a);
	r->n = 0;
	double d = target - b;
	/* distance needed to stop from v */
	double stop = v * fabs(v) / (2.0 * amax);
	double s = (d - stop) >= 0.0 ? 1.0 : -1.0;
	if (fabs(d - stop) < 1e-15 && fabs(v) <= vmax) {
		/* already on the braking curve */
		push(r, &t, &b, &v, -copysign(amax, v), fabs(v) / amax);
	} else {
		/* peak speed in direction s without cruise */
		double V = sqrt(fmax(0.0, (2.0 * amax * s * d + v * v) / 2.0));
		if (V > vmax)
			V = vmax;
		double a1 = (s * V - v) >= 0.0 ? amax : -amax;
		double t1 = fabs(s * V - v) / amax;
		double d1 = v * t1 + 0.5 * a1 * t1 * t1;
		double t3 = V / amax;
		double d3 = s * V * t3 / 2.0;
		double t2 = V > 0.0 ? (d - d1 - d3) / (s * V) : 0.0;
		if (t2 < 0.0)
			t2 = 0.0;
		push(r, &t, &b, &v, a1, t1);
		push(r, &t, &b, &v, 0.0, t2);
		push(r, &t, &b, &v, -s * amax, t3);
	}
	/* land exactly on the target at rest */
	r->t_end = t;
	r->b_end = target;
	r->v_end = 0.0;
}

void ramp_to_rate(ramp *r, double t, double v_target, double amax)
{
	double b, v, a;
	ramp_eval(r, t, &b, &v, &a);
	r->n = 0;
	double dv = v_target - v;
	push(r, &t, &b, &v, copysign(amax, dv), fabs(dv) / amax);
	r->t_end = t;
	r->b_end = b;
	r->v_end = v_target;
}
