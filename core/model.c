/*
 * model.c - equations of motion of the machine (MODEL.md "Equations of
 * motion"): exact planar rigid-body kinematics of the trough with three
 * point masses (unbalanced mass, two eliminator masses on guides turned to
 * beta(t)), mass matrix M = diag(M_r, M_r, J_r, J_w, 0, 0) + sum m_k J_k^T J_k
 * solved by Cholesky at every evaluation, suspension with preload, Kloss or
 * ideal drive, and the feed's reaction at the deck points.
 *
 * Velocity-product and beta-rate terms enter through a_k in
 * r_k'' = J_k q'' + a_k; see the derivation next to point_mass_* below.
 */
#include <math.h>
#include <string.h>

#include "model.h"
#include "feed.h"

static inline void rot(double ca, double sa, const double b[2], double out[2])
{
	out[0] = ca * b[0] - sa * b[1];
	out[1] = sa * b[0] + ca * b[1];
}

/* Kloss static characteristic (paper eq. 10), counter-clockwise sense. */
static double kloss(const model *md, double omega)
{
	double slip = md->omega_ss - omega;
	double s_ut = md->p.slip_ut;
	return 2.0 * md->p.M_ut * slip * s_ut / (s_ut * s_ut + slip * slip);
}

/* Motor torque on the rotor for relative speed omega, both senses. */
static double motor_torque(const model *md, double omega)
{
	if (!md->drive_on)
		return 0.0;
	return md->rotation == SIM_CCW ? kloss(md, omega) : -kloss(md, -omega);
}

/* One point mass: Jacobian columns (2 x 6, column-major jc[i][0..1]) and
 * the bias acceleration a. */
typedef struct pm {
	double m;
	double jc[NQ_FULL][2];
	double a[2];
	double r[2];  /* position relative to G */
} pm;

/* Unbalanced mass at G + R w + e (cos phi, sin phi):
 *   r'' = [I, perp(Rw), e(-sin phi, cos phi)] q'' - alpha'^2 Rw - e phi'^2 (cos, sin). */
static void point_mass_vibrator(const model *md, double ca, double sa, const double *q,
				const double *qd, pm *k)
{
	double w[2] = {md->p.w_x, md->p.w_y}, Rw[2];
	rot(ca, sa, w, Rw);
	double cf = cos(q[Q_PHI]), sf = sin(q[Q_PHI]), e = md->p.e;
	memset(k->jc, 0, sizeof k->jc);
	k->m = md->p.m;
	k->jc[Q_X][0] = 1.0;
	k->jc[Q_Y][1] = 1.0;
	k->jc[Q_ALPHA][0] = -Rw[1];
	k->jc[Q_ALPHA][1] = Rw[0];
	k->jc[Q_PHI][0] = -e * sf;
	k->jc[Q_PHI][1] = e * cf;
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
static void point_mass_eliminator(const model *md, int i, double ca, double sa,
				  const double *q, const double *qd, double sb, double cb,
				  double beta_d, double beta_dd, pm *k)
{
	int qs = i == 0 ? Q_S1 : Q_S2;
	double px = i == 0 ? md->p.p1_x : md->p.p2_x;
	double py = i == 0 ? md->p.p1_y : md->p.p2_y;
	double u[2] = {-sb, cb}, up[2] = {-cb, -sb};
	double cs = md->p.c + q[qs], sd = qd[qs], ad = qd[Q_ALPHA];
	double b[2] = {px + cs * u[0], py + cs * u[1]}, Rb[2], Ru[2];
	rot(ca, sa, b, Rb);
	rot(ca, sa, u, Ru);
	double brel[2] = {sd * u[0] + cs * beta_d * up[0], sd * u[1] + cs * beta_d * up[1]};
	double Rbrel[2];
	rot(ca, sa, brel, Rbrel);
	double g2 = 2.0 * sd * beta_d, h1 = cs * beta_dd, h2 = cs * beta_d * beta_d;
	double gl[2] = {g2 * up[0] + h1 * up[0] - h2 * u[0], g2 * up[1] + h1 * up[1] - h2 * u[1]};
	double Rgl[2];
	rot(ca, sa, gl, Rgl);
	memset(k->jc, 0, sizeof k->jc);
	k->m = i == 0 ? md->p.m1 : md->p.m2;
	k->jc[Q_X][0] = 1.0;
	k->jc[Q_Y][1] = 1.0;
	k->jc[Q_ALPHA][0] = -Rb[1];
	k->jc[Q_ALPHA][1] = Rb[0];
	k->jc[qs][0] = Ru[0];
	k->jc[qs][1] = Ru[1];
	k->a[0] = -ad * ad * Rb[0] - 2.0 * ad * Rbrel[1] + Rgl[0];
	k->a[1] = -ad * ad * Rb[1] + 2.0 * ad * Rbrel[0] + Rgl[1];
	k->r[0] = Rb[0];
	k->r[1] = Rb[1];
}

void model_full_coords(const model *md, double t, const double *y, double q[NQ_FULL],
		       double qd[NQ_FULL])
{
	const double *qr = y, *qrd = y + md->npos;
	memset(q, 0, sizeof(double) * NQ_FULL);
	memset(qd, 0, sizeof(double) * NQ_FULL);
	for (int r = 0; r < md->nq; r++)
		for (int a = 0; a < md->ncol[r]; a++) {
			q[md->col[r][a]] += qr[r];
			qd[md->col[r][a]] += qrd[r];
		}
	if (md->phi_prescribed) {
		double psi, psid, psidd;
		ramp_eval(&md->psi_ramp, t, &psi, &psid, &psidd);
		q[Q_PHI] += psi;
		qd[Q_PHI] += psid;
	}
}

void model_deck(const model *md, int k, const model_rot *R, const double q[NQ_FULL],
		const double qd[NQ_FULL], double pos[2], double vel[2])
{
	double dv[2] = {md->d[k], md->p.h_d}, Rd[2];
	rot(R->c, R->s, dv, Rd);
	pos[0] = q[Q_X] + Rd[0];
	pos[1] = q[Q_Y] + Rd[1];
	vel[0] = qd[Q_X] - qd[Q_ALPHA] * Rd[1];
	vel[1] = qd[Q_Y] + qd[Q_ALPHA] * Rd[0];
}

/* Generalized force of a force F applied at column k's deck point. */
static void deck_force(const model *md, int k, const model_rot *R, const double F[2],
		       double Q[NQ_FULL])
{
	double dv[2] = {md->d[k], md->p.h_d}, Rd[2];
	rot(R->c, R->s, dv, Rd);
	Q[Q_X] += F[0];
	Q[Q_Y] += F[1];
	Q[Q_ALPHA] += -Rd[1] * F[0] + Rd[0] * F[1];
}

void model_deck_forces(const model *md, const model_rot *R, const double (*F)[2],
		       double scale, double Q[NQ_FULL])
{
	for (int k = 0; k <= (md->K - 1) / 2; k++) {
		int kk = md->K - 1 - k;
		double Qpair[NQ_FULL] = {0}, Qm[NQ_FULL] = {0};
		deck_force(md, k, R, F[k], Qpair);
		if (kk != k) {
			deck_force(md, kk, R, F[kk], Qm);
			for (int i = 0; i < NQ_FULL; i++)
				Qpair[i] += Qm[i];
		}
		for (int i = 0; i < NQ_FULL; i++)
			Q[i] += scale * Qpair[i];
	}
}

/* In-place Cholesky solve of the n x n SPD system A x = b (A overwritten).
 * Returns 0, or -1 if A is not positive definite. */
static int cholesky_solve(int n, double A[NQ_FULL][NQ_FULL], double *b)
{
	for (int j = 0; j < n; j++) {
		double d = A[j][j];
		for (int k = 0; k < j; k++)
			d -= A[j][k] * A[j][k];
		if (!(d > 0.0))
			return -1;
		d = sqrt(d);
		A[j][j] = d;
		for (int i = j + 1; i < n; i++) {
			double s = A[i][j];
			for (int k = 0; k < j; k++)
				s -= A[i][k] * A[j][k];
			A[i][j] = s / d;
		}
	}
	for (int i = 0; i < n; i++) {
		double s = b[i];
		for (int k = 0; k < i; k++)
			s -= A[i][k] * b[k];
		b[i] = s / A[i][i];
	}
	for (int i = n - 1; i >= 0; i--) {
		double s = b[i];
		for (int k = i + 1; k < n; k++)
			s -= A[k][i] * b[k];
		b[i] = s / A[i][i];
	}
	return 0;
}

/* The machine's configuration at time t: full coordinates, beta and its
 * rates, and the three point masses. */
typedef struct config {
	double q[NQ_FULL], qd[NQ_FULL];
	double beta, beta_d, beta_dd, sbeta, cbeta;
	double ca, sa;
	pm pms[3];
} config;

static void configure(const model *md, double t, const double *y, config *c)
{
	model_full_coords(md, t, y, c->q, c->qd);
	ramp_eval(&md->beta_ramp, t, &c->beta, &c->beta_d, &c->beta_dd);
	model_rot Ra = model_rotation(c->q);
	c->ca = Ra.c;
	c->sa = Ra.s;
	c->sbeta = sin(c->beta);
	c->cbeta = cos(c->beta);
	point_mass_vibrator(md, c->ca, c->sa, c->q, c->qd, &c->pms[0]);
	for (int i = 0; i < 2; i++)
		point_mass_eliminator(md, i, c->ca, c->sa, c->q, c->qd, c->sbeta, c->cbeta,
				      c->beta_d, c->beta_dd, &c->pms[1 + i]);
}

/* Machine: mass matrix, forces without the feed (plus Qextra), reduced
 * solve. Writes machine accelerations into dy and the machine powers. */
static void machine(model *md, double t, const double *y, const double Qextra[NQ_FULL],
		    double *dy, model_eval *ev)
{
	const sim_params *p = &md->p;
	config cf;
	configure(md, t, y, &cf);
	const double *q = cf.q, *qd = cf.qd, ca = cf.ca, sa = cf.sa;
	const double beta = cf.beta, beta_d = cf.beta_d, sbeta = cf.sbeta, cbeta = cf.cbeta;
	const pm *pms = cf.pms;

	double M[NQ_FULL][NQ_FULL] = {{0}};
	double rhs[NQ_FULL];
	M[Q_X][Q_X] = p->M_r;
	M[Q_Y][Q_Y] = p->M_r;
	M[Q_ALPHA][Q_ALPHA] = p->J_r;
	M[Q_PHI][Q_PHI] = p->J_w;
	for (int i = 0; i < NQ_FULL; i++)
		rhs[i] = Qextra ? Qextra[i] : 0.0;
	rhs[Q_Y] -= p->M_r * p->g;
	for (int k = 0; k < 3; k++) {
		const pm *P = &pms[k];
		for (int i = 0; i < NQ_FULL; i++) {
			double ji0 = P->jc[i][0], ji1 = P->jc[i][1];
			if (ji0 == 0.0 && ji1 == 0.0)
				continue;
			for (int j = 0; j <= i; j++)
				M[i][j] += P->m * (ji0 * P->jc[j][0] + ji1 * P->jc[j][1]);
			/* gravity and the velocity-product terms */
			rhs[i] += P->m * (-ji1 * p->g - ji0 * P->a[0] - ji1 * P->a[1]);
		}
	}
	double damp_power = 0.0;
	/* suspension spring sets with preload */
	for (int i = 0; i < 2; i++) {
		double Pb[2] = {i == 0 ? p->l1 : -p->l2, -p->h}, RP[2];
		rot(ca, sa, Pb, RP);
		double ux = q[Q_X] + RP[0] - Pb[0], uy = q[Q_Y] + RP[1] - Pb[1];
		double vx = qd[Q_X] - qd[Q_ALPHA] * RP[1], vy = qd[Q_Y] + qd[Q_ALPHA] * RP[0];
		double Fx = -p->k_x * ux - p->b_x * vx;
		double Fy = -p->k_y * uy - p->b_y * vy + md->F0[i];
		rhs[Q_X] += Fx;
		rhs[Q_Y] += Fy;
		rhs[Q_ALPHA] += -RP[1] * Fx + RP[0] * Fy;
		damp_power += p->b_x * vx * vx + p->b_y * vy * vy;
	}
	/* eliminator springs and dampers along the guides */
	rhs[Q_S1] += -p->k_s1 * q[Q_S1] - p->b_s1 * qd[Q_S1];
	rhs[Q_S2] += -p->k_s2 * q[Q_S2] - p->b_s2 * qd[Q_S2];
	damp_power += p->b_s1 * qd[Q_S1] * qd[Q_S1] + p->b_s2 * qd[Q_S2] * qd[Q_S2];
	/* drive: torque on the rotor, reaction on the trough */
	double omega = qd[Q_PHI] - qd[Q_ALPHA];
	double drag = p->b_phi * omega * fabs(omega);
	double load = -(double)md->rotation * p->M_load;
	double torque = 0.0;
	if (!md->phi_prescribed)
		torque = motor_torque(md, omega);
	rhs[Q_PHI] += torque - drag + load;
	rhs[Q_ALPHA] -= torque - drag + load;
	damp_power += drag * omega - load * omega;

	/* complete the symmetric M */
	for (int i = 0; i < NQ_FULL; i++)
		for (int j = i + 1; j < NQ_FULL; j++)
			M[i][j] = M[j][i];

	/* prescribed accelerations q_p'' */
	double qpdd[NQ_FULL] = {0};
	if (md->phi_prescribed) {
		double psi, psid;
		ramp_eval(&md->psi_ramp, t, &psi, &psid, &qpdd[Q_PHI]);
	}
	/* reduced system Tt M T qr'' = Tt (rhs - M qp''); T only selects
	 * coordinates or moves two together, so sums over index lists do */
	int n = md->nq;
	double Mr[NQ_FULL][NQ_FULL], br[NQ_FULL];
	double res[NQ_FULL];
	for (int i = 0; i < NQ_FULL; i++) {
		double s = rhs[i];
		if (md->phi_prescribed)
			s -= M[i][Q_PHI] * qpdd[Q_PHI];
		res[i] = s;
	}
	for (int r = 0; r < n; r++) {
		const int *ir = md->col[r];
		br[r] = md->ncol[r] == 1 ? res[ir[0]] : res[ir[0]] + res[ir[1]];
		for (int c = 0; c <= r; c++) {
			const int *ic = md->col[c];
			double m = 0.0;
			for (int a = 0; a < md->ncol[r]; a++)
				for (int b = 0; b < md->ncol[c]; b++)
					m += M[ir[a]][ic[b]];
			Mr[r][c] = m;
		}
	}
	if (cholesky_solve(n, Mr, br) != 0) {
		for (int r = 0; r < n; r++)
			br[r] = NAN;
	}
	double qdd[NQ_FULL];
	memcpy(qdd, qpdd, sizeof qdd);
	for (int r = 0; r < n; r++)
		for (int a = 0; a < md->ncol[r]; a++)
			qdd[md->col[r][a]] += br[r];
	if (md->phi_prescribed) {
		/* the drive's torque closes the rotor's equation */
		double s = -rhs[Q_PHI] - drag + load;
		for (int j = 0; j < NQ_FULL; j++)
			s += M[Q_PHI][j] * qdd[j];
		torque = s;
	}
	for (int r = 0; r < n; r++) {
		dy[r] = y[md->npos + r];
		dy[md->npos + r] = br[r];
	}
	/* work of the actuator that turns the guides: it carries each
	 * eliminator mass along dr/dbeta = (c + s) R u' against its inertia
	 * and weight (the guide's normal force); zero while beta is held */
	double guide_power = 0.0;
	if (beta_d != 0.0) {
		for (int k = 1; k < 3; k++) {
			const pm *P = &pms[k];
			double acc[2] = {P->a[0], P->a[1] + p->g};
			for (int i = 0; i < NQ_FULL; i++) {
				acc[0] += P->jc[i][0] * qdd[i];
				acc[1] += P->jc[i][1] * qdd[i];
			}
			double cs = p->c + q[k == 1 ? Q_S1 : Q_S2];
			double up[2] = {-cbeta, -sbeta}, Rup[2];
			rot(ca, sa, up, Rup);
			guide_power += P->m * cs * beta_d * (acc[0] * Rup[0] + acc[1] * Rup[1]);
		}
	}
	dy[2 * md->npos + ACC_IN] = torque * omega + guide_power;
	dy[2 * md->npos + ACC_DAMP] = damp_power;
	if (ev) {
		memcpy(ev->q, q, sizeof ev->q);
		memcpy(ev->qd, qd, sizeof ev->qd);
		memcpy(ev->qdd, qdd, sizeof qdd);
		ev->beta = beta;
		ev->beta_dot = beta_d;
		ev->torque = torque;
		ev->rotor_speed = omega;
		double dv[2] = {0.0, p->h_d}, Rd[2];
		rot(ca, sa, dv, Rd);
		ev->deck[0] = q[Q_X] + Rd[0] - dv[0];
		ev->deck[1] = q[Q_Y] + Rd[1] - dv[1];
		ev->deck_vel[0] = qd[Q_X] - qd[Q_ALPHA] * Rd[1];
		ev->deck_vel[1] = qd[Q_Y] + qd[Q_ALPHA] * Rd[0];
	}
}

void model_machine_rhs(model *md, double t, const double *y, const double Qfeed[NQ_FULL],
		       double *dy, model_eval *ev)
{
	md->rhs_evals++;
	machine(md, t, y, Qfeed, dy, ev);
}

void model_rhs(model *md, double t, const double *y, double *dy, model_eval *ev)
{
	md->rhs_evals++;
	double Qfeed[NQ_FULL] = {0};
	double *acc = dy + 2 * md->npos;
	acc[ACC_FRIC] = 0.0;
	acc[ACC_CONTACT] = 0.0;
	if (md->nf > 0) {
		double q[NQ_FULL], qd[NQ_FULL];
		model_full_coords(md, t, y, q, qd);
		feed_rhs(md, y, q, qd, dy, Qfeed, &acc[ACC_FRIC], &acc[ACC_CONTACT]);
		if (!md->sc.feed_coupling)
			memset(Qfeed, 0, sizeof Qfeed);
	}
	machine(md, t, y, Qfeed, dy, ev);
}

double model_contact_force(const model *md, double delta, double delta_dot)
{
	double f = md->p.p == 1.0 ? md->p.k_c * delta : md->p.k_c * pow(delta, md->p.p);
	return delta_dot >= 0.0 ? f : f * md->p.R * md->p.R;
}

double model_energy_stored(model *md, double t, const double *y, double *kinetic,
			   double *potential)
{
	const sim_params *p = &md->p;
	config cf;
	configure(md, t, y, &cf);
	const double *q = cf.q, *qd = cf.qd, ca = cf.ca, sa = cf.sa;
	const double beta_d = cf.beta_d, sbeta = cf.sbeta, cbeta = cf.cbeta;
	const pm *pms = cf.pms;
	double T = 0.5 * (p->M_r * (qd[Q_X] * qd[Q_X] + qd[Q_Y] * qd[Q_Y]) +
			  p->J_r * qd[Q_ALPHA] * qd[Q_ALPHA] + p->J_w * qd[Q_PHI] * qd[Q_PHI]);
	double V = p->M_r * p->g * q[Q_Y];
	for (int k = 0; k < 3; k++) {
		const pm *P = &pms[k];
		double v[2] = {0.0, 0.0};
		for (int i = 0; i < NQ_FULL; i++) {
			v[0] += P->jc[i][0] * qd[i];
			v[1] += P->jc[i][1] * qd[i];
		}
		if (k > 0) { /* guide rotation: (c + s) beta' u' in the body frame */
			double cs = p->c + q[k == 1 ? Q_S1 : Q_S2];
			double up[2] = {-cbeta, -sbeta}, Rup[2];
			rot(ca, sa, up, Rup);
			v[0] += cs * beta_d * Rup[0];
			v[1] += cs * beta_d * Rup[1];
		}
		T += 0.5 * P->m * (v[0] * v[0] + v[1] * v[1]);
		V += P->m * p->g * (q[Q_Y] + P->r[1]);
	}
	for (int i = 0; i < 2; i++) {
		double Pb[2] = {i == 0 ? p->l1 : -p->l2, -p->h}, RP[2];
		rot(ca, sa, Pb, RP);
		double ux = q[Q_X] + RP[0] - Pb[0], uy = q[Q_Y] + RP[1] - Pb[1];
		V += 0.5 * (p->k_x * ux * ux + p->k_y * uy * uy) - md->F0[i] * uy;
	}
	V += 0.5 * (p->k_s1 * q[Q_S1] * q[Q_S1] + p->k_s2 * q[Q_S2] * q[Q_S2]);
	double Tf = 0.0, Vf = 0.0;
	if (md->nf > 0)
		feed_energy(md, y, &Tf, &Vf);
	*kinetic = T + Tf;
	*potential = V + Vf;
	return *kinetic + *potential;
}
