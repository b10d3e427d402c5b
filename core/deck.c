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

void deck_accel(const deck *dk, int k, const deck_rot *R, const double qd[NQ_FULL],
		const double qdd[NQ_FULL], double acc[2])
{
	double Rd[2];
	deck_arm(dk, dk->d[k], R, Rd);
	double ad = qd[Q_ALPHA], add = qdd[Q_ALPHA];
	acc[0] = qdd[Q_X] - add * Rd[1] - ad * ad * Rd[0];
	acc[1] = qdd[Q_Y] + add * Rd[0] - ad * ad * Rd[1];
}

void deck_point_affine(const deck *dk, const deck_rot *R, const double q[NQ_FULL],
		       const double qd[NQ_FULL], const double qdd[NQ_FULL], double out[3][2][2])
{
	/* the point at body x = 0, and R e_x, the arm's rate per metre of x */
	double Rd[2], Re[2];
	const double ex[2] = {1.0, 0.0};
	deck_arm(dk, 0.0, R, Rd);
	deck_rotate(R, ex, Re);
	double ad = qd[Q_ALPHA], add = qdd[Q_ALPHA];
	out[0][0][0] = q[Q_X] + Rd[0];
	out[0][0][1] = q[Q_Y] + Rd[1];
	out[1][0][0] = qd[Q_X] - ad * Rd[1];
	out[1][0][1] = qd[Q_Y] + ad * Rd[0];
	out[2][0][0] = qdd[Q_X] - add * Rd[1] - ad * ad * Rd[0];
	out[2][0][1] = qdd[Q_Y] + add * Rd[0] - ad * ad * Rd[1];
	out[0][1][0] = Re[0];
	out[0][1][1] = Re[1];
	out[1][1][0] = -ad * Re[1];
	out[1][1][1] = ad * Re[0];
	out[2][1][0] = -add * Re[1] - ad * ad * Re[0];
	out[2][1][1] = add * Re[0] - ad * ad * Re[1];
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
