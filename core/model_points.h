/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model_points.h - the kinematics of the machine's three point masses
 * (unbalanced mass, two eliminator masses on their guides): position
 * relative to G, Jacobian and bias acceleration, with the derivation.
 * Static functions included by model.c only, where they were, so that its
 * stages inline them exactly as before.
 */
#ifndef CONVSIM_MODEL_POINTS_H
#define CONVSIM_MODEL_POINTS_H

#include <math.h>

#include "model.h"

/* One point mass: its Jacobian, which has the same shape for all three
 * (the unit columns of x and y, a column ja on alpha and a column jo on its
 * own coordinate `own`: phi for the vibrator, s_i for eliminator i), and
 * the bias acceleration a. */
typedef struct pm {
	double m;
	int own;
	double ja[2], jo[2];
	double a[2];
	double r[2];  /* position relative to G */
} pm;

/* r' = J q' (+ the guide's turn, added by the caller). */
static void pm_velocity(const pm *P, const double *qd, double v[2])
{
	v[0] = qd[Q_X] + P->ja[0] * qd[Q_ALPHA] + P->jo[0] * qd[P->own];
	v[1] = qd[Q_Y] + P->ja[1] * qd[Q_ALPHA] + P->jo[1] * qd[P->own];
}

/* Unbalanced mass at G + R w + e (cos phi, sin phi):
 *   r'' = [I, perp(Rw), e(-sin phi, cos phi)] q'' - alpha'^2 Rw - e phi'^2 (cos, sin). */
static void point_mass_vibrator(const model *md, const deck_rot *R, const double *q,
				const double *qd, pm *k)
{
	double w[2] = {md->p.w_x, md->p.w_y}, Rw[2];
	deck_rotate(R, w, Rw);
	double cf, sf, e = md->p.e;
	angle_sincos(q[Q_PHI], &sf, &cf);
	k->m = md->p.m;
	k->own = Q_PHI;
	k->ja[0] = -Rw[1];
	k->ja[1] = Rw[0];
	k->jo[0] = -e * sf;
	k->jo[1] = e * cf;
	double ad2 = qd[Q_ALPHA] * qd[Q_ALPHA], pd2 = qd[Q_PHI] * qd[Q_PHI];
	k->a[0] = -ad2 * Rw[0] - e * pd2 * cf;
	k->a[1] = -ad2 * Rw[1] - e * pd2 * sf;
	k->r[0] = Rw[0] + e * cf;
	k->r[1] = Rw[1] + e * sf;
}

/* Eliminator mass i at G + R b, b = p_i + (c + s_i) u(beta),
 * u = (-sin beta, cos beta), u' = du/dbeta = (-cos beta, -sin beta):
 *   r'' = [I, perp(Rb), R u (on s_i)] q''
 *         - alpha'^2 R b + 2 alpha' perp(R b_rel')
 *         + R (2 s' beta' u' + (c + s)(beta'' u' - beta'^2 u)),
 * with b_rel' = s' u + (c + s) beta' u' the guide-frame rate. */
static void point_mass_eliminator(const model *md, int i, const deck_rot *R,
				  const double *q, const double *qd, double sb, double cb,
				  double beta_d, double beta_dd, pm *k)
{
	int qs = i == 0 ? Q_S1 : Q_S2;
	double px = i == 0 ? md->p.p1_x : md->p.p2_x;
	double py = i == 0 ? md->p.p1_y : md->p.p2_y;
	double u[2] = {-sb, cb}, up[2] = {-cb, -sb};
	double cs = md->p.c + q[qs], sd = qd[qs], ad = qd[Q_ALPHA];
	double b[2] = {px + cs * u[0], py + cs * u[1]}, Rb[2], Ru[2];
	deck_rotate(R, b, Rb);
	deck_rotate(R, u, Ru);
	double brel[2] = {sd * u[0] + cs * beta_d * up[0], sd * u[1] + cs * beta_d * up[1]};
	double Rbrel[2];
	deck_rotate(R, brel, Rbrel);
	double g2 = 2.0 * sd * beta_d, h1 = cs * beta_dd, h2 = cs * beta_d * beta_d;
	double gl[2] = {g2 * up[0] + h1 * up[0] - h2 * u[0], g2 * up[1] + h1 * up[1] - h2 * u[1]};
	double Rgl[2];
	deck_rotate(R, gl, Rgl);
	k->m = i == 0 ? md->p.m1 : md->p.m2;
	k->own = qs;
	k->ja[0] = -Rb[1];
	k->ja[1] = Rb[0];
	k->jo[0] = Ru[0];
	k->jo[1] = Ru[1];
	k->a[0] = -ad * ad * Rb[0] - 2.0 * ad * Rbrel[1] + Rgl[0];
	k->a[1] = -ad * ad * Rb[1] + 2.0 * ad * Rbrel[0] + Rgl[1];
	k->r[0] = Rb[0];
	k->r[1] = Rb[1];
}

#endif
