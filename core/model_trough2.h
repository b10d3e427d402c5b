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

/* The entries of M this layout's solve reads (model_solve.c's
 * trough2_solves): its x and y diagonals (M[y][x] is zero) and the rows of
 * the own coordinates phi, s1, s2 on x and y; their own diagonals are
 * md->own_m, constant. */
typedef struct trough2_mass {
	double xx, yy;
	double own[3][2];
} trough2_mass;

/* Stages configure and mass_matrix_and_bias together for the reduced
 * scene's layout (MODEL_LAYOUT_TROUGH2: x, y | phi, s1, s2, alpha fixed at
 * 0) while beta is held (beta' = beta'' = 0), which is how a measurement
 * runs. There R is the identity and alpha' = beta' = beta'' = 0, so the
 * eliminators' bias accelerations are zero, their Jacobians on s_i are the
 * guide's direction u, and the alpha row and column, which this layout's
 * solve does not read, are left out (M there is zero; cf's point masses
 * are not filled: with beta held nothing reads them), and of M only what
 * the layout's solve reads is formed, in scalars (trough2_mass). What remains is the
 * two stages' arithmetic operation for operation (terms that are a zero
 * left out: they change at most the sign of a zero), so the results are
 * theirs to the last bit (test_machine.c compares the two on random
 * states) in about two fifths of their instructions (callgrind). Returns
 * 0, having set only c's beta and its rates, where it does not apply. */
static int trough2_held(const model *md, const model_ctl *ctl, double t, const double *y,
			const double Qfeed[NQ_FULL], config *c, trough2_mass *M,
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
	feed_force(Qfeed, rhs);
	rhs[Q_Y] -= p->M_r * p->g;
	/* the vibrator (point_mass_vibrator with R = I, alpha' = 0) */
	double cf, sf;
	angle_sincos(c->q[Q_PHI], &sf, &cf);
	const double e = p->e, m = p->m;
	const double pd2 = c->qd[Q_PHI] * c->qd[Q_PHI];
	const double jo0 = -e * sf, jo1 = e * cf;
	const double a0 = -(e * pd2 * cf), a1 = -(e * pd2 * sf);
	M->xx = M->yy = p->M_r + m;
	M->own[0][0] = m * jo0;
	M->own[0][1] = m * jo1;
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
		M->xx += mi;
		M->yy += mi;
		M->own[1 + i][0] = mi * u0;
		M->own[1 + i][1] = mi * u1;
		double fy = -mi * p->g;
		rhs[Q_Y] += fy;
		rhs[o] += u1 * fy;
	}
	return 1;
}

/* model_solve.c's trough2_solves for one right-hand side on trough2_mass,
 * operation for operation (the Schur complement on x, y, its LDL^T
 * factorisation and substitution), so the same to the last bit, without
 * the matrix's array: the layout's solve fused into its evaluation. */
static void trough2_solve(const model *md, const trough2_mass *M, const double rhs[NQ_FULL],
			  double br[NQ_FULL])
{
	const double *inv = md->own_inv + 2; /* reduced phi, s1, s2 */
	double s00 = M->xx, s10 = 0.0, s11 = M->yy;
#pragma GCC unroll 3
	for (int d = 0; d < 3; d++)
		s00 -= M->own[d][0] * inv[d] * M->own[d][0];
#pragma GCC unroll 3
	for (int d = 0; d < 3; d++) {
		s10 -= M->own[d][1] * inv[d] * M->own[d][0];
		s11 -= M->own[d][1] * inv[d] * M->own[d][1];
	}
	double d1 = 0.0;
	if (s00 > 0.0) {
		s10 = s10 * (1.0 / s00);
		d1 = s11 - s10 * s10 * s00;
	}
	if (!(s00 > 0.0) || !(d1 > 0.0)) {
		for (int r = 0; r < 5; r++)
			br[r] = NAN;
		return;
	}
	const double b[3] = {rhs[Q_PHI], rhs[Q_S1], rhs[Q_S2]};
	double x0 = rhs[Q_X], x1 = rhs[Q_Y];
#pragma GCC unroll 3
	for (int d = 0; d < 3; d++)
		x0 -= M->own[d][0] * inv[d] * b[d];
#pragma GCC unroll 3
	for (int d = 0; d < 3; d++)
		x1 -= M->own[d][1] * inv[d] * b[d];
	x1 -= s10 * x0;
	x1 /= d1;
	x0 /= s00;
	x0 -= s10 * x1;
#pragma GCC unroll 3
	for (int d = 0; d < 3; d++) {
		double s = b[d];
		s -= M->own[d][0] * x0;
		s -= M->own[d][1] * x1;
		br[2 + d] = s * inv[d];
	}
	br[0] = x0;
	br[1] = x1;
}

/* The entries of M the layout's solve reads, from trough2_mass, where an
 * evaluation shows M (the corrector's solves, ode_split.c); the others
 * are not written. */
static inline void trough2_matrix(const trough2_mass *M, double out[NQ_FULL][NQ_FULL])
{
	static const int o[3] = {Q_PHI, Q_S1, Q_S2};
	out[Q_X][Q_X] = M->xx;
	out[Q_Y][Q_X] = 0.0;
	out[Q_Y][Q_Y] = M->yy;
#pragma GCC unroll 3
	for (int d = 0; d < 3; d++) {
		out[o[d]][Q_X] = M->own[d][0];
		out[o[d]][Q_Y] = M->own[d][1];
	}
}

#endif
