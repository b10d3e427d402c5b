/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * mirror.c - the mirror reduction of v(beta) sweeps ("model only what a
 * scene needs", applied to a set of points rather than to one instance).
 *
 * On a machine symmetric about the vertical through G, the clockwise
 * motion at beta and the counter-clockwise motion at 180 deg - beta are
 * mirror images (docs/accuracy.md "Checks with known answers"): mirroring x
 * maps phi to pi - phi (the rotor turns the other way, hanging down at the
 * same angle), the guide direction u(beta) to -u(pi - beta) (so the
 * eliminators swap and their strokes change sign; with c != 0 the masses
 * would sit on the wrong side of their guide points, so c must be 0), the
 * spring sets and the columns onto each other; the Kloss motor, the
 * bearing drag and the load torque are odd in the rotor speed and gravity,
 * friction and the contact law are mirror-invariant. So the transport
 * velocity changes sign and nothing that is measured depends on which of
 * the two is integrated. A sweep over both senses integrates one point of
 * each pair and derives the other (sim_mirror_plan,
 * sim_mirror_measurement); `convsim sweep`, the daemon's sweeps and the
 * fit's batches all plan with these two functions.
 *
 * What a derived point differs by from a direct run: floating-point round
 * off (sin(pi - beta) is not bit for bit sin(beta)), which the feed's
 * hopping amplifies, and the estimator's period boundaries, which fall
 * half a period later on the mirrored run (phi - alpha crosses 2 pi k where
 * the original's crosses pi + 2 pi k). docs/model-numerics.md ("Modelling
 * only what a scene needs") gives the measured difference over the 74
 * points.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "model.h"
#include "sim.h"
#include "sim_mirror.h"

/* beta_j counts as pi - beta_i within this (rad): degrees converted to
 * radians land within a few ulps of each other. */
#define MIRROR_BETA_TOL 1e-9

int sim_mirror_applies(const sim_params *p, const sim_scene *sc)
{
	return sc->mirror && model_machine_symmetric(p) && p->c == 0.0;
}

size_t sim_mirror_plan(const sim_params *p, const sim_scene *sc, size_t n, const double *beta,
		       const int *rotation, long *source)
{
	for (size_t i = 0; i < n; i++)
		source[i] = -1;
	if (!sim_mirror_applies(p, sc))
		return n;
	size_t measured = n;
	for (size_t i = 0; i < n; i++) {
		if (source[i] >= 0)
			continue;
		/* point i is measured; the first unplanned mirror image after
		 * it is derived from it */
		for (size_t j = i + 1; j < n; j++)
			if (source[j] < 0 && rotation[j] == -rotation[i] &&
			    fabs(beta[j] - (M_PI - beta[i])) <= MIRROR_BETA_TOL) {
				source[j] = (long)i;
				measured--;
				break;
			}
	}
	return measured;
}

void sim_mirror_measurement(const sim_measurement *src, sim_measurement *dst)
{
	*dst = *src;
	dst->transport_velocity = -src->transport_velocity;
	dst->rotor_speed_mean = -src->rotor_speed_mean;
	dst->cpu_seconds = 0.0;
}

void sim_mirror_failure(char *out, size_t len, double beta_deg, int rotation, const char *why)
{
	/* the cause copied first: out may be the very buffer why is in */
	char cause[119];
	size_t k = strnlen(why, sizeof cause - 1);
	memcpy(cause, why, k);
	cause[k] = '\0';
	snprintf(out, len, "mirror image of %g deg %s: %s", beta_deg,
		 rotation == SIM_CW ? "cw" : "ccw", cause);
}
