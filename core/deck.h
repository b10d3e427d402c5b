/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * deck.h - internal: the trough as a rigid body seen from its body points
 * (docs/MODEL.md "Frames and coordinates"): the rotation R(alpha), body vectors
 * turned into the world frame, the deck points D_k = G + R(alpha)(d_k, h_d)
 * with their velocities and accelerations, and the generalized force of
 * forces applied there. The machine (model.c), the feed coupling
 * (dynamics.c, ode_split.c) and the observables (sim.c) share it; it calls
 * no other module. Lengths in m, angles in rad, SI throughout.
 */
#ifndef CONVSIM_DECK_H
#define CONVSIM_DECK_H

#include <math.h>

#include "angle.h"
#include "params.h"

/* Machine coordinates q = (x, y, alpha, phi, s1, s2) (docs/MODEL.md). */
enum { Q_X, Q_Y, Q_ALPHA, Q_PHI, Q_S1, Q_S2, NQ_FULL };

/* R(alpha) of a machine state, computed once per evaluation. */
typedef struct deck_rot {
	double c, s;
} deck_rot;

static inline deck_rot deck_rotation(const double q[NQ_FULL])
{
	deck_rot r = {1.0, 0.0};
	if (q[Q_ALPHA] != 0.0) {
		angle_sincos(q[Q_ALPHA], &r.s, &r.c);
	}
	return r;
}

/* out = R b: a body vector turned into the world frame (as it is where
 * alpha = 0, as in every scene the symmetric reduction runs). */
static inline void deck_rotate(const deck_rot *R, const double b[2], double out[2])
{
	if (R->s == 0.0 && R->c == 1.0) {
		out[0] = b[0];
		out[1] = b[1];
		return;
	}
	out[0] = R->c * b[0] - R->s * b[1];
	out[1] = R->s * b[0] + R->c * b[1];
}

/* Deck geometry of the integrated columns: K columns at body x d[k], deck
 * height h_d above G. Constant during a run. */
typedef struct deck {
	int K;
	double h_d;
	double d[SIM_MAX_COLUMNS];
} deck;

/* Position (from the origin of the static equilibrium frame) and velocity
 * of the deck point at body x for the machine state q, qd. */
void deck_point(const deck *dk, double x, const deck_rot *R, const double q[NQ_FULL],
		const double qd[NQ_FULL], double pos[2], double vel[2]);

/* A deck point's position, velocity and acceleration are affine in its
 * body x: out[i][0] + x out[i][1] (i = 0, 1, 2 for position, velocity,
 * acceleration; from q, q', q''), so one pair of them serves every
 * column. */
void deck_point_affine(const deck *dk, const deck_rot *R, const double q[NQ_FULL],
		       const double qd[NQ_FULL], const double qdd[NQ_FULL], double out[3][2][2]);

/* Every integrated column's deck point: pos[k], vel[k]. */
typedef struct deck_motion {
	double pos[SIM_MAX_COLUMNS][2], vel[SIM_MAX_COLUMNS][2];
} deck_motion;
void deck_motion_eval(const deck *dk, const double q[NQ_FULL], const double qd[NQ_FULL],
		      deck_motion *out);

/* Add to Q the generalized force of the forces F[k] (N) at every column's
 * deck point, times scale. Mirrored columns k and K-1-k are summed together
 * first, so that the moments of a symmetric motion cancel exactly despite
 * round-off. */
void deck_forces(const deck *dk, const deck_rot *R, const double (*F)[2], double scale,
		 double Q[NQ_FULL]);

#endif
