/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * steady.c - the machine part of the `steady` start (docs/MODEL.md "Start
 * steady"): the machine on its periodic forced response at the loaded
 * motor speed, the feed settled on the moving deck.
 *
 * Where alpha is fixed (the symmetric reduction, the defaults) the machine
 * at a constant rotor speed is linear, and its forced response is solved
 * in the frequency domain (harmonic_orbit below), the linear solution
 * MODEL.md names, in about 30 evaluations of the right-hand side.
 * Otherwise it is found by shooting (Nayfeh & Balachandran, Applied
 * Nonlinear Dynamics, 1995, ch. 7): the machine alone, the feed's weight
 * resting on the deck points as constant forces, the rotor turning at a
 * constant relative speed Omega, is periodic with T = 2 pi / |Omega|;
 * Newton's method on z -> Phi_T(z) - z (Phi_T: one period of classical
 * RK4, its Jacobian by finite differences and kept while the residual
 * falls tenfold per step) finds the periodic state z. The machine is nearly linear, so this is the linear
 * frequency-domain solution plus its small nonlinear corrections, and two
 * or three Newton steps converge. With the Kloss motor, Omega is where the
 * motor's torque balances the mean torque that the periodic motion draws
 * (dampers, bearing drag, load): a fixed-point iteration on the motor's
 * stable branch, ended once the speed moves by less than OMEGA_TOL of it.
 *
 * The steps per period: at least 32, and more where a mode of the machine
 * is fast, so that h omega <= 0.2 for its fastest mode. For czubak2016
 * that is 32 (T = 0.04 s, h = 1.25e-3 s, as fine as the default
 * machine step that follows). Measured over the 74 points: v moved by at most
 * 4.2e-6 m/s against 128 steps per period, as much as a round-off change
 * moves it (the settling that follows forgets the start's own small
 * error); with the early end of the speed iteration the shooting fell
 * from about 2 ms to 0.5 ms a point. The feed's own dissipation is not known before it moves;
 * sim.c's settling phase takes care of what remains.
 */
#include <math.h>
#include <string.h>

#include "dynamics.h"
#include "feed.h"

enum { STEPS_MIN = 32, NEWTON_MAX = 6, OMEGA_ITER = 4, NZ = 2 * NQ_FULL };
#define STEP_PHASE_MAX 0.2 /* h omega of the fastest mode, at most */
#define OMEGA_TOL 1e-7     /* relative change of the motor speed that ends it */

typedef struct shooter {
	model mm;           /* the machine alone, phi - alpha prescribed */
	model_ctl ctl;      /* its controls: beta held, psi at Omega */
	const model *md;    /* the scene's model: deck points, feed weight */
	double T;           /* s, the period */
	int steps;          /* RK4 steps per period */
	double mean_torque; /* N m, of the last period integrated */
	double orbit[3][3]; /* the trough's x, y, alpha on it: mean, cos and sin
			     * parts in the rotor's phase (the last period
			     * one_period recorded, or harmonic_orbit's) */
} shooter;

static void shoot_rhs(const shooter *sh, double t, const double *y, double *dy, model_eval *ev)
{
	double q[NQ_FULL], qd[NQ_FULL], Qfeed[NQ_FULL] = {0};
	model_full_coords(&sh->mm, &sh->ctl, t, y, q, qd);
	dynamics_feed_weight(sh->md, q, Qfeed);
	model_machine_rhs(&sh->mm, &sh->ctl, t, y, Qfeed, dy, ev);
}

/* One period of classical RK4 from z (positions then rates, 2 nq values):
 * the end state into out, the drive's mean torque into sh->mean_torque,
 * and with record the trough's x, y, alpha over it into sh->orbit (the mean
 * and the first harmonic of the steps' starts, a discrete Fourier
 * transform in the phase 2 pi s / steps). */
static void one_period(shooter *sh, const double *z, double *out, int record)
{
	const model *mm = &sh->mm;
	int nq = mm->nq, n = mm->n;
	double y[NZ + ACC_N] = {0}, k1[NZ + ACC_N], k2[NZ + ACC_N], k3[NZ + ACC_N],
	       k4[NZ + ACC_N], tmp[NZ + ACC_N];
	memcpy(y, z, sizeof(double) * (size_t)nq);
	memcpy(y + mm->npos, z + nq, sizeof(double) * (size_t)nq);
	double h = sh->T / sh->steps, t = 0.0, torque = 0.0, dft[3][3] = {{0}};
	model_eval ev;
	for (int s = 0; s < sh->steps; s++) {
		shoot_rhs(sh, t, y, k1, &ev);
		torque += ev.torque;
		if (record) {
			double th = 2.0 * M_PI * s / sh->steps, c = cos(th), sn = sin(th);
			for (int i = 0; i < 3; i++) { /* x, y, alpha */
				dft[i][0] += ev.q[i] / sh->steps;
				dft[i][1] += 2.0 * c * ev.q[i] / sh->steps;
				dft[i][2] += 2.0 * sn * ev.q[i] / sh->steps;
			}
		}
		for (int i = 0; i < n; i++)
			tmp[i] = y[i] + 0.5 * h * k1[i];
		shoot_rhs(sh, t + 0.5 * h, tmp, k2, NULL);
		for (int i = 0; i < n; i++)
			tmp[i] = y[i] + 0.5 * h * k2[i];
		shoot_rhs(sh, t + 0.5 * h, tmp, k3, NULL);
		for (int i = 0; i < n; i++)
			tmp[i] = y[i] + h * k3[i];
		shoot_rhs(sh, t + h, tmp, k4, NULL);
		for (int i = 0; i < n; i++)
			y[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
		t += h;
	}
	sh->mean_torque = torque / sh->steps;
	if (record)
		memcpy(sh->orbit, dft, sizeof dft);
	memcpy(out, y, sizeof(double) * (size_t)nq);
	memcpy(out + nq, y + mm->npos, sizeof(double) * (size_t)nq);
}

/* Jacobian of z -> Phi_T(z) - z at z by forward differences (end =
 * Phi_T(z) given; sh->mean_torque is kept, that of z). */
static void shoot_jacobian(shooter *sh, const double *z, const double *end, double J[NZ][NZ])
{
	int m = 2 * sh->mm.nq;
	double pert[NZ], endp[NZ], torque = sh->mean_torque;
	for (int b = 0; b < m; b++) {
		memcpy(pert, z, sizeof(double) * (size_t)m);
		double hz = 1e-7 * fmax(fabs(z[b]), b < m / 2 ? 1e-3 : 1e-1);
		pert[b] += hz;
		one_period(sh, pert, endp, 0);
		for (int a = 0; a < m; a++)
			J[a][b] = (endp[a] - end[a]) / hz - (a == b ? 1.0 : 0.0);
	}
	sh->mean_torque = torque;
}

/* Newton on Phi_T(z) - z = 0 from the guess in z (updated). The machine is
 * nearly linear, so the Jacobian in *J (valid when *have_J) is kept while
 * each step shrinks the residual at least tenfold (the chord method; the
 * motor-speed rounds reuse it as well), and computed afresh otherwise. */
static void shoot(shooter *sh, double *z, double J[NZ][NZ], int *have_J)
{
	int m = 2 * sh->mm.nq;
	double end[NZ], A[NZ][NZ], r[NZ], last = INFINITY;
	for (int it = 0; it < NEWTON_MAX; it++) {
		one_period(sh, z, end, 1);
		double norm = 0.0, scale = 0.0;
		for (int i = 0; i < m; i++) {
			r[i] = z[i] - end[i];
			norm = fmax(norm, fabs(r[i]));
			scale = fmax(scale, fabs(z[i]));
		}
		if (norm <= 1e-13 * fmax(scale, 1e-3))
			break;
		if (!*have_J || !(norm <= 0.1 * last)) {
			shoot_jacobian(sh, z, end, J);
			*have_J = 1;
		}
		last = norm;
		memcpy(A, J, sizeof A);
		dynamics_dense_solve(m, NZ, &A[0][0], r);
		for (int i = 0; i < m; i++)
			if (!isfinite(r[i]))
				return;
		for (int i = 0; i < m; i++)
			z[i] += r[i];
	}
}

/* The forced response of a linear machine (alpha fixed, so R = I, and
 * beta held): in its reduced coordinates (x, y, s1, s2) the mass matrix is
 * constant and every force is linear in q and q' but for the drive's
 * (e Omega^2 at the rotor's angle, first harmonic) and the constant ones,
 * so q'' = A q + B q' + g0 + gc cos(theta) + gs sin(theta), theta = |Omega|
 * t. A and B come from the machine's own right-hand side, one column per
 * unit change of a coordinate (exact for a linear map up to round-off);
 * g's parts from HARMONIC_SAMPLES evaluations at q = q' = 0 over a
 * period (a discrete Fourier transform, exact with no harmonic above the
 * first). The periodic solution q0 + qc cos + qs sin then solves
 *   A q0 = -g0,  [A + w^2, w B; -w B, A + w^2] [qc; qs] = -[gc; gs]
 * (w = |Omega|): MODEL.md's linear frequency-domain solution itself, with
 * no time step. The drive's mean torque is the mean over the same samples
 * of the orbit (a trigonometric polynomial of degree 2: exact). About 30
 * evaluations where the shooting takes 22 periods of RK4 (2,800). z gets
 * the state at t = 0; returns 0, or -1 if a solve fails (the caller then
 * shoots). */
enum { HARMONIC_SAMPLES = 8 };

static int harmonic_orbit(shooter *sh, double *z)
{
	const model *mm = &sh->mm;
	const int nq = mm->nq, npos = mm->npos;
	const double w = 2.0 * M_PI / sh->T;
	double y[NZ + ACC_N] = {0}, dy[NZ + ACC_N], g[HARMONIC_SAMPLES][NQ_FULL];
	double A[NQ_FULL][NQ_FULL], B[NQ_FULL][NQ_FULL];
	/* the samples: their times, and cos and sin of their phases */
	double ts[HARMONIC_SAMPLES], cs[HARMONIC_SAMPLES], sn[HARMONIC_SAMPLES];
	for (int k = 0; k < HARMONIC_SAMPLES; k++) {
		double th = 2.0 * M_PI * k / HARMONIC_SAMPLES;
		ts[k] = k * sh->T / HARMONIC_SAMPLES;
		cs[k] = cos(th);
		sn[k] = sin(th);
		shoot_rhs(sh, ts[k], y, dy, NULL);
		memcpy(g[k], dy + npos, sizeof(double) * (size_t)nq);
	}
	for (int c = 0; c < 2 * nq; c++) {
		/* unit changes of the order of the orbit: 1 mm, 0.1 m/s */
		double d = c < nq ? 1e-3 : 1e-1;
		memset(y, 0, sizeof y);
		y[c < nq ? c : npos + c - nq] = d;
		shoot_rhs(sh, 0.0, y, dy, NULL);
		for (int r = 0; r < nq; r++) {
			double a = (dy[npos + r] - g[0][r]) / d;
			if (c < nq)
				A[r][c] = a;
			else
				B[r][c - nq] = a;
		}
	}
	double g0[NQ_FULL] = {0}, L[2 * NQ_FULL][2 * NQ_FULL], S[NQ_FULL][NQ_FULL],
	       b[2 * NQ_FULL] = {0};
	for (int k = 0; k < HARMONIC_SAMPLES; k++)
		for (int r = 0; r < nq; r++) {
			g0[r] -= g[k][r] / HARMONIC_SAMPLES;
			b[r] -= 2.0 * cs[k] * g[k][r] / HARMONIC_SAMPLES;
			b[nq + r] -= 2.0 * sn[k] * g[k][r] / HARMONIC_SAMPLES;
		}
	for (int r = 0; r < nq; r++)
		for (int c = 0; c < nq; c++) {
			double a = A[r][c] + (r == c ? w * w : 0.0);
			S[r][c] = A[r][c];
			L[r][c] = L[nq + r][nq + c] = a;
			L[r][nq + c] = w * B[r][c];
			L[nq + r][c] = -w * B[r][c];
		}
	dynamics_dense_solve(nq, NQ_FULL, &S[0][0], g0);
	dynamics_dense_solve(2 * nq, 2 * NQ_FULL, &L[0][0], b);
	for (int r = 0; r < nq; r++)
		if (!isfinite(g0[r]) || !isfinite(b[r]) || !isfinite(b[nq + r]))
			return -1;
	/* the drive's mean torque over the orbit */
	double torque = 0.0;
	for (int k = 0; k < HARMONIC_SAMPLES; k++) {
		memset(y, 0, sizeof y);
		for (int r = 0; r < nq; r++) {
			y[r] = g0[r] + cs[k] * b[r] + sn[k] * b[nq + r];
			y[npos + r] = w * (-sn[k] * b[r] + cs[k] * b[nq + r]);
		}
		model_eval ev;
		shoot_rhs(sh, ts[k], y, dy, &ev);
		torque += ev.torque;
	}
	sh->mean_torque = torque / HARMONIC_SAMPLES;
	for (int r = 0; r < nq; r++) {
		z[r] = g0[r] + b[r];
		z[nq + r] = w * b[nq + r];
	}
	for (int r = 0; r < nq; r++) {
		int i = mm->col[r][0];
		if (i == Q_X || i == Q_Y) {
			sh->orbit[i][0] = g0[r];
			sh->orbit[i][1] = b[r];
			sh->orbit[i][2] = b[nq + r];
		}
	}
	return 0;
}

/* The signed relative rotor speed at which the Kloss motor delivers the
 * torque `need` (N m, signed like the rotation) on its stable branch, slip
 * below the breakdown slip: the small root of M_el(slip) = |need|. NaN at
 * or past the breakdown torque. */
static double motor_speed_for(const model *md, const model_ctl *ctl, double need)
{
	double s_ut = md->p.slip_ut, M_ut = md->p.M_ut, tau = (double)ctl->rotation * need;
	if (!(fabs(tau) < M_ut))
		return NAN;
	double slip = tau == 0.0 ? 0.0 : s_ut * (M_ut - sqrt(M_ut * M_ut - tau * tau)) / tau;
	return (double)ctl->rotation * (ctl->omega_ss - slip);
}

/* An upper bound of the machine's fastest angular frequency (rad/s) at
 * drive speed Omega: the eliminators on their springs, the trough on the
 * suspension (both spring sets in each direction, the other masses left
 * out), its rocking, and the drive itself. */
static double fastest_mode(const sim_params *p, double Omega)
{
	double k = 2.0 * fmax(p->k_x, p->k_y), l = fmax(p->l1, p->l2);
	double w = fabs(Omega);
	w = fmax(w, sqrt(p->k_s1 / p->m1));
	w = fmax(w, sqrt(p->k_s2 / p->m2));
	w = fmax(w, sqrt(k / p->M_r));
	w = fmax(w, sqrt(k * (l * l + p->h * p->h) / p->J_r));
	return w;
}

/* The settled feed moves with its deck point: shifted by the deck point's
 * displacement from q0 to q, at the deck point's velocity. */
static void move_feed(const model *md, const double q0[NQ_FULL], const double qd0[NQ_FULL],
		      const double q[NQ_FULL], const double qd[NQ_FULL], double *y)
{
	deck_rot R0 = deck_rotation(q0), R = deck_rotation(q);
	double *xi = y + md->nq, *eta = xi + md->nf;
	double *xid = y + md->npos + md->nq, *etad = xid + md->nf;
	for (int k = 0; k < md->dk.K; k++) {
		double p0[2], v0[2], p1[2], v1[2];
		deck_point(&md->dk, md->dk.d[k], &R0, q0, qd0, p0, v0);
		deck_point(&md->dk, md->dk.d[k], &R, q, qd, p1, v1);
		for (int j = 0; j < md->L; j++) {
			int e = k * md->L + j;
			xi[e] += p1[0] - p0[0];
			eta[e] += p1[1] - p0[1];
			xid[e] = v1[0];
			etad[e] = v1[1];
		}
	}
}

void dynamics_steady_start(const model *md, model_ctl *ctl, double *y, trough_orbit *orbit)
{
	orbit->sense = 0;
	if (!ctl->drive_on)
		return;
	double q0[NQ_FULL], qd0[NQ_FULL];
	model_full_coords(md, ctl, 0.0, y, q0, qd0);
	sim_scene sc = md->sc;
	sc.feed = 0;
	sc.drive = SIM_DRIVE_IDEAL;
	sc.motor_on = 1;
	shooter sh = {.md = md};
	model_init(&sh.mm, &sh.ctl, &md->p, &sc); /* the same preload as md's */
	sh.ctl.beta_ramp = ctl->beta_ramp;
	sh.ctl.rotation = ctl->rotation;
	sh.ctl.omega_ss = ctl->omega_ss;
	double psi0 = q0[Q_PHI] - q0[Q_ALPHA];
	double Omega = (double)ctl->rotation * ctl->omega_ss;
	double z[NZ] = {0}, J[NZ][NZ];
	int nq = sh.mm.nq, have_J = 0;
	/* alpha fixed and beta held: linear, solved in the frequency domain */
	const int linear = sh.mm.alpha_fixed && sh.ctl.beta_ramp.v_end == 0.0 &&
			   sh.ctl.beta_ramp.t_end <= 0.0;
	for (int r = 0; r < nq; r++)
		z[r] = q0[sh.mm.col[r][0]]; /* the guess: the static equilibrium */
	for (int it = 0; it < OMEGA_ITER; it++) {
		sh.T = 2.0 * M_PI / fabs(Omega);
		sh.steps = (int)fmax(STEPS_MIN,
				     ceil(sh.T * fastest_mode(&md->p, Omega) / STEP_PHASE_MAX));
		ramp_hold(&sh.ctl.psi_ramp, 0.0, psi0, Omega);
		if (!linear || harmonic_orbit(&sh, z) != 0)
			shoot(&sh, z, J, &have_J);
		double next = motor_speed_for(md, ctl, sh.mean_torque);
		/* an orbit whose mean torque the motor cannot give at any
		 * speed of its stable branch is no steady state of this
		 * machine (it stays below its resonance, or stalls): the
		 * machine starts from its static equilibrium, at rest, and the
		 * settling runs it up */
		if (!md->phi_prescribed && !isfinite(next))
			return;
		if (md->phi_prescribed || fabs(next - Omega) <= OMEGA_TOL * fabs(Omega))
			break;
		Omega = next;
	}
	double yy[NZ + ACC_N] = {0}, q[NQ_FULL], qd[NQ_FULL];
	memcpy(yy, z, sizeof(double) * (size_t)nq);
	memcpy(yy + sh.mm.npos, z + nq, sizeof(double) * (size_t)nq);
	model_full_coords(&sh.mm, &sh.ctl, 0.0, yy, q, qd);
	for (int r = 0; r < md->nq; r++) {
		int i = md->col[r][0];
		y[r] = q[i];
		y[md->npos + r] = qd[i];
	}
	if (md->nf > 0)
		move_feed(md, q0, qd0, q, qd, y);
	memcpy(orbit->xya, sh.orbit, sizeof sh.orbit);
	orbit->psi0 = psi0;
	orbit->sense = Omega < 0.0 ? -1 : 1;
	for (int i = 0; i < 3; i++)
		for (int c = 0; c < 3; c++)
			if (!isfinite(orbit->xya[i][c]))
				orbit->sense = 0;
}
