/*
 * setup.c - builds the cheapest model a scene needs (MODEL.md "Model only
 * what a scene needs") and its initial state: the static equilibrium of
 * the machine with the suspension preload and the feed settled on the deck.
 *
 * Reductions:
 *   no feed            -> no feed coordinates;
 *   ideal drive        -> phi = alpha + psi(t) prescribed (constant speed);
 *   symmetric machine and no trough rotation asked for -> alpha = 0 and one
 *                         representative column standing for K;
 *   one-way coupling   -> the feed does not act on the trough.
 */
#include <math.h>
#include <string.h>

#include "feed.h"
#include "model.h"

static int machine_symmetric(const sim_params *p)
{
	return p->h == 0.0 && p->l1 == p->l2 && p->w_x == 0.0 && p->w_y == 0.0 &&
	       p->m1 == p->m2 && p->k_s1 == p->k_s2 && p->b_s1 == p->b_s2 &&
	       p->p1_x == -p->p2_x && p->p1_y == p->p2_y;
}

double model_feed_mass_ratio(const sim_params *p, const sim_scene *sc)
{
	if (!sc->feed)
		return 0.0;
	double feed = p->m_n * (double)sc->columns * (double)sc->layers;
	return feed / (p->M_r + p->m + p->m1 + p->m2);
}

void model_init(model *md, const sim_params *p, const sim_scene *sc)
{
	memset(md, 0, sizeof *md);
	md->p = *p;
	md->sc = *sc;
	md->rotation = p->rotation;
	md->omega_ss = p->omega_ss;
	md->drive_on = sc->motor_on;

	int feed = sc->feed && sc->columns > 0 && sc->layers > 0;
	int sym = !sc->trough_rotation && machine_symmetric(p);
	int ideal = sc->drive == SIM_DRIVE_IDEAL;
	if (!feed)
		md->reductions |= SIM_RED_NO_FEED;
	if (sym)
		md->reductions |= SIM_RED_SYMMETRIC;
	if (ideal)
		md->reductions |= SIM_RED_IDEAL_DRIVE;
	if (feed && !sc->feed_coupling)
		md->reductions |= SIM_RED_ONE_WAY;

	/* reduced coordinates: each full coordinate that is integrated gets a
	 * column; under the ideal drive phi follows alpha's column */
	int r = 0, col_alpha = -1;
	for (int i = 0; i < NQ_FULL; i++) {
		if (i == Q_ALPHA && sym)
			continue;
		if (i == Q_PHI && ideal)
			continue;
		if (i == Q_ALPHA)
			col_alpha = r;
		md->T[i][r++] = 1.0;
	}
	if (ideal && col_alpha >= 0)
		md->T[Q_PHI][col_alpha] = 1.0;
	md->nq = r;
	for (int c = 0; c < r; c++)
		for (int i = 0; i < NQ_FULL; i++)
			if (md->T[i][c] != 0.0)
				md->col[c][md->ncol[c]++] = i;
	md->alpha_fixed = sym;
	md->phi_prescribed = ideal;

	if (feed) {
		md->L = sc->layers;
		if (sym) {
			md->K = 1;
			md->col_weight = (double)sc->columns;
			md->d[0] = 0.0;
		} else {
			md->K = sc->columns;
			md->col_weight = 1.0;
			for (int k = 0; k < md->K; k++)
				md->d[k] = md->K == 1 ? 0.0
						      : p->column_span *
							    (-1.0 + 2.0 * (double)k / (double)(md->K - 1));
		}
		md->nf = md->K * md->L;
	}
	md->npos = md->nq + 2 * md->nf;
	md->n = 2 * md->npos + ACC_N;

	ramp_hold(&md->beta_ramp, 0.0, p->beta, 0.0);
	double speed = ideal && sc->motor_on ? (double)p->rotation * p->omega_ss : 0.0;
	ramp_hold(&md->psi_ramp, 0.0, -M_PI / 2.0, speed);
}

/* Static accelerations (zero exactly where gravity, springs with preload
 * and the feed weight at the deck points balance) at rest for full
 * coordinates q, motor off. */
static void static_residual(const model *md, const double q[NQ_FULL], double res[NQ_FULL])
{
	model tmp = *md; /* machine only, every coordinate free */
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
	tmp.drive_on = 0;
	double y[2 * NQ_FULL + ACC_N] = {0}, dy[2 * NQ_FULL + ACC_N];
	memcpy(y, q, sizeof(double) * NQ_FULL);
	double Qfeed[NQ_FULL] = {0}, F[64][2];
	model_rot R = model_rotation(q);
	/* one-way coupling: the feed's weight never reaches the trough */
	if (md->nf > 0 && md->sc.feed_coupling) {
		for (int k = 0; k < md->K; k++) {
			F[k][0] = 0.0;
			F[k][1] = -md->L * md->p.m_n * md->p.g;
		}
		model_deck_forces(md, &R, (const double(*)[2])F, md->col_weight, Qfeed);
	}
	model_eval ev;
	model_machine_rhs(&tmp, 0.0, y, Qfeed, dy, &ev);
	memcpy(res, ev.qdd, sizeof ev.qdd);
}

void model_equilibrium(model *md, double *y)
{
	const sim_params *p = &md->p;
	memset(y, 0, sizeof(double) * (size_t)md->n);
	/* preload: the empty machine at rest with x = y = alpha = 0 is in
	 * equilibrium with the eliminators at their static stroke and the
	 * unbalanced mass hanging down */
	double sb = sin(p->beta), cb = cos(p->beta);
	double s1 = -p->m1 * p->g * cb / p->k_s1, s2 = -p->m2 * p->g * cb / p->k_s2;
	double W = (p->M_r + p->m + p->m1 + p->m2) * p->g;
	double moment = p->g * (p->m * p->w_x + p->m1 * (p->p1_x - (p->c + s1) * sb) +
				p->m2 * (p->p2_x - (p->c + s2) * sb));
	/* F0_1 + F0_2 = W, l1 F0_1 - l2 F0_2 = moment */
	md->F0[0] = (moment + p->l2 * W) / (p->l1 + p->l2);
	md->F0[1] = W - md->F0[0];

	/* Newton on (x, y, alpha, s1, s2) with phi = -pi/2, with the feed
	 * weight at the deck points; the static accelerations vanish */
	double q[NQ_FULL] = {0, 0, 0, -M_PI / 2.0, s1, s2};
	int idx[5] = {Q_X, Q_Y, Q_ALPHA, Q_S1, Q_S2};
	int n = md->alpha_fixed ? 4 : 5;
	if (md->alpha_fixed) {
		idx[2] = Q_S1;
		idx[3] = Q_S2;
	}
	for (int it = 0; it < 8; it++) {
		double r0[NQ_FULL];
		static_residual(md, q, r0);
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
			static_residual(md, q, r1);
			q[idx[b]] = qs;
			for (int a = 0; a < n; a++)
				J[a][b] = (r1[idx[a]] - r0[idx[a]]) / hq;
		}
		/* Gaussian elimination with partial pivoting */
		for (int c = 0; c < n; c++) {
			int piv = c;
			for (int r = c + 1; r < n; r++)
				if (fabs(J[r][c]) > fabs(J[piv][c]))
					piv = r;
			for (int k = 0; k < n; k++) {
				double t = J[c][k];
				J[c][k] = J[piv][k];
				J[piv][k] = t;
			}
			double t = rhs[c];
			rhs[c] = rhs[piv];
			rhs[piv] = t;
			for (int r = c + 1; r < n; r++) {
				double f = J[r][c] / J[c][c];
				for (int k = c; k < n; k++)
					J[r][k] -= f * J[c][k];
				rhs[r] -= f * rhs[c];
			}
		}
		for (int c = n - 1; c >= 0; c--) {
			double s = rhs[c];
			for (int k = c + 1; k < n; k++)
				s -= J[c][k] * rhs[k];
			rhs[c] = s / J[c][c];
		}
		for (int a = 0; a < n; a++)
			q[idx[a]] += rhs[a];
	}
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
		double speed = md->psi_ramp.v_end;
		ramp_hold(&md->psi_ramp, 0.0, q[Q_PHI] - q[Q_ALPHA], speed);
	}
	if (md->nf > 0)
		feed_settle(md, y, q);
}
