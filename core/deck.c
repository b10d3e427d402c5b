/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * deck.c - deck-point kinematics and the generalized force of forces at
 * the deck points (see deck.h). One function, deck_arm, turns a deck point's
 * body offset (x, h_d) by R(alpha); everything else is built on it.
 */
#include "deck.h"

/* R (x, h_d): the arm from G to the deck point at body x. */
static void deck_arm(const deck *dk, double x, const deck_rot *R, double Rd[2])
{
	double dv[2] = {x, dk->h_d};
	deck_rotate(R, dv, Rd);
}

void deck_point(const deck *dk, double x, const deck_rot *R, const double q[NQ_FULL],
		const double qd[NQ_FULL], double pos[2], double vel[2])
{
	double Rd[2];
	deck_arm(dk, x, R, Rd);
	pos[0] = q[Q_X] + Rd[0];
	pos[1] = q[Q_Y] + Rd[1];
	vel[0] = qd[Q_X] - qd[Q_ALPHA] * Rd[1];
	vel[1] = qd[Q_Y] + qd[Q_ALPHA] * Rd[0];
}

/* Position, velocity and acceleration (out[0..2][b]) of the point at arm r
 * (world frame) from G's p, v, a and alpha's rates ad, add. */
static void arm_kinematics(const double p[2], const double v[2], const double a[2], double ad,
			   double add, const double r[2], double out[3][2][2], int b)
{
	out[0][b][0] = p[0] + r[0];
	out[0][b][1] = p[1] + r[1];
	out[1][b][0] = v[0] - ad * r[1];
	out[1][b][1] = v[1] + ad * r[0];
	out[2][b][0] = a[0] - add * r[1] - ad * ad * r[0];
	out[2][b][1] = a[1] + add * r[0] - ad * ad * r[1];
}

void deck_point_affine(const deck *dk, const deck_rot *R, const double q[NQ_FULL],
		       const double qd[NQ_FULL], const double qdd[NQ_FULL], double out[3][2][2])
{
	/* the point at body x = 0 (G's motion and the arm R (0, h_d)), and
	 * the rate per metre of x (no motion of G and the arm R e_x) */
	double Rd[2], Re[2];
	const double ex[2] = {1.0, 0.0}, none[2] = {0.0, 0.0};
	deck_arm(dk, 0.0, R, Rd);
	deck_rotate(R, ex, Re);
	arm_kinematics(q, qd, qdd, qd[Q_ALPHA], qdd[Q_ALPHA], Rd, out, 0);
	arm_kinematics(none, none, none, qd[Q_ALPHA], qdd[Q_ALPHA], Re, out, 1);
}

void deck_motion_eval(const deck *dk, const double q[NQ_FULL], const double qd[NQ_FULL],
		      deck_motion *out)
{
	deck_rot R = deck_rotation(q);
	for (int k = 0; k < dk->K; k++)
		deck_point(dk, dk->d[k], &R, q, qd, out->pos[k], out->vel[k]);
}

/* Generalized force of a force F applied at column k's deck point. */
static void deck_force(const deck *dk, int k, const deck_rot *R, const double F[2],
		       double Q[NQ_FULL])
{
	double Rd[2];
	deck_arm(dk, dk->d[k], R, Rd);
	Q[Q_X] += F[0];
	Q[Q_Y] += F[1];
	Q[Q_ALPHA] += -Rd[1] * F[0] + Rd[0] * F[1];
}

void deck_forces(const deck *dk, const deck_rot *R, const double (*F)[2], double scale,
		 double Q[NQ_FULL])
{
	for (int k = 0; k <= (dk->K - 1) / 2; k++) {
		int kk = dk->K - 1 - k;
		double Qpair[NQ_FULL] = {0}, Qm[NQ_FULL] = {0};
		deck_force(dk, k, R, F[k], Qpair);
		if (kk != k) {
			deck_force(dk, kk, R, F[kk], Qm);
			for (int i = 0; i < NQ_FULL; i++)
				Qpair[i] += Qm[i];
		}
		for (int i = 0; i < NQ_FULL; i++)
			Q[i] += scale * Qpair[i];
	}
}
