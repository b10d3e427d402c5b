/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * feed.c - the feed model (docs/MODEL.md "Feed", paper eqs. 6-9).
 *
 * Column k has layers j = 1..L (stored 0..L-1, bottom first) with absolute
 * coordinates xi (horizontal) and eta (vertical); layer 0 of the paper is
 * the deck point D_k = G + R(alpha)(d_k, h_d). Between layer j-1 and j:
 *   delta = eta_{j-1} - eta_j,  contact when delta > 0,
 *   F = k delta^p (loading, delta' >= 0) or R^2 k delta^p (unloading),
 *   T = -mu F sgn(xi'_j - xi'_{j-1})   (on layer j; -T on layer j-1).
 * The loading/unloading switch is taken at delta' = 0 with delta' >= 0 as
 * loading, so that a layer at rest carries its full load (the paper's
 * formula with sgn(0) = 0 would halve it there).
 *
 * The deck's motion comes in (deck_motion, or the deck point of one
 * sub-step); the feed's forces on the deck go out. No machine function is
 * called here: dynamics.c and ode_split.c couple the two.
 */
#include <math.h>
#include <string.h>

#include "feed.h"

/* The loading branch of the paper's contact law (eq. 7): k delta^p. */
static inline double loading_force(double k_c, double p, double delta)
{
	return p == 1.0 ? k_c * delta : k_c * pow(delta, p);
}

/* Normal contact force of the paper's law (eq. 7) for compression delta > 0
 * and its rate: loading k delta^p for rate >= 0, unloading R^2 k delta^p. */
static double contact_force(const model *md, double delta, double delta_dot)
{
	double f = loading_force(md->p.k_c, md->p.p, delta);
	return delta_dot >= 0.0 ? f : f * md->p.R * md->p.R;
}

static inline double friction_sign(const model *md, double v)
{
	if (md->sc.friction == SIM_FRICTION_REGULARISED)
		return tanh(v / md->sc.friction_eps);
	return (v > 0.0) - (v < 0.0);
}

/* Indices of the feed blocks in y. */
#define XI(md, y) ((y) + (md)->nq)
#define ETA(md, y) ((y) + (md)->nq + (md)->nf)
#define XID(md, y) ((y) + (md)->npos + (md)->nq)
#define ETAD(md, y) ((y) + (md)->npos + (md)->nq + (md)->nf)

/* Column k: accelerations into dy, deck force into F (2). */
static void column_rhs(const model *md, const double *y, int k, const double dpos[2],
		       const double dvel[2], double *dy, double F[2], double *fric,
		       double *contact)
{
	const int L = md->L, base = k * L;
	const double *xi = XI(md, y), *eta = ETA(md, y);
	const double *xid = XID(md, y), *etad = ETAD(md, y);
	double *axi = XID(md, dy), *aeta = ETAD(md, dy);
	const double mu = md->p.mu;
	double prev_eta = dpos[1], prev_etad = dvel[1], prev_xid = dvel[0];
	(void)xi;
	F[0] = F[1] = 0.0;
	for (int j = 0; j < L; j++) {
		int e = base + j;
		axi[e] = 0.0;
		aeta[e] = 0.0;
		double delta = prev_eta - eta[e];
		if (delta > 0.0) {
			double ddot = prev_etad - etad[e];
			double Fn = contact_force(md, delta, ddot);
			double vrel = xid[e] - prev_xid;
			double T = -mu * Fn * friction_sign(md, vrel);
			axi[e] += T;
			aeta[e] += Fn;
			if (j > 0) {
				axi[e - 1] -= T;
				aeta[e - 1] -= Fn;
			} else {
				F[0] = -T;
				F[1] = -Fn;
			}
			*contact += Fn * ddot;
			*fric -= T * vrel;
		}
		prev_eta = eta[e];
		prev_etad = etad[e];
		prev_xid = xid[e];
	}
	const double inv_m = 1.0 / md->p.m_n, g = md->p.g;
	for (int j = 0; j < L; j++) {
		axi[base + j] *= inv_m;
		aeta[base + j] = aeta[base + j] * inv_m - g;
	}
}

void feed_rhs(const model *md, const double *y, const deck_motion *dm, double *dy,
	      double (*F)[2], double *fric_power, double *contact_power)
{
	const int nf = md->nf;
	/* position rates are the velocities */
	memcpy(XI(md, dy), XID(md, y), sizeof(double) * (size_t)nf);
	memcpy(ETA(md, dy), ETAD(md, y), sizeof(double) * (size_t)nf);
	double fric = 0.0, contact = 0.0;
	for (int k = 0; k < md->dk.K; k++)
		column_rhs(md, y, k, dm->pos[k], dm->vel[k], dy, F[k], &fric, &contact);
	*fric_power = md->col_weight * fric;
	*contact_power = md->col_weight * contact;
}

void feed_deck_forces(const model *md, const double *y, const deck_motion *dm,
		      double (*F)[2])
{
	const double *eta = ETA(md, y), *xid = XID(md, y), *etad = ETAD(md, y);
	for (int k = 0; k < md->dk.K; k++) {
		/* column_rhs's bottom contact, the same arithmetic */
		const int e = k * md->L;
		double delta = dm->pos[k][1] - eta[e];
		F[k][0] = F[k][1] = 0.0;
		if (md->L > 0 && delta > 0.0) {
			double Fn = contact_force(md, delta, dm->vel[k][1] - etad[e]);
			double T = -md->p.mu * Fn * friction_sign(md, xid[e] - dm->vel[k][0]);
			F[k][0] = -T;
			F[k][1] = -Fn;
		}
	}
}

void feed_energy(const model *md, const double *y, double *kinetic, double *potential)
{
	const double *eta = ETA(md, y), *xid = XID(md, y), *etad = ETAD(md, y);
	double T = 0.0, V = 0.0;
	for (int e = 0; e < md->nf; e++) {
		T += xid[e] * xid[e] + etad[e] * etad[e];
		V += eta[e];
	}
	*kinetic = 0.5 * md->col_weight * md->p.m_n * T;
	*potential = md->col_weight * md->p.m_n * md->p.g * V;
}

double feed_contact_energy(const model *md, const double *y, const deck_motion *dm)
{
	const double *eta = ETA(md, y), *etad = ETAD(md, y);
	double E = 0.0;
	for (int k = 0; k < md->dk.K; k++) {
		double prev = dm->pos[k][1], prevd = dm->vel[k][1];
		for (int j = 0; j < md->L; j++) {
			int e = k * md->L + j;
			double delta = prev - eta[e];
			if (delta > 0.0)
				E += contact_force(md, delta, prevd - etad[e]) * delta /
				     (md->p.p + 1.0);
			prev = eta[e];
			prevd = etad[e];
		}
	}
	return md->col_weight * E;
}

void feed_settle(const model *md, double *y, const deck_motion *dm)
{
	double *xi = XI(md, y), *eta = ETA(md, y), *xid = XID(md, y), *etad = ETAD(md, y);
	const double w = md->p.m_n * md->p.g;
	for (int k = 0; k < md->dk.K; k++) {
		const double *pos = dm->pos[k];
		double level = pos[1];
		for (int j = 0; j < md->L; j++) {
			int e = k * md->L + j;
			/* layer j carries itself and every layer above it */
			double load = w * (double)(md->L - j);
			double delta = md->p.p == 1.0 ? load / md->p.k_c
						     : pow(load / md->p.k_c, 1.0 / md->p.p);
			level -= delta;
			eta[e] = level;
			xi[e] = pos[0];
			xid[e] = 0.0;
			etad[e] = 0.0;
		}
	}
}

void feed_scale_contacts(const model *md, double *y, const deck_motion *dm, double factor)
{
	double *eta = ETA(md, y);
	for (int k = 0; k < md->dk.K; k++) {
		/* the old level below each layer and where it now stands */
		double below_old = dm->pos[k][1], below_new = dm->pos[k][1];
		for (int j = 0; j < md->L; j++) {
			int e = k * md->L + j;
			double delta = below_old - eta[e];
			below_old = eta[e];
			eta[e] = below_new - (delta > 0.0 ? factor * delta : delta);
			below_new = eta[e];
		}
	}
}

double feed_mean_xi(const model *md, const double *y, int k)
{
	const double *xi = XI(md, y);
	int from = k < 0 ? 0 : k * md->L, to = k < 0 ? md->nf : from + md->L;
	double s = 0.0;
	for (int e = from; e < to; e++)
		s += xi[e];
	return to > from ? s / (double)(to - from) : 0.0;
}

double feed_mean_xi_rate(const model *md, const double *y)
{
	const double *xid = XID(md, y);
	double s = 0.0;
	for (int e = 0; e < md->nf; e++)
		s += xid[e];
	return md->nf > 0 ? s / md->nf : 0.0;
}

#include "feed_chain.h" /* the column's impulse solve */

/* A column's normal impulse bounds from the compressions at a sub-step's
 * start (the deck at height top): loading k delta^p h (hi), unloading
 * R^2 k delta^p h (lo); and the velocities the layers would reach under
 * gravity alone (vs). Inlined, with p a constant where the caller can
 * make it one. */
static inline void normal_bounds(int L, double h, double k_c, double p, double R2, double g,
				 double top, const double *eta, const double *etad, double *hi,
				 double *lo, double *vs)
{
	double prev_eta = top;
	for (int j = 0; j < L; j++) {
		double delta = prev_eta - eta[j];
		/* contact_force (delta, rate >= 0) with the parameters in
		 * registers: the arrays written here may not alias md */
		hi[j] = delta > 0.0 ? h * loading_force(k_c, p, delta) : 0.0;
		lo[j] = R2 * hi[j];
		vs[j] = etad[j] - g * h;
		prev_eta = eta[j];
	}
}

/* One sub-step of column k on the state y itself: the deck at dp (the
 * sub-step's start), its velocity dv1 at the middle and dv0 at the middle
 * of the sub-step before (friction events). Impulse on the deck into
 * imp[2]; its work added to *w. */
static inline void column_substep(const model *md, double *y, int k, double h, const double dp[2],
				  const double dv0[2], const double dv1[2], int events,
				  signed char *modes, double imp[2], feed_work *w)
{
	const int L = md->L, base = k * L;
	double *xi = XI(md, y) + base, *eta = ETA(md, y) + base, *xid = XID(md, y) + base,
	       *etad = ETAD(md, y) + base;
	const double m = md->p.m_n, g = md->p.g, mu = md->p.mu, R2 = md->p.R * md->p.R;
	const double k_c = md->p.k_c, p = md->p.p;
	double hi[SIM_MAX_LAYERS], lo[SIM_MAX_LAYERS], vs[SIM_MAX_LAYERS], Pn[SIM_MAX_LAYERS],
		Pt[SIM_MAX_LAYERS], vn[SIM_MAX_LAYERS], vt[SIM_MAX_LAYERS];
	signed char *mn = modes + base, *mt = modes + md->nf + base;
	if (L < 1 || L > SIM_MAX_LAYERS)
		return;
	if (p == 1.0) /* the linear law: its test out of the loop */
		normal_bounds(L, h, k_c, 1.0, R2, g, dp[1], eta, etad, hi, lo, vs);
	else
		normal_bounds(L, h, k_c, p, R2, g, dp[1], eta, etad, hi, lo, vs);
	chain_solve(L, m, vs, dv1[1], lo, hi, Pn, vn, mn, NULL);
	/* friction impulses within [-mu, mu] times the normal ones */
	for (int j = 0; j < L; j++) {
		hi[j] = mu * Pn[j];
		lo[j] = -hi[j];
	}
	if (md->sc.friction == SIM_FRICTION_COULOMB) {
		if (events)
			friction_events(L, m, xid, dv0[0], dv1[0], lo, hi, Pt, vt, mt);
		else
			chain_solve(L, m, xid, dv1[0], lo, hi, Pt, vt, mt, NULL);
	} else {
		/* regularised: explicit in the velocities at the start */
		for (int j = 0; j < L; j++) {
			double below = j == 0 ? dv1[0] : xid[j - 1];
			Pt[j] = hi[j] * tanh((below - xid[j]) / md->sc.friction_eps);
		}
		for (int j = 0; j < L; j++)
			vt[j] = xid[j] + (Pt[j] - (j + 1 < L ? Pt[j + 1] : 0.0)) / m;
	}
	/* Each impulse's work at the velocities the sub-step gives it: a
	 * layer's is the mean of its velocity before and after the impulses
	 * (an impulse P changes m v^2 / 2 by exactly P (v_before + v_after) /
	 * 2), the deck's the one the solve used (dv1). Contact j's work on the
	 * relative motion is then what it takes from the kinetic energy of
	 * the two sides, and the deck's work on the bottom layer what it
	 * gives: per sub-step, the column's kinetic and gravitational energy
	 * change by deck - friction - contact work exactly, but for gravity's
	 * m g h (v_after - v_before) / 2 per layer (the leapfrog's positions
	 * advance with v_after), which sums to a bounded term, not a drift. */
	double prev_vy = 2.0 * dv1[1], prev_vx = 2.0 * dv1[0], work_c = 0.0, work_f = 0.0;
	for (int j = 0; j < L; j++) {
		/* twice the mean velocities: the half taken once, below */
		double sum_vy = etad[j] + vn[j], sum_vx = xid[j] + vt[j];
		etad[j] = vn[j];
		xid[j] = vt[j];
		work_c += Pn[j] * (prev_vy - sum_vy);
		work_f += Pt[j] * (prev_vx - sum_vx);
		prev_vy = sum_vy;
		prev_vx = sum_vx;
		xi[j] += h * vt[j];
		eta[j] += h * vn[j];
	}
	w->contact += 0.5 * work_c;
	w->friction += 0.5 * work_f;
	w->deck += Pn[0] * dv1[1] + Pt[0] * dv1[0];
	imp[0] -= Pt[0];
	imp[1] -= Pn[0];
}

/* (feed.h) T_k = w J_k B, with B the trough's (x, y, alpha) part, J_k the
 * deck point's Jacobian on (x, y, alpha) and w the physical columns one
 * integrated column stands for. Mirrored states give mirrored T to the
 * last bit (each entry's terms change sign together). */
void feed_yield_compliance(const model *md, int nb, const double (*qr)[NQ_FULL], const deck_rot *R,
			   feed_yield *yl)
{
	double B[3][3] = {{0}};
	for (int c = 0; c < nb; c++) {
		double qdd[NQ_FULL];
		model_reduced_to_full(md, qr[c], qdd);
		for (int i = 0; i < 3; i++)
			B[i][c] = qdd[i];
	}
	/* J_k = [[1, 0, -Rd_y], [0, 1, Rd_x]] with Rd_k the deck point's
	 * arm from G */
	const deck *dk = &md->dk;
	yl->nb = nb;
	for (int k = 0; k < dk->K; k++) {
		double b[2] = {dk->d[k], dk->h_d}, *Rd = yl->Rd[k];
		deck_rotate(R, b, Rd);
		for (int q = 0; q < 3; q++) {
			yl->T[k][0][q] = md->col_weight * (B[0][q] - Rd[1] * B[2][q]);
			yl->T[k][1][q] = md->col_weight * (B[1][q] + Rd[0] * B[2][q]);
		}
	}
}

/* feed_yield_velocity's body, inlined into the sub-step loop */
static inline void yield_velocity(const feed_yield *yl, int K, const double (*E)[2],
				  double (*dv)[2])
{
	const int turns = yl->nb > 2;
	/* mirrored columns j and K-1-j summed first, so that a mirrored
	 * motion stays mirrored to the last bit (the pair's x and alpha parts
	 * cancel exactly); the three sums as scalars, in registers */
	double Gx = 0.0, Gy = 0.0, Ga = 0.0;
	for (int j = 0; j <= (K - 1) / 2; j++) {
		int jj = K - 1 - j;
		const double *Rj = yl->Rd[j], *Rjj = yl->Rd[jj];
		double gx = E[j][0], gy = E[j][1], ga = 0.0;
		if (turns)
			ga = -Rj[1] * E[j][0] + Rj[0] * E[j][1];
		if (jj != j) {
			gx += E[jj][0];
			gy += E[jj][1];
			if (turns)
				ga += -Rjj[1] * E[jj][0] + Rjj[0] * E[jj][1];
		}
		Gx += gx;
		Gy += gy;
		Ga += ga;
	}
	for (int k = 0; k < K; k++) {
		const double(*T)[3] = yl->T[k];
		dv[k][0] = T[0][0] * Gx + T[0][1] * Gy;
		dv[k][1] = T[1][0] * Gx + T[1][1] * Gy;
		if (turns) {
			dv[k][0] += T[0][2] * Ga;
			dv[k][1] += T[1][2] * Ga;
		}
	}
}

void feed_yield_velocity(const feed_yield *yl, int K, const double (*E)[2], double (*dv)[2])
{
	yield_velocity(yl, K, E, dv);
}

/* feed_dem_step's yielding deck for one integrated column (the symmetric
 * reduction's): yield_velocity's and the sub-step loop's arithmetic
 * operation for operation, the loops over the columns gone. */
static void one_column_yielding(const model *md, double *y, int ns, double h,
				const double (*pos)[2], const double (*vel)[2], int events,
				const feed_yield *yl, signed char *modes, double imp[2],
				feed_work *work)
{
	const int turns = yl->nb > 2;
	const double(*T)[3] = yl->T[0];
	const double *Rd = yl->Rd[0], *F = yl->F[0];
	double last0 = F[0] * h, last1 = F[1] * h, dv0 = 0.0, dv1 = 0.0, dp0 = 0.0, dp1 = 0.0;
	for (int i = 0; i < ns; i++) {
		double E0 = imp[0] + 0.5 * last0 - F[0] * (i + 0.5) * h;
		double E1 = imp[1] + 0.5 * last1 - F[1] * (i + 0.5) * h;
		double Gx = 0.0 + E0, Gy = 0.0 + E1, Ga = 0.0;
		if (turns)
			Ga += -Rd[1] * E0 + Rd[0] * E1;
		double n0 = T[0][0] * Gx + T[0][1] * Gy, n1 = T[1][0] * Gx + T[1][1] * Gy;
		if (turns) {
			n0 += T[0][2] * Ga;
			n1 += T[1][2] * Ga;
		}
		double p[2] = {pos[i][0] + dp0, pos[i][1] + dp1};
		double v0[2] = {vel[i][0] + dv0, vel[i][1] + dv1};
		double v1[2] = {vel[i + 1][0] + n0, vel[i + 1][1] + n1};
		dp0 += h * n0;
		dp1 += h * n1;
		dv0 = n0;
		dv1 = n1;
		double before0 = imp[0], before1 = imp[1];
		column_substep(md, y, 0, h, p, v0, v1, events, modes, imp, work);
		last0 = imp[0] - before0;
		last1 = imp[1] - before1;
	}
}

void feed_dem_step(const model *md, double *y, int ns, double h, const double (*deck_pos)[2],
		   const double (*deck_vel)[2], int events, const feed_yield *yield,
		   signed char *modes, double (*impulse)[2], feed_work *work)
{
	const int K = md->dk.K;
	if (md->L < 1 || md->L > SIM_MAX_LAYERS)
		return;
	for (int k = 0; k < K; k++)
		impulse[k][0] = impulse[k][1] = 0.0;
	if (!yield) {
		for (int k = 0; k < K; k++) {
			const double(*pos)[2] = deck_pos + (size_t)k * ns;
			const double(*vel)[2] = deck_vel + (size_t)k * (ns + 1);
			for (int i = 0; i < ns; i++)
				column_substep(md, y, k, h, pos[i], vel[i], vel[i + 1], events, modes,
					       impulse[k], work);
		}
		return;
	}
	if (K == 1) {
		one_column_yielding(md, y, ns, h, deck_pos, deck_vel, events, yield, modes,
				    impulse[0], work);
		return;
	}
	/* the deck yields: at the middle of sub-step i its velocity at
	 * column k moves by T_k G, G = sum_j J_j^T E_j the generalized
	 * impulse of E_j, the impulse column j gave the deck by then (each
	 * sub-step's spread over it, as the corrector spreads the step's;
	 * half of the one in progress, taken as the last one) less what the
	 * held reaction F_j accounts for by then; its position by the sum of
	 * those over the sub-steps before. At rest E is zero. */
	double last[SIM_MAX_COLUMNS][2], dv[SIM_MAX_COLUMNS][2], dp[SIM_MAX_COLUMNS][2],
		E[SIM_MAX_COLUMNS][2];
	for (int j = 0; j < K; j++) /* before the first: the held mean's */
		for (int c = 0; c < 2; c++) {
			last[j][c] = yield->F[j][c] * h;
			dv[j][c] = dp[j][c] = 0.0;
		}
	for (int i = 0; i < ns; i++) {
		for (int j = 0; j < K; j++)
			for (int c = 0; c < 2; c++)
				E[j][c] = impulse[j][c] + 0.5 * last[j][c] - yield->F[j][c] * (i + 0.5) * h;
		double dvn[SIM_MAX_COLUMNS][2];
		yield_velocity(yield, K, (const double(*)[2])E, dvn);
		for (int k = 0; k < K; k++) {
			const double(*pos)[2] = deck_pos + (size_t)k * ns;
			const double(*vel)[2] = deck_vel + (size_t)k * (ns + 1);
			const double *dvk = dvn[k];
			double p[2], v0[2], v1[2];
			for (int c = 0; c < 2; c++) {
				p[c] = pos[i][c] + dp[k][c];
				v0[c] = vel[i][c] + dv[k][c];
				v1[c] = vel[i + 1][c] + dvk[c];
				dp[k][c] += h * dvk[c];
				dv[k][c] = dvk[c];
			}
			double before[2] = {impulse[k][0], impulse[k][1]};
			column_substep(md, y, k, h, p, v0, v1, events, modes, impulse[k], work);
			last[k][0] = impulse[k][0] - before[0];
			last[k][1] = impulse[k][1] - before[1];
		}
	}
}
