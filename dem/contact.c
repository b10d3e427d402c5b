/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * contact.c - the linear spring-dashpot contact's restitution and its
 * inverse, the damping ratio that gives a restitution (dem.h): the
 * bed's contacts are set from the latter, the report of a run prints the
 * former. Pure arithmetic, no LIGGGHTS.
 */
#include <math.h>

#include "dem.h"

/* Restitution of the linear contact with damping ratio zeta, the force
 * never attractive: x'' = -max(0, x + 2 zeta x') from x = 0, x' = 1 until
 * x < 0 again (time in units of 1/omega), RK4. */
double dem_restitution(double zeta)
{
	double x = 0, v = 1, h = 1e-4;
	for (int i = 0; i < 400000; i++) {
		double k1x = v, k1v = -fmax(0, x + 2 * zeta * v);
		double x2 = x + 0.5 * h * k1x, v2 = v + 0.5 * h * k1v;
		double k2x = v2, k2v = -fmax(0, x2 + 2 * zeta * v2);
		double x3 = x + 0.5 * h * k2x, v3 = v + 0.5 * h * k2v;
		double k3x = v3, k3v = -fmax(0, x3 + 2 * zeta * v3);
		double x4 = x + h * k3x, v4 = v + h * k3v;
		double k4x = v4, k4v = -fmax(0, x4 + 2 * zeta * v4);
		double xn = x + h / 6 * (k1x + 2 * k2x + 2 * k3x + k4x);
		double vn = v + h / 6 * (k1v + 2 * k2v + 2 * k3v + k4v);
		if (xn < 0) /* interpolate the exit speed linearly */
			return -(v + (vn - v) * x / (x - xn));
		x = xn;
		v = vn;
	}
	return 0; /* overdamped: the grain never leaves by itself */
}

double dem_restitution_damping(double e)
{
	double lo = 0, hi = 1;
	if (e >= 1)
		return 0;
	/* past critical damping (e 0.135) the grain still leaves sooner and
	 * slower as zeta grows: widen the bracket until it holds e */
	while (dem_restitution(hi) > e && hi < 1e3) {
		lo = hi;
		hi *= 2;
	}
	for (int i = 0; i < 50; i++) {
		double mid = 0.5 * (lo + hi);
		if (dem_restitution(mid) > e)
			lo = mid;
		else
			hi = mid;
	}
	return 0.5 * (lo + hi);
}
