/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model_solve.c - the machine's mass matrix solve (model.h): the reduced
 * system T^t M T qr'' = T^t (rhs - M qp'') for the accelerations. Each
 * point mass moves one coordinate of its own (phi for the vibrator, s_i
 * for eliminator i) with a constant inertia, and no two of those couple,
 * so M is a 3 x 3 block on the trough's (x, y, alpha) bordered by a
 * constant diagonal: the own coordinates are eliminated with the inverses
 * model_solve_layout computes once, and only the Schur complement on the
 * trough's coordinates is factored (LDL^T, no square roots) at each
 * evaluation, instead of a Cholesky factorisation of the whole matrix.
 */
#include <math.h>

#include "model.h"

/* The two layouts of every scene with the Kloss drive, the trough's
 * coordinates first and the own ones after them: (x, y, alpha | phi, s1,
 * s2) and, alpha fixed, (x, y | phi, s1, s2). For them the solve is
 * written with the sizes and indices as constants (the compiler then
 * unrolls it), and split into the Schur complement's factorisation and
 * the solve for one right-hand side, so that several forces share one
 * factorisation (model_reduced_solves). The arithmetic is general_solve's for
 * these layouts, operation for operation: the results are the same to the
 * last bit. */
static const int full_trough3[NQ_FULL] = {Q_X, Q_Y, Q_ALPHA, Q_PHI, Q_S1, Q_S2};
static const int full_trough2[NQ_FULL] = {Q_X, Q_Y, Q_PHI, Q_S1, Q_S2, 0};

void model_solve_layout(model *md)
{
	const sim_params *p = &md->p;
	/* M's diagonal on a point mass's own coordinate, constant: J_w + m e^2
	 * on phi (|jo| = e), m_i on s_i (|jo| = |u| = 1) */
	md->own_m[Q_PHI] = p->J_w + p->m * p->e * p->e;
	md->own_m[Q_S1] = p->m1;
	md->own_m[Q_S2] = p->m2;
	md->n_body = 0;
	md->selection = !md->phi_prescribed;
	for (int i = 0; i < NQ_FULL; i++)
		md->sel[i] = -1;
	for (int r = 0; r < md->nq; r++) {
		if (md->ncol[r] != 1)
			md->selection = 0;
		int i = md->col[r][0];
		md->sel[i] = r;
		md->own_inv[r] = 0.0;
		if (md->ncol[r] == 1 && (i == Q_PHI || i == Q_S1 || i == Q_S2))
			md->own_inv[r] = 1.0 / md->own_m[i];
		else
			md->body[md->n_body++] = r;
	}
	/* the layouts with a solve of constant sizes: the trough's
	 * coordinates first, in order, the own ones after them */
	md->layout = MODEL_LAYOUT_GENERAL;
	if (md->selection) {
		const int *full = md->n_body == 3 ? full_trough3 : full_trough2;
		int same = md->nq == md->n_body + 3 && (md->n_body == 3 || md->n_body == 2);
		for (int r = 0; same && r < md->nq; r++)
			same = md->col[r][0] == full[r] && (r < md->n_body) == (md->own_inv[r] == 0.0);
		if (same)
			md->layout = md->n_body == 3 ? MODEL_LAYOUT_TROUGH3 : MODEL_LAYOUT_TROUGH2;
	}
}

/* In-place LDL^T factorisation of the n x n (n <= 3) SPD matrix A (lower
 * half used and overwritten: L below the diagonal, D on it). Returns 0,
 * or -1 if A is not positive definite. Inlined where n is a constant, so
 * the loops unroll there. */
static inline int ldlt_factor(const int n, double A[3][3])
{
#pragma GCC unroll 6
	for (int j = 0; j < n; j++) {
		double d = A[j][j];
#pragma GCC unroll 6
		for (int k = 0; k < j; k++)
			d -= A[j][k] * A[j][k] * A[k][k];
		if (!(d > 0.0))
			return -1;
		A[j][j] = d;
		double inv = 1.0 / d;
#pragma GCC unroll 6
		for (int i = j + 1; i < n; i++) {
			double s = A[i][j];
#pragma GCC unroll 6
			for (int k = 0; k < j; k++)
				s -= A[i][k] * A[j][k] * A[k][k];
			A[i][j] = s * inv;
		}
	}
	return 0;
}

/* Solve A x = b in place (x into b) with ldlt_factor's A. */
static inline void ldlt_subst(const int n, const double A[3][3], double *b)
{
#pragma GCC unroll 6
	for (int i = 0; i < n; i++)
#pragma GCC unroll 6
		for (int k = 0; k < i; k++)
			b[i] -= A[i][k] * b[k];
#pragma GCC unroll 6
	for (int i = n - 1; i >= 0; i--) {
		b[i] /= A[i][i];
#pragma GCC unroll 6
		for (int k = i + 1; k < n; k++)
			b[i] -= A[k][i] * b[k];
	}
}

/* The point masses' own coordinates (phi, s1, s2 where integrated alone)
 * have constant, mutually uncoupled diagonals (md->own_inv holds their
 * inverses), so they are eliminated first and only the Schur complement
 * on the trough's coordinates (x, y and alpha, at most 3) is factored. */
/* The Schur complement S on the trough's nb coordinates, factored as
 * LDL^T in place (ldlt_factor); -1 if not positive definite. */
static inline int schur_factor(const double M[NQ_FULL][NQ_FULL], const double *own_inv,
			       const int n, const int nb, const int *full, double S[3][3])
{
#pragma GCC unroll 6
	for (int a = 0; a < nb; a++) {
#pragma GCC unroll 6
		for (int c = 0; c <= a; c++)
			S[a][c] = M[full[a]][full[c]];
#pragma GCC unroll 6
		for (int d = nb; d < n; d++) {
			const double *Md = M[full[d]];
#pragma GCC unroll 6
			for (int c = 0; c <= a; c++)
				S[a][c] -= Md[full[a]] * own_inv[d] * Md[full[c]];
		}
	}
	return ldlt_factor(nb, S);
}

/* One right-hand side through schur_factor's S (general_solve's
 * arithmetic). */
static inline void schur_solve(const double M[NQ_FULL][NQ_FULL], const double *own_inv,
			       const int n, const int nb, const int *full, const double S[3][3],
			       const double rhs[NQ_FULL], double br[NQ_FULL])
{
	double x[3];
#pragma GCC unroll 6
	for (int r = 0; r < n; r++)
		br[r] = rhs[full[r]];
#pragma GCC unroll 6
	for (int a = 0; a < nb; a++) {
		x[a] = br[a];
#pragma GCC unroll 6
		for (int d = nb; d < n; d++)
			x[a] -= M[full[d]][full[a]] * own_inv[d] * br[d];
	}
	ldlt_subst(nb, S, x);
#pragma GCC unroll 6
	for (int d = nb; d < n; d++) {
		const double *Md = M[full[d]];
		double s = br[d];
#pragma GCC unroll 6
		for (int c = 0; c < nb; c++)
			s -= Md[full[c]] * x[c];
		br[d] = s * own_inv[d];
	}
#pragma GCC unroll 6
	for (int a = 0; a < nb; a++)
		br[a] = x[a];
}

/* nrhs right-hand sides through one factorisation, for a layout with the
 * sizes n, nb and the indices full as constants. */
static inline void trough_solves(const double M[NQ_FULL][NQ_FULL], const double *own_inv,
				 const int n, const int nb, const int *full, int nrhs,
				 const double (*rhs)[NQ_FULL], double (*br)[NQ_FULL])
{
	double S[3][3];
	if (schur_factor(M, own_inv, n, nb, full, S) != 0) {
		for (int i = 0; i < nrhs; i++)
			for (int r = 0; r < n; r++)
				br[i][r] = NAN;
		return;
	}
	for (int i = 0; i < nrhs; i++)
		schur_solve(M, own_inv, n, nb, full, (const double(*)[3])S, rhs[i], br[i]);
}

static void trough3_solves(const model *md, const double M[NQ_FULL][NQ_FULL], int nrhs,
			   const double (*rhs)[NQ_FULL], double (*br)[NQ_FULL])
{
	trough_solves(M, md->own_inv, 6, 3, full_trough3, nrhs, rhs, br);
}

static void trough2_solves(const model *md, const double M[NQ_FULL][NQ_FULL], int nrhs,
			   const double (*rhs)[NQ_FULL], double (*br)[NQ_FULL])
{
	trough_solves(M, md->own_inv, 5, 2, full_trough2, nrhs, rhs, br);
}

void model_reduced_solves(const model *md, const double M[NQ_FULL][NQ_FULL], int nrhs,
			  const double (*rhs)[NQ_FULL], double (*br)[NQ_FULL])
{
	static const double none[NQ_FULL];
	if (md->layout == MODEL_LAYOUT_TROUGH3)
		trough3_solves(md, M, nrhs, rhs, br);
	else if (md->layout == MODEL_LAYOUT_TROUGH2)
		trough2_solves(md, M, nrhs, rhs, br);
	else
		for (int i = 0; i < nrhs; i++)
			model_reduced_solve(md, M, rhs[i], none, br[i]);
}

/* The general case: reduced coordinates that combine full ones, and
 * prescribed accelerations; with neither (one full coordinate each) every
 * sum below has one term, so the layouts above are this arithmetic. */
static void general_solve(const model *md, const double M[NQ_FULL][NQ_FULL],
			  const double rhs[NQ_FULL], const double qpdd[NQ_FULL], double br[NQ_FULL])
{
	int n = md->nq, nb = md->n_body;
	double Mr[NQ_FULL][NQ_FULL], res[NQ_FULL], S[3][3], x[3];
	for (int i = 0; i < NQ_FULL; i++)
		res[i] = md->phi_prescribed ? rhs[i] - M[i][Q_PHI] * qpdd[Q_PHI] : rhs[i];
	for (int r = 0; r < n; r++) {
		const int *ir = md->col[r];
		br[r] = md->ncol[r] == 1 ? res[ir[0]] : res[ir[0]] + res[ir[1]];
		for (int c = 0; c < nb; c++) {
			const int *ic = md->col[md->body[c]];
			double m = 0.0;
			for (int a = 0; a < md->ncol[r]; a++)
				for (int b = 0; b < md->ncol[md->body[c]]; b++)
					m += M[ir[a]][ic[b]];
			Mr[r][c] = m;
		}
	}
	/* Mr[r][c]: row r against body coordinate c; S = B - C D^-1 C^T */
	for (int a = 0; a < nb; a++) {
		int ra = md->body[a];
		x[a] = br[ra];
		for (int c = 0; c <= a; c++)
			S[a][c] = Mr[ra][c];
		for (int d = 0; d < n; d++) {
			double inv = md->own_inv[d];
			if (inv == 0.0)
				continue;
			x[a] -= Mr[d][a] * inv * br[d];
			for (int c = 0; c <= a; c++)
				S[a][c] -= Mr[d][a] * inv * Mr[d][c];
		}
	}
	if (ldlt_factor(nb, S) != 0) {
		for (int r = 0; r < n; r++)
			br[r] = NAN;
		return;
	}
	ldlt_subst(nb, (const double(*)[3])S, x);
	for (int d = 0; d < n; d++) {
		double inv = md->own_inv[d];
		if (inv == 0.0)
			continue;
		double s = br[d];
		for (int c = 0; c < nb; c++)
			s -= Mr[d][c] * x[c];
		br[d] = s * inv;
	}
	for (int a = 0; a < nb; a++)
		br[md->body[a]] = x[a];
}

void model_reduced_solve(const model *md, const double M[NQ_FULL][NQ_FULL],
			  const double rhs[NQ_FULL], const double qpdd[NQ_FULL], double br[NQ_FULL])
{
	if (md->layout == MODEL_LAYOUT_TROUGH3)
		trough3_solves(md, M, 1, (const double(*)[NQ_FULL])rhs, (double(*)[NQ_FULL])br);
	else if (md->layout == MODEL_LAYOUT_TROUGH2)
		trough2_solves(md, M, 1, (const double(*)[NQ_FULL])rhs, (double(*)[NQ_FULL])br);
	else
		general_solve(md, M, rhs, qpdd, br);
}
