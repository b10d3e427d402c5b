/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model.c - equations of motion of the machine (docs/MODEL.md "Equations of
 * motion"): exact planar rigid-body kinematics of the trough with three
 * point masses (unbalanced mass, two eliminator masses on guides turned to
 * beta(t)), mass matrix M = diag(M_r, M_r, J_r, J_w, 0, 0) + sum m_k J_k^T J_k
 * solved at every evaluation (model_solve.c), suspension with preload,
 * Kloss or ideal drive, and the feed's reaction as a given generalized
 * force.
 *
 * The right-hand side is a pipeline of stages (in the manner of MuJoCo's
 * mj_fwdPosition, mj_fwdVelocity, mj_fwdActuation, ...), each with a
 * one-line contract; model_machine_rhs runs them in this order:
 *   configure             q, q', beta(t), R(alpha), the three point masses
 *   mass_matrix_and_bias  M (lower half) and Q_feed - gravity - sum m J^T a
 *   suspension            spring sets with preload, their damping power
 *   eliminators           guide springs and dampers, their damping power
 *   drive                 motor torque, bearing drag and load, rotor speed
 *   solve                 reduced solve for q'' (model_solve.c; and the
 *                         ideal drive's torque that closes the rotor
 *                         equation)
 *   power                 drive and guide-actuator input, damping power
 *
 * Velocity-product and beta-rate terms enter through a_k in
 * r_k'' = J_k q'' + a_k; see the derivation next to point_mass_* in
 * model_points.h.
 */
#include <math.h>
#include <string.h>

#include "model.h"

/* Kloss static characteristic (paper eq. 10), for phi' > 0. */
static double kloss(const model *md, const model_ctl *ctl, double omega)
{
	double slip = ctl->omega_ss - omega;
	double s_ut = md->p.slip_ut;
	return 2.0 * md->p.M_ut * slip * s_ut / (s_ut * s_ut + slip * slip);
}

/* Motor torque on the rotor for relative speed omega, both senses: the
 * Kloss characteristic for phi' > 0 (clockwise), mirrored for phi' < 0. */
static double motor_torque(const model *md, const model_ctl *ctl, double omega)
{
	if (!ctl->drive_on)
		return 0.0;
	return ctl->rotation == SIM_CW ? kloss(md, ctl, omega) : -kloss(md, ctl, -omega);
}

#include "model_points.h" /* the three point masses' kinematics */

/* The full coordinates of reduced ones in the reduced scene's layout
 * (MODEL_LAYOUT_TROUGH2: x, y | phi, s1, s2; alpha none), each its reduced
 * one added to zero: the selection of model_full_coords, and zero plus
 * model_add_reduced, with the indices as constants (several times a step). */
static inline void trough2_full(const double *qr, double full[NQ_FULL])
{
	full[Q_X] = 0.0 + qr[0];
	full[Q_Y] = 0.0 + qr[1];
	full[Q_ALPHA] = 0.0;
	full[Q_PHI] = 0.0 + qr[2];
	full[Q_S1] = 0.0 + qr[3];
	full[Q_S2] = 0.0 + qr[4];
}

void model_full_coords(const model *md, const model_ctl *ctl, double t, const double *y,
		       double q[NQ_FULL], double qd[NQ_FULL])
{
	const double *qr = y, *qrd = y + md->npos;
	if (md->layout == MODEL_LAYOUT_TROUGH2) {
		trough2_full(qr, q);
		trough2_full(qrd, qd);
		return;
	}
	if (md->selection) {
		/* each reduced coordinate one full one, none prescribed: each
		 * full coordinate its reduced one added to zero, as
		 * model_add_reduced would, or zero (no clear of the whole
		 * arrays first: this runs several times a step) */
		for (int i = 0; i < NQ_FULL; i++) {
			int r = md->sel[i];
			q[i] = r < 0 ? 0.0 : 0.0 + qr[r];
			qd[i] = r < 0 ? 0.0 : 0.0 + qrd[r];
		}
		return;
	}
	memset(q, 0, sizeof(double) * NQ_FULL);
	memset(qd, 0, sizeof(double) * NQ_FULL);
	model_add_reduced(md, qr, q);
	model_add_reduced(md, qrd, qd);
	if (md->phi_prescribed) {
		double psi, psid, psidd;
		ramp_eval(&ctl->psi_ramp, t, &psi, &psid, &psidd);
		q[Q_PHI] += psi;
		qd[Q_PHI] += psid;
	}
}

void model_reduced_to_full(const model *md, const double *qr, double full[NQ_FULL])
{
	if (md->layout == MODEL_LAYOUT_TROUGH2) {
		trough2_full(qr, full);
		return;
	}
	memset(full, 0, sizeof(double) * NQ_FULL);
	model_add_reduced(md, qr, full);
}

/* The machine's configuration at time t: full coordinates, beta and its
 * rates, and the three point masses. */
typedef struct config {
	double q[NQ_FULL], qd[NQ_FULL];
	double beta, beta_d, beta_dd, sbeta, cbeta;
	deck_rot R;
	pm pms[3];
} config;

/* sin and cos of beta, remembered for the last beta this thread asked
 * for: beta is held for most of a run, and the memo is keyed by the exact
 * value, so the results are those of sin and cos themselves. */
static void beta_sincos(double beta, double *sb, double *cb)
{
	static _Thread_local double memo[3] = {NAN, NAN, NAN};
	if (beta != memo[0]) {
		memo[0] = beta;
		memo[1] = sin(beta);
		memo[2] = cos(beta);
	}
	*sb = memo[1];
	*cb = memo[2];
}

/* Stage configure: q, q', beta(t) and its rates, R(alpha), point masses. */
static void configure(const model *md, const model_ctl *ctl, double t, const double *y,
		      config *c)
{
	model_full_coords(md, ctl, t, y, c->q, c->qd);
	ramp_eval(&ctl->beta_ramp, t, &c->beta, &c->beta_d, &c->beta_dd);
	c->R = deck_rotation(c->q);
	beta_sincos(c->beta, &c->sbeta, &c->cbeta);
	point_mass_vibrator(md, &c->R, c->q, c->qd, &c->pms[0]);
	for (int i = 0; i < 2; i++)
		point_mass_eliminator(md, i, &c->R, c->q, c->qd, c->sbeta, c->cbeta, c->beta_d,
				      c->beta_dd, &c->pms[1 + i]);
}

/* rhs = Qfeed, or 0 without one: a copy of fixed size, a few vector moves */
static inline void feed_force(const double Qfeed[NQ_FULL], double rhs[NQ_FULL])
{
	if (Qfeed)
		memcpy(rhs, Qfeed, sizeof(double) * NQ_FULL);
	else
		memset(rhs, 0, sizeof(double) * NQ_FULL);
}

/* M = 0, a row at a time: each row's clear is a few vector stores, where
 * the whole matrix's was a string instruction with its start-up cost (5 %
 * of the evaluation on the reduced scene's path). */
static inline void zero_matrix(double M[NQ_FULL][NQ_FULL])
{
	for (int i = 0; i < NQ_FULL; i++)
		memset(M[i], 0, sizeof M[i]);
}

/* Stage mass_matrix_and_bias: lower half of M, and rhs = Qfeed - gravity -
 * sum m_k J_k^T a_k (the velocity-product and beta-rate terms). Each point
 * mass fills the (x, y, alpha) block, its own coordinate's row there and
 * its own (constant) diagonal; the own coordinates never couple. */
static void mass_matrix_and_bias(const model *md, const config *cf, const double Qfeed[NQ_FULL],
				 double M[NQ_FULL][NQ_FULL], double rhs[NQ_FULL])
{
	const sim_params *p = &md->p;
	zero_matrix(M);
	M[Q_X][Q_X] = M[Q_Y][Q_Y] = p->M_r;
	M[Q_ALPHA][Q_ALPHA] = p->J_r;
	feed_force(Qfeed, rhs);
	rhs[Q_Y] -= p->M_r * p->g;
	for (int k = 0; k < 3; k++) {
		const pm *P = &cf->pms[k];
		const double m = P->m, *ja = P->ja, *jo = P->jo;
		const int o = P->own;
		M[Q_X][Q_X] += m;
		M[Q_Y][Q_Y] += m;
		M[Q_ALPHA][Q_X] += m * ja[0];
		M[Q_ALPHA][Q_Y] += m * ja[1];
		M[Q_ALPHA][Q_ALPHA] += m * (ja[0] * ja[0] + ja[1] * ja[1]);
		M[o][Q_X] = m * jo[0];
		M[o][Q_Y] = m * jo[1];
		M[o][Q_ALPHA] = m * (jo[0] * ja[0] + jo[1] * ja[1]);
		M[o][o] = md->own_m[o];
		/* gravity and the velocity-product terms, -m J^T (a + g e_y) */
		double f0 = -m * P->a[0], f1 = -m * (P->a[1] + p->g);
		rhs[Q_X] += f0;
		rhs[Q_Y] += f1;
		rhs[Q_ALPHA] += ja[0] * f0 + ja[1] * f1;
		rhs[o] += jo[0] * f0 + jo[1] * f1;
	}
}

#include "model_trough2.h" /* the reduced scene's two stages, beta held */

/* Spring set i's attachment turned by R(alpha) (RP) and its displacement
 * from rest (u). */
static void suspension_point(const sim_params *p, const config *cf, int i, double RP[2],
			     double u[2])
{
	double Pb[2] = {i == 0 ? p->l1 : -p->l2, -p->h};
	deck_rotate(&cf->R, Pb, RP);
	u[0] = cf->q[Q_X] + RP[0] - Pb[0];
	u[1] = cf->q[Q_Y] + RP[1] - Pb[1];
}

/* The share of the settling damping the `steady` start adds at time t < 0:
 * full until settle_t0, then faded out by a half cosine to none at t = 0. */
static double settle_share(const model_ctl *ctl, double t)
{
	if (!(t < 0.0 && ctl->settle_b > 0.0))
		return 0.0;
	if (t <= ctl->settle_t0)
		return ctl->settle_b;
	return 0.5 * ctl->settle_b * (1.0 + cos(M_PI * (t - ctl->settle_t0) / -ctl->settle_t0));
}

/* Stage suspension: the two spring sets with preload into rhs; their
 * damping power is added to *damp_power. */
static inline __attribute__((always_inline)) void
suspension(const model *md, const model_ctl *ctl, double t, const config *cf, double rhs[NQ_FULL],
	   double *damp_power)
{
	const sim_params *p = &md->p;
	const double *qd = cf->qd;
	double extra = settle_share(ctl, t), vo[3] = {0.0, 0.0, 0.0};
	const trough_orbit *o = &md->settle_orbit;
	if (extra > 0.0 && o->sense != 0) {
		/* the forced response's rates at the rotor's present phase */
		double th = o->sense * (cf->q[Q_PHI] - cf->q[Q_ALPHA] - o->psi0);
		double thd = o->sense * (qd[Q_PHI] - qd[Q_ALPHA]);
		double sn = sin(th), cs = cos(th);
		for (int c = 0; c < 3; c++)
			vo[c] = thd * (-o->xya[c][1] * sn + o->xya[c][2] * cs);
	}
	for (int i = 0; i < 2; i++) {
		double RP[2], u[2];
		suspension_point(p, cf, i, RP, u);
		double vx = qd[Q_X] - qd[Q_ALPHA] * RP[1], vy = qd[Q_Y] + qd[Q_ALPHA] * RP[0];
		double Fx = -p->k_x * u[0] - p->b_x * vx;
		double Fy = -p->k_y * u[1] - p->b_y * vy + md->F0[i];
		if (extra > 0.0) {
			/* the settling's damper: on the spring set's velocity
			 * relative to that on the forced response */
			double Ex = -extra * md->settle_damping[0] * (vx - (vo[0] - vo[2] * RP[1]));
			double Ey = -extra * md->settle_damping[1] * (vy - (vo[1] + vo[2] * RP[0]));
			Fx += Ex;
			Fy += Ey;
			*damp_power -= Ex * vx + Ey * vy;
		}
		rhs[Q_X] += Fx;
		rhs[Q_Y] += Fy;
		rhs[Q_ALPHA] += -RP[1] * Fx + RP[0] * Fy;
		*damp_power += p->b_x * vx * vx + p->b_y * vy * vy;
	}
}

/* Stage eliminators: springs and dampers along the guides into rhs; their
 * damping power is added to *damp_power. */
static void eliminators(const sim_params *p, const config *cf, double rhs[NQ_FULL],
			double *damp_power)
{
	const double *q = cf->q, *qd = cf->qd;
	rhs[Q_S1] += -p->k_s1 * q[Q_S1] - p->b_s1 * qd[Q_S1];
	rhs[Q_S2] += -p->k_s2 * q[Q_S2] - p->b_s2 * qd[Q_S2];
	*damp_power += p->b_s1 * qd[Q_S1] * qd[Q_S1] + p->b_s2 * qd[Q_S2] * qd[Q_S2];
}

/* The drive's terms at one evaluation. */
typedef struct drive_terms {
	double omega;   /* rad/s rotor speed relative to the trough */
	double drag;    /* N m bearing drag */
	double load;    /* N m load torque */
	double torque;  /* N m motor torque (ideal drive: set by solve) */
} drive_terms;

/* Stage drive: motor torque (Kloss; none for the ideal drive), drag and
 * load (against the turning, at most M_load, near standstill the motor's
 * slip slope times the speed: it holds a standing rotor) on phi and their
 * reaction on alpha; drag and load power added to *damp_power. */
static inline __attribute__((always_inline)) void
drive(const model *md, const model_ctl *ctl, const config *cf, double rhs[NQ_FULL],
      double *damp_power, drive_terms *dt)
{
	const sim_params *p = &md->p;
	dt->omega = cf->qd[Q_PHI] - cf->qd[Q_ALPHA];
	dt->drag = p->b_phi * dt->omega * fabs(dt->omega);
	dt->load = -fmax(-p->M_load, fmin(p->M_load, 2.0 * p->M_ut / p->slip_ut * dt->omega));
	dt->torque = 0.0;
	if (!md->phi_prescribed)
		dt->torque = motor_torque(md, ctl, dt->omega);
	rhs[Q_PHI] += dt->torque - dt->drag + dt->load;
	rhs[Q_ALPHA] -= dt->torque - dt->drag + dt->load;
	*damp_power += dt->drag * dt->omega - dt->load * dt->omega;
}

/* The upper half of M from its lower half, for the general solve: the
 * layouts of constant sizes read the lower half only. */
static void symmetrize(const model *md, double M[NQ_FULL][NQ_FULL])
{
	if (md->layout != MODEL_LAYOUT_GENERAL)
		return;
	for (int i = 0; i < NQ_FULL; i++)
		for (int j = i + 1; j < NQ_FULL; j++)
			M[i][j] = M[j][i];
}

/* Stage solve: complete M, solve for qr'' (br) and the full q'' (qdd); under
 * the ideal drive the drive's torque is what closes the rotor's equation. */
static void solve(const model *md, const model_ctl *ctl, double t, double M[NQ_FULL][NQ_FULL],
		  const double rhs[NQ_FULL], drive_terms *dt, double br[NQ_FULL],
		  double qdd[NQ_FULL])
{
	symmetrize(md, M);
	/* prescribed accelerations q_p'' */
	double qpdd[NQ_FULL] = {0};
	if (md->phi_prescribed) {
		double psi, psid;
		ramp_eval(&ctl->psi_ramp, t, &psi, &psid, &qpdd[Q_PHI]);
	}
	model_reduced_solve(md, (const double(*)[NQ_FULL])M, rhs, qpdd, br);
	if (md->layout == MODEL_LAYOUT_TROUGH2) { /* no prescribed ones there */
		trough2_full(br, qdd);
		return;
	}
	memcpy(qdd, qpdd, sizeof(double) * NQ_FULL);
	model_add_reduced(md, br, qdd);
	if (md->phi_prescribed) {
		double s = -rhs[Q_PHI];
		for (int j = 0; j < NQ_FULL; j++)
			s += M[Q_PHI][j] * qdd[j];
		dt->torque = s;
	}
}

/* Eliminator mass k (1, 2) moves along dr/dbeta = (c + s) R u' when the
 * guide turns: returns c + s and writes R u'. */
static double guide_turn(const sim_params *p, const config *cf, int k, double Rup[2])
{
	double up[2] = {-cf->cbeta, -cf->sbeta};
	deck_rotate(&cf->R, up, Rup);
	return p->c + cf->q[k == 1 ? Q_S1 : Q_S2];
}

/* Stage power: work rate of the actuator that turns the guides (it carries
 * each eliminator mass along dr/dbeta against its inertia and weight, the
 * guide's normal force; zero while beta is held). */
static double guide_power(const sim_params *p, const config *cf, const double qdd[NQ_FULL])
{
	double power = 0.0;
	if (cf->beta_d == 0.0)
		return power;
	for (int k = 1; k < 3; k++) {
		const pm *P = &cf->pms[k];
		double acc[2];
		pm_velocity(P, qdd, acc);
		acc[0] += P->a[0];
		acc[1] += P->a[1] + p->g;
		double Rup[2];
		double cs = guide_turn(p, cf, k, Rup);
		power += P->m * cs * cf->beta_d * (acc[0] * Rup[0] + acc[1] * Rup[1]);
	}
	return power;
}

/* What an evaluation shows the observer. */
static void observe(const config *cf, const double qdd[NQ_FULL], const drive_terms *dt,
		    model_eval *ev)
{
	memcpy(ev->q, cf->q, sizeof ev->q);
	memcpy(ev->qd, cf->qd, sizeof ev->qd);
	memcpy(ev->qdd, qdd, sizeof ev->qdd);
	ev->beta = cf->beta;
	ev->beta_dot = cf->beta_d;
	ev->torque = dt->torque;
	ev->rotor_speed = dt->omega;
	ev->R = cf->R;
}

/* Stage deck load: an external feed's force at the centre deck point D =
 * G + R(alpha) (0, h_d) and its moment, J_D^T F + moment on alpha, into
 * rhs; returns its power F . v_D + moment alpha'. Nothing (and no
 * arithmetic) without a load, or under one-way coupling. */
static double deck_load(const model *md, const model_ctl *ctl, const config *cf, double rhs[NQ_FULL])
{
	const double *L = ctl->deck_load;
	if (!md->sc.feed_coupling || (L[0] == 0.0 && L[1] == 0.0 && L[2] == 0.0))
		return 0.0;
	const double rx = -cf->R.s * md->p.h_d, ry = cf->R.c * md->p.h_d;
	const double ad = cf->qd[Q_ALPHA];
	rhs[Q_X] += L[0];
	rhs[Q_Y] += L[1];
	rhs[Q_ALPHA] += rx * L[1] - ry * L[0] + L[2];
	return L[0] * (cf->qd[Q_X] - ad * ry) + L[1] * (cf->qd[Q_Y] + ad * rx) + L[2] * ad;
}

/* The stages between M and the solve: the deck's load (its power
 * returned), suspension, eliminators and drive, into rhs. */
static inline __attribute__((always_inline)) double
forces(const model *md, const model_ctl *ctl, double t, const config *cf, double rhs[NQ_FULL],
       double *damp_power, drive_terms *dt)
{
	double load_power = deck_load(md, ctl, cf, rhs);
	suspension(md, ctl, t, cf, rhs, damp_power);
	eliminators(&md->p, cf, rhs, damp_power);
	drive(md, ctl, cf, rhs, damp_power, dt);
	return load_power;
}

void model_machine_rhs(const model *md, const model_ctl *ctl, double t, const double *y,
		       const double Qfeed[NQ_FULL], double *dy, model_eval *ev)
{
	config cf;
	double Mown[NQ_FULL][NQ_FULL], rhs[NQ_FULL], br[NQ_FULL], qdd[NQ_FULL];
	/* M formed where the observer reads it, not copied there */
	double(*M)[NQ_FULL] = ev ? ev->M : Mown;
	double damp_power = 0.0;
	drive_terms dt;
	trough2_mass m2;
	double load_power;
	if (trough2_held(md, ctl, t, y, Qfeed, &cf, &m2, rhs)) {
		/* the layout's solve on M's entries in scalars */
		load_power = forces(md, ctl, t, &cf, rhs, &damp_power, &dt);
		trough2_solve(md, &m2, rhs, br);
		trough2_full(br, qdd);
		if (ev)
			trough2_matrix(&m2, ev->M);
	} else {
		configure(md, ctl, t, y, &cf);
		mass_matrix_and_bias(md, &cf, Qfeed, M, rhs);
		load_power = forces(md, ctl, t, &cf, rhs, &damp_power, &dt);
		solve(md, ctl, t, M, rhs, &dt, br, qdd);
	}
	/* positions' rates and accelerations; in the reduced scene's
	 * layout (x, y | phi, s1, s2) two copies of constant size */
	if (md->layout == MODEL_LAYOUT_TROUGH2) {
		memcpy(dy, y + md->npos, 5 * sizeof *dy);
		memcpy(dy + md->npos, br, 5 * sizeof *dy);
	} else {
		for (int r = 0; r < md->nq; r++) {
			dy[r] = y[md->npos + r];
			dy[md->npos + r] = br[r];
		}
	}
	dy[2 * md->npos + ACC_IN] = dt.torque * dt.omega + guide_power(&md->p, &cf, qdd) + load_power;
	dy[2 * md->npos + ACC_DAMP] = damp_power;
	if (ev)
		observe(&cf, qdd, &dt, ev);
}

void model_force_response(const model *md, const model_ctl *ctl, double t, const double *y,
			  const double Q[NQ_FULL], double *qrdd)
{
	config cf;
	double M[NQ_FULL][NQ_FULL], rhs[NQ_FULL];
	configure(md, ctl, t, y, &cf);
	mass_matrix_and_bias(md, &cf, NULL, M, rhs);
	symmetrize(md, M);
	model_reduced_solves(md, (const double(*)[NQ_FULL])M, 1, (const double(*)[NQ_FULL])Q,
			     (double(*)[NQ_FULL])qrdd);
}

void model_machine_energy(const model *md, const model_ctl *ctl, double t, const double *y,
			  double *kinetic, double *potential)
{
	const sim_params *p = &md->p;
	config cf;
	configure(md, ctl, t, y, &cf);
	const double *q = cf.q, *qd = cf.qd;
	double T = 0.5 * (p->M_r * (qd[Q_X] * qd[Q_X] + qd[Q_Y] * qd[Q_Y]) +
			  p->J_r * qd[Q_ALPHA] * qd[Q_ALPHA] + p->J_w * qd[Q_PHI] * qd[Q_PHI]);
	double V = p->M_r * p->g * q[Q_Y];
	for (int k = 0; k < 3; k++) {
		const pm *P = &cf.pms[k];
		double v[2];
		pm_velocity(P, qd, v);
		if (k > 0) { /* guide rotation: (c + s) beta' u' in the body frame */
			double Rup[2];
			double cs = guide_turn(p, &cf, k, Rup);
			v[0] += cs * cf.beta_d * Rup[0];
			v[1] += cs * cf.beta_d * Rup[1];
		}
		T += 0.5 * P->m * (v[0] * v[0] + v[1] * v[1]);
		V += P->m * p->g * (q[Q_Y] + P->r[1]);
	}
	for (int i = 0; i < 2; i++) {
		double RP[2], u[2];
		suspension_point(p, &cf, i, RP, u);
		V += 0.5 * (p->k_x * u[0] * u[0] + p->k_y * u[1] * u[1]) - md->F0[i] * u[1];
	}
	V += 0.5 * (p->k_s1 * q[Q_S1] * q[Q_S1] + p->k_s2 * q[Q_S2] * q[Q_S2]);
	*kinetic = T;
	*potential = V;
}
