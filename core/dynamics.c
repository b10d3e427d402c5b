/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dynamics.c - machine plus feed (see dynamics.h): the deck's motion from
 * the machine state, the feed's right-hand side along it, the feed's
 * reaction on the deck as a generalized force into the machine's
 * right-hand side; stored energy; the initial static equilibrium (Newton
 * on the machine's static accelerations with the feed's weight at the deck
 * points, then the feed settled on the deck).
 */
#include <math.h>
#include <string.h>

#include "dynamics.h"
#include "feed.h"

/* Stage feed reaction: the feed's dy along the deck's motion, its friction
 * and contact powers, and its force on the deck into Qfeed (if coupled). */
static void feed_reaction(const model *md, const model_ctl *ctl, double t, const double *y,
			  double *dy, double Qfeed[NQ_FULL], double *fric, double *contact)
{
	double q[NQ_FULL], qd[NQ_FULL], F[SIM_MAX_COLUMNS][2];
	deck_motion dm;
	model_full_coords(md, ctl, t, y, q, qd);
	deck_motion_eval(&md->dk, q, qd, &dm);
	feed_rhs(md, y, &dm, dy, F, fric, contact);
	if (md->sc.feed_coupling) {
		deck_rot R = deck_rotation(q);
		deck_forces(&md->dk, &R, (const double(*)[2])F, md->col_weight, Qfeed);
	}
}

void dynamics_feed_reaction(const model *md, const model_ctl *ctl, double t, const double *y,
			    double *dy, double Qfeed[NQ_FULL])
{
	double fric, contact;
	if (md->nf > 0)
		feed_reaction(md, ctl, t, y, dy, Qfeed, &fric, &contact);
}

void dynamics_eval(const model *md, const model_ctl *ctl, double t, const double *y, double *dy,
		   model_eval *ev)
{
	double Qfeed[NQ_FULL] = {0};
	double *acc = dy + 2 * md->npos;
	acc[ACC_FRIC] = 0.0;
	acc[ACC_CONTACT] = 0.0;
	acc[ACC_FEED] = 0.0; /* dem's alone */
	acc[ACC_DECK] = 0.0;
	if (md->nf > 0)
		feed_reaction(md, ctl, t, y, dy, Qfeed, &acc[ACC_FRIC], &acc[ACC_CONTACT]);
	model_machine_rhs(md, ctl, t, y, Qfeed, dy, ev);
}

void dynamics_observe(const model *md, const model_ctl *ctl, double t, const double *y,
		      double *dy, model_eval *ev)
{
	double Qfeed[NQ_FULL] = {0};
	if (md->nf > 0 && md->sc.feed_coupling) {
		double q[NQ_FULL], qd[NQ_FULL], F[SIM_MAX_COLUMNS][2];
		deck_motion dm;
		model_full_coords(md, ctl, t, y, q, qd);
		deck_motion_eval(&md->dk, q, qd, &dm);
		feed_deck_forces(md, y, &dm, F);
		deck_rot R = deck_rotation(q);
		deck_forces(&md->dk, &R, (const double(*)[2])F, md->col_weight, Qfeed);
	}
	model_machine_rhs(md, ctl, t, y, Qfeed, dy, ev);
}

double dynamics_energy_stored(const model *md, const model_ctl *ctl, double t, const double *y,
			      double *kinetic, double *potential)
{
	double T, V, Tf = 0.0, Vf = 0.0;
	model_machine_energy(md, ctl, t, y, &T, &V);
	if (md->nf > 0)
		feed_energy(md, y, &Tf, &Vf);
	*kinetic = T + Tf;
	*potential = V + Vf;
	return *kinetic + *potential;
}

double dynamics_contact_energy(const model *md, const double *y, const double q[NQ_FULL],
			       const double qd[NQ_FULL])
{
	if (md->nf == 0)
		return 0.0;
	deck_motion dm;
	deck_motion_eval(&md->dk, q, qd, &dm);
	return feed_contact_energy(md, y, &dm);
}

void dynamics_feed_weight(const model *md, const double q[NQ_FULL], double Qfeed[NQ_FULL])
{
	/* one-way coupling: the feed's weight never reaches the trough */
	if (md->nf == 0 || !md->sc.feed_coupling)
		return;
	double F[SIM_MAX_COLUMNS][2];
	deck_rot R = deck_rotation(q);
	for (int k = 0; k < md->dk.K; k++) {
		F[k][0] = 0.0;
		F[k][1] = -md->L * md->p.m_n * md->p.g;
	}
	deck_forces(&md->dk, &R, (const double(*)[2])F, md->col_weight, Qfeed);
}

/* Static accelerations (zero exactly where gravity, springs with preload
 * and the feed weight at the deck points balance) at rest for full
 * coordinates q, motor off. */
static void static_residual(const model *md, const model_ctl *ctl, const double q[NQ_FULL],
			    double res[NQ_FULL])
{
	model tmp = *md; /* machine only, every coordinate free */
	model_ctl off = *ctl;
	memset(tmp.T, 0, sizeof tmp.T);
	for (int i = 0; i < NQ_FULL; i++) {
		tmp.T[i][i] = 1.0;
		tmp.ncol[i] = 1;
		tmp.col[i][0] = i;
	}
	tmp.nq = NQ_FULL;
	tmp.nf = 0;
	tmp.npos = NQ_FULL;
	tmp.n = 2 * NQ_FULL + ACC_N;
	tmp.phi_prescribed = 0;
	model_solve_layout(&tmp);
	off.drive_on = 0;
	double y[2 * NQ_FULL + ACC_N] = {0}, dy[2 * NQ_FULL + ACC_N];
	memcpy(y, q, sizeof(double) * NQ_FULL);
	double Qfeed[NQ_FULL] = {0};
	dynamics_feed_weight(md, q, Qfeed);
	model_eval ev;
	model_machine_rhs(&tmp, &off, 0.0, y, Qfeed, dy, &ev);
	memcpy(res, ev.qdd, sizeof ev.qdd);
}

void dynamics_dense_solve(int n, int lda, double *A, double *b)
{
	for (int c = 0; c < n; c++) {
		int piv = c;
		for (int r = c + 1; r < n; r++)
			if (fabs(A[r * lda + c]) > fabs(A[piv * lda + c]))
				piv = r;
		for (int k = 0; k < n; k++) {
			double t = A[c * lda + k];
			A[c * lda + k] = A[piv * lda + k];
			A[piv * lda + k] = t;
		}
		double t = b[c];
		b[c] = b[piv];
		b[piv] = t;
		for (int r = c + 1; r < n; r++) {
			double f = A[r * lda + c] / A[c * lda + c];
			for (int k = c; k < n; k++)
				A[r * lda + k] -= f * A[c * lda + k];
			b[r] -= f * b[c];
		}
	}
	for (int c = n - 1; c >= 0; c--) {
		double s = b[c];
		for (int k = c + 1; k < n; k++)
			s -= A[c * lda + k] * b[k];
		b[c] = s / A[c * lda + c];
	}
}

/* Newton's iteration on the static accelerations of (x, y, alpha, s1, s2)
 * from the preload's strokes: q (written) at rest in equilibrium. */
static void static_equilibrium(const model *md, const model_ctl *ctl, double q[NQ_FULL])
{
	double s[2];
	model_static_strokes(&md->p, s);
	double q0[NQ_FULL] = {0, 0, 0, -M_PI / 2.0, s[0], s[1]};
	memcpy(q, q0, sizeof q0);
	/* Newton on (x, y, alpha, s1, s2) with phi = -pi/2, with the feed
	 * weight at the deck points; the static accelerations vanish */
	int idx[5] = {Q_X, Q_Y, Q_ALPHA, Q_S1, Q_S2};
	int n = md->alpha_fixed ? 4 : 5;
	if (md->alpha_fixed) {
		idx[2] = Q_S1;
		idx[3] = Q_S2;
	}
	for (int it = 0; it < 8; it++) {
		double r0[NQ_FULL];
		static_residual(md, ctl, q, r0);
		double J[5][5], rhs[5];
		double norm = 0.0;
		for (int a = 0; a < n; a++) {
			rhs[a] = -r0[idx[a]];
			norm = fmax(norm, fabs(rhs[a]));
		}
		if (norm < 1e-15)
			break;
		for (int b = 0; b < n; b++) {
			double hq = 1e-7;
			double qs = q[idx[b]];
			q[idx[b]] = qs + hq;
			double r1[NQ_FULL];
			static_residual(md, ctl, q, r1);
			q[idx[b]] = qs;
			for (int a = 0; a < n; a++)
				J[a][b] = (r1[idx[a]] - r0[idx[a]]) / hq;
		}
		dynamics_dense_solve(n, 5, &J[0][0], rhs);
		for (int a = 0; a < n; a++)
			q[idx[a]] += rhs[a];
	}
}

void dynamics_equilibrium(const model *md, model_ctl *ctl, double *y)
{
	double q[NQ_FULL];
	memset(y, 0, sizeof(double) * (size_t)md->n);
	static_equilibrium(md, ctl, q);
	/* reduced coordinates from the full ones */
	for (int r = 0; r < md->nq; r++) {
		for (int i = 0; i < NQ_FULL; i++) {
			if (md->T[i][r] == 1.0 && !(md->phi_prescribed && i == Q_PHI)) {
				y[r] = q[i];
				break;
			}
		}
	}
	if (md->phi_prescribed) {
		double speed = ctl->psi_ramp.v_end;
		ramp_hold(&ctl->psi_ramp, 0.0, q[Q_PHI] - q[Q_ALPHA], speed);
	}
	if (md->nf > 0) {
		double zero[NQ_FULL] = {0};
		deck_motion dm;
		deck_motion_eval(&md->dk, q, zero, &dm);
		feed_settle(md, y, &dm);
	}
}
