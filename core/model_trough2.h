/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model_trough2.h - model.c's stages configure and mass_matrix_and_bias
 * together for the reduced scene's layout while beta is held (how a
 * measurement runs). A static function included by model.c only, where it
 * was, so that its evaluation compiles exactly as before.
 */
#ifndef CONVSIM_MODEL_TROUGH2_H
#define CONVSIM_MODEL_TROUGH2_H

#include "model.h"

/* Stages configure and mass_matrix_and_bias together for the reduced
 * scene's layout (MODEL_LAYOUT_TROUGH2: x, y | phi, s1, s2, alpha fixed at
 * 0) while beta is held (beta' = beta'' = 0), which is how a measurement
 * runs. There R is the identity and alpha' = beta' = beta'' = 0, so the
 * eliminators' bias accelerations are zero, their Jacobians on s_i are the
 * guide's direction u, and the alpha row and column, which this layout's
 * solve does not read, are left out (M there is zero; cf's point masses
 * are not filled: with beta held nothing reads them). What remains is the
 * two stages' arithmetic operation for operation (terms that are a zero
 * left out: they change at most the sign of a zero), so the results are
 * theirs to the last bit (test_machine.c compares the two on random
 * states) in about two fifths of their instructions (callgrind). Returns
 * 0, having set only c's beta and its rates, where it does not apply. */
static int trough2_held(const model *md, const model_ctl *ctl, double t, const double *y,
			const double Qfeed[NQ_FULL], config *c, double M[NQ_FULL][NQ_FULL],
			double rhs[NQ_FULL])
{
	if (md->layout != MODEL_LAYOUT_TROUGH2)
		return 0;
	ramp_eval(&ctl->beta_ramp, t, &c->beta, &c->beta_d, &c->beta_dd);
	if (c->beta_d != 0.0 || c->beta_dd != 0.0)
		return 0;
	const sim_params *p = &md->p;
	trough2_full(y, c->q); /* model_full_coords in this layout */
	trough2_full(y + md->npos, c->qd);
	c->R = (deck_rot){1.0, 0.0};
	beta_sincos(c->beta, &c->sbeta, &c->cbeta);
	zero_matrix(M);
	feed_force(Qfeed, rhs);
	rhs[Q_Y] -= p->M_r * p->g;
	/* the vibrator (point_mass_vibrator with R = I, alpha' = 0) */
	double cf, sf;
	angle_sincos(c->q[Q_PHI], &sf, &cf);
	const double e = p->e, m = p->m;
	const double pd2 = c->qd[Q_PHI] * c->qd[Q_PHI];
	const double jo0 = -e * sf, jo1 = e * cf;
	const double a0 = -(e * pd2 * cf), a1 = -(e * pd2 * sf);
	M[Q_X][Q_X] = M[Q_Y][Q_Y] = p->M_r + m;
	M[Q_PHI][Q_X] = m * jo0;
	M[Q_PHI][Q_Y] = m * jo1;
	M[Q_PHI][Q_PHI] = md->own_m[Q_PHI];
	double f0 = -m * a0, f1 = -m * (a1 + p->g);
	rhs[Q_X] += f0;
	rhs[Q_Y] += f1;
	rhs[Q_PHI] += jo0 * f0 + jo1 * f1;
	/* the eliminators: Jacobian u = (-sin beta, cos beta) on s_i and no
	 * bias acceleration, so of -m_i J^T (a + g e_y) their weight alone */
	const double u0 = -c->sbeta, u1 = c->cbeta;
	for (int i = 0; i < 2; i++) {
		const int o = i == 0 ? Q_S1 : Q_S2;
		const double mi = i == 0 ? p->m1 : p->m2;
		M[Q_X][Q_X] += mi;
		M[Q_Y][Q_Y] += mi;
		M[o][Q_X] = mi * u0;
		M[o][Q_Y] = mi * u1;
		M[o][o] = md->own_m[o];
		double fy = -mi * p->g;
		rhs[Q_Y] += fy;
		rhs[o] += u1 * fy;
	}
	return 1;
}

#endif
