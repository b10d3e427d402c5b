/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * angle.h - sine and cosine of the machine's angles (the rotor's phi four
 * times a machine step, the trough's alpha), cheaper than libm's call
 * where they are evaluated most.
 */
#ifndef CONVSIM_ANGLE_H
#define CONVSIM_ANGLE_H

#include <math.h>

/* sin and cos of x (rad), inlined: x = k pi/2 + r with |r| <= pi/4,
 * pi/2 in three parts, the first two of at most 30 bits, so that k times
 * each is exact for |k| < 2^23; then the Taylor series of sin r to r^17
 * and of cos r to r^16 (the first terms left out are below 1e-17).
 * Beyond |x| = 1.26e7 rad (a day of the rotor at 145 rad/s), and for x
 * not finite, libm's. Within 3 ulps of libm's (test_machine.c), odd and
 * even exactly. */
static inline void angle_sincos(double x, double *s, double *c)
{
	static const double P1 = 0x1.921fb54p+0, P2 = 0x1.10b46118p-30,
			    P3 = 0x1.313198a2e0370p-61;
	if (!(fabs(x) < 0x1.8p23)) { /* and not finite */
		*s = sin(x);
		*c = cos(x);
		return;
	}
	double k = nearbyint(x * 0x1.45f306dc9c883p-1); /* x 2/pi */
	double r = ((x - k * P1) - k * P2) - k * P3, z = r * r;
	double sr = r + r * z * (-1.0 / 6 + z * (1.0 / 120 + z * (-1.0 / 5040 + z * (1.0 / 362880 +
		    z * (-1.0 / 39916800 + z * (1.0 / 6227020800.0 + z * (-1.0 / 1307674368000.0 +
		    z * (1.0 / 355687428096000.0))))))));
	double cr = 1.0 + z * (-0.5 + z * (1.0 / 24 + z * (-1.0 / 720 + z * (1.0 / 40320 +
		    z * (-1.0 / 3628800 + z * (1.0 / 479001600 + z * (-1.0 / 87178291200.0 +
		    z * (1.0 / 20922789888000.0))))))));
	switch ((long)k & 3) {
	case 0: *s = sr; *c = cr; break;
	case 1: *s = cr; *c = -sr; break;
	case 2: *s = -sr; *c = -cr; break;
	default: *s = -cr; *c = sr; break;
	}
}

#endif
