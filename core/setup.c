/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * setup.c - builds the cheapest model a scene needs (docs/MODEL.md "Model only
 * what a scene needs"): the reduced layout, the deck geometry, the
 * suspension preload, and the initial controls. (The initial state, the
 * static equilibrium with the feed settled, is dynamics_equilibrium.)
 *
 * Reductions:
 *   no feed            -> no feed coordinates;
 *   ideal drive        -> phi = alpha + psi(t) prescribed (constant speed);
 *   symmetric machine and no trough rotation asked for -> alpha = 0 and one
 *                         representative column standing for K;
 *   one-way coupling   -> the feed does not act on the trough.
 */
#include <math.h>
#include <stddef.h>
#include <string.h>

#include "model.h"

int model_machine_symmetric(const sim_params *p)
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

/* The machine alone (no feed) of p and sc with its guides at the b-th of
 * BOUND_BETAS angles, 0 to 135 deg: the step bounds take the largest rate
 * over them, so that one bound holds for every beta a session, sweep or
 * experiment may take. */
#define BOUND_BETAS 4
static void bare_machine(const sim_params *p, const sim_scene *sc, int b, model *md,
			 model_ctl *ctl)
{
	sim_scene bare = *sc;
	bare.feed = 0;
	sim_params pb = *p;
	pb.beta = (double)b * M_PI / BOUND_BETAS;
	model_init(md, ctl, &pb, &bare);
}

/* The row of md's coordinates that carries the rotor's angle; -1: none
 * (the ideal drive prescribes it). */
static int rotor_row(const model *md)
{
	int r_phi = -1;
	for (int r = 0; r < md->nq; r++)
		for (int a = 0; a < md->ncol[r]; a++)
			if (md->col[r][a] == Q_PHI)
				r_phi = r;
	return r_phi;
}

double model_slip_rate(const sim_params *p, const sim_scene *sc)
{
	if (sc->drive != SIM_DRIVE_MOTOR)
		return 0.0;
	/* the mass matrix does not depend on the feed (it acts as a force);
	 * the largest over the rotor's angle and the guides' (beta moves
	 * the eliminators' masses: 0.15 % for czubak2016), so that one bound
	 * holds for every beta a session, sweep or experiment may take */
	double inv_inertia = 0.0;
	for (int b = 0; b < BOUND_BETAS; b++) {
		model md;
		model_ctl ctl;
		bare_machine(p, sc, b, &md, &ctl);
		int r_phi = rotor_row(&md);
		if (r_phi < 0)
			return 0.0;
		for (int i = 0; i < 8; i++) {
			double y[2 * NQ_FULL + ACC_N] = {0}, Q[NQ_FULL] = {0}, qrdd[NQ_FULL] = {0},
			       qdd[NQ_FULL] = {0};
			y[r_phi] = (double)i * M_PI / 4.0;
			Q[Q_PHI] = 1.0;
			Q[Q_ALPHA] = -1.0;
			model_force_response(&md, &ctl, 0.0, y, Q, qrdd);
			model_add_reduced(&md, qrdd, qdd);
			inv_inertia = fmax(inv_inertia, qdd[Q_PHI] - qdd[Q_ALPHA]);
		}
	}
	double slope = 2.0 * p->M_ut / p->slip_ut + 2.0 * p->b_phi * p->omega_ss;
	return slope * inv_inertia;
}

/* The spectral radius of the n x n matrix a (row-major; overwritten):
 * |a^(2^k)|^(1/2^k) by repeated squaring, each square scaled to norm 1,
 * so that a defective or complex dominant pair converges as well as a
 * real one (to the power 2^-k of the eigenvectors' conditioning). */
#define RADIUS_SQUARINGS 14
static double spectral_radius(double *a, int n)
{
	double b[4 * NQ_FULL * NQ_FULL];
	double log_scale = 0.0; /* log |a0^(2^k)| less log of a's norm now */
	for (int k = 0; k <= RADIUS_SQUARINGS; k++) {
		double norm = 0.0;
		for (int i = 0; i < n * n; i++)
			norm += a[i] * a[i];
		norm = sqrt(norm);
		if (!(norm > 0.0) || !isfinite(norm))
			return norm > 0.0 ? INFINITY : 0.0;
		for (int i = 0; i < n * n; i++)
			a[i] /= norm;
		log_scale += log(norm) / ldexp(1.0, k);
		if (k == RADIUS_SQUARINGS)
			break;
		for (int i = 0; i < n; i++) {
			double *row = b + i * n;
			for (int j = 0; j < n; j++)
				row[j] = 0.0;
			for (int l = 0; l < n; l++) {
				double ail = a[i * n + l];
				for (int j = 0; j < n; j++)
					row[j] += ail * a[l * n + j];
			}
		}
		memcpy(a, b, sizeof(double) * (size_t)(n * n));
	}
	return exp(log_scale);
}

/* The rotor's angles machine_rate linearizes at, over half a turn (the
 * mass matrix's dependence on it, through the unbalance's sine and
 * cosine, repeats every half turn): where the rotor's inertia is mostly
 * the unbalance's (J_w << m e^2), a trough moving across the unbalance's
 * arm carries little of its mass, and a light trough's damper is that
 * much faster: a 1-kg trough with the preset's 10-kg unbalance, b_x 1e6
 * N s/m, moves 1.2 kg at 90 deg and 11 kg at 0 (tests/unit/
 * test_hard_machine.c). */
#define RATE_ROTOR_ANGLES 8

static double machine_rate(const sim_params *p, const sim_scene *sc)
{
	double rate = 0.0;
	for (int b = 0; b < BOUND_BETAS; b++) {
		model md;
		model_ctl ctl;
		/* the load torque apart: its slope at standstill is the
		 * motor's slip slope, model_slip_rate's */
		sim_params unloaded = *p;
		unloaded.M_load = 0.0;
		bare_machine(&unloaded, sc, b, &md, &ctl);
		/* the motor off (its slip mode is model_slip_rate's), the
		 * settling's damper on in full (it only adds damping) */
		ctl.drive_on = 0;
		ctl.settle_b = 1.0;
		ctl.settle_t0 = -1.0;
		md.settle_orbit.sense = 0;
		int r_phi = rotor_row(&md);
		for (int a = 0; a < (r_phi < 0 ? 1 : RATE_ROTOR_ANGLES); a++) {
			/* forward differences: the machine is linear about rest
			 * but for its geometry's rotation, an error of h
			 * relative */
			const double t = -2.0, h = 1e-6;
			int n = 2 * md.nq;
			double jac[4 * NQ_FULL * NQ_FULL], y[2 * NQ_FULL + ACC_N] = {0},
			       f0[2 * NQ_FULL + ACC_N], f[2 * NQ_FULL + ACC_N];
			if (r_phi >= 0)
				y[r_phi] = (double)a * M_PI / RATE_ROTOR_ANGLES;
			model_machine_rhs(&md, &ctl, t, y, NULL, f0, NULL);
			for (int j = 0; j < n; j++) {
				double y0 = y[j];
				y[j] = y0 + h;
				model_machine_rhs(&md, &ctl, t, y, NULL, f, NULL);
				y[j] = y0;
				for (int i = 0; i < n; i++)
					jac[i * n + j] = (f[i] - f0[i]) / h;
			}
			rate = fmax(rate, spectral_radius(jac, n));
		}
	}
	return rate;
}

/* What model_machine_rate reads: the parameters but beta (its own four)
 * and its ramps', with rotation's padding zeroed, and the scene's drive,
 * reduction and motor. */
typedef struct machine_rate_key {
	sim_params p;
	int drive, trough_rotation, motor_on;
} machine_rate_key;

static void machine_rate_key_of(const sim_params *p, const sim_scene *sc, machine_rate_key *k)
{
	memset(k, 0, sizeof *k);
	size_t a = offsetof(sim_params, rotation) + sizeof p->rotation, b = offsetof(sim_params, m1);
	memcpy(&k->p, p, a);
	memcpy((char *)&k->p + b, (const char *)p + b, sizeof *p - b);
	k->p.beta = k->p.beta_rate = k->p.beta_accel = 0.0;
	k->drive = sc->drive;
	k->trough_rotation = sc->trough_rotation;
	k->motor_on = sc->motor_on;
}

/* The machines whose rate a thread keeps (a few: a daemon's thread that
 * restores sessions, or checks requests, meets several in turn). */
#define RATE_MEMO 4

double model_machine_rate(const sim_params *p, const sim_scene *sc)
{
	/* a run asks several times and a sweep at every point for the same
	 * machine: the last RATE_MEMO answers are kept, per thread */
	static _Thread_local struct {
		int valid;
		machine_rate_key key;
		double rate;
	} memo[RATE_MEMO];
	static _Thread_local unsigned next;
	machine_rate_key key;
	machine_rate_key_of(p, sc, &key);
	for (int i = 0; i < RATE_MEMO; i++)
		if (memo[i].valid && memcmp(&key, &memo[i].key, sizeof key) == 0)
			return memo[i].rate;
	unsigned i = next++ % RATE_MEMO;
	memo[i].rate = machine_rate(p, sc);
	memcpy(&memo[i].key, &key, sizeof key);
	memo[i].valid = 1;
	return memo[i].rate;
}

double model_column_sag(const sim_params *p, const sim_scene *sc)
{
	if (!(sc->feed && sc->columns > 0 && sc->layers > 0))
		return 0.0;
	double sag = 0.0;
	for (int i = 1; i <= sc->layers; i++)
		sag += pow((double)i * p->m_n * p->g / p->k_c, 1.0 / p->p);
	return sag;
}

void model_static_strokes(const sim_params *p, double s[2])
{
	double cb = cos(p->beta);
	s[0] = -p->m1 * p->g * cb / p->k_s1;
	s[1] = -p->m2 * p->g * cb / p->k_s2;
}

/* The suspension's preload: the empty machine at rest with x = y = alpha
 * = 0 is in equilibrium with the eliminators at their static stroke and
 * the unbalanced mass hanging down. */
static void preload(const sim_params *p, double F0[2])
{
	double s[2];
	model_static_strokes(p, s);
	double sb = sin(p->beta), s1 = s[0], s2 = s[1];
	double W = (p->M_r + p->m + p->m1 + p->m2) * p->g;
	double moment = p->g * (p->m * p->w_x + p->m1 * (p->p1_x - (p->c + s1) * sb) +
				p->m2 * (p->p2_x - (p->c + s2) * sb));
	/* F0_1 + F0_2 = W, l1 F0_1 - l2 F0_2 = moment */
	F0[0] = (moment + p->l2 * W) / (p->l1 + p->l2);
	F0[1] = W - F0[0];
}

/* The reduced coordinates of md (T, nq, col, ncol): the symmetric machine
 * drops alpha, the ideal drive phi. */
static void reduce_coordinates(model *md, int sym, int ideal)
{
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
}

/* The feed's columns on the deck (one representative column of weight
 * columns on the symmetric machine) and its coordinates' count. */
static void place_columns(model *md, const sim_params *p, const sim_scene *sc, int sym)
{
	deck *dk = &md->dk;
	md->L = sc->layers;
	if (sym) {
		dk->K = 1;
		md->col_weight = (double)sc->columns;
		dk->d[0] = 0.0;
	} else {
		dk->K = sc->columns;
		md->col_weight = 1.0;
		for (int k = 0; k < dk->K; k++)
			dk->d[k] = dk->K == 1 ? 0.0
					      : p->column_span *
						    (-1.0 + 2.0 * (double)k / (double)(dk->K - 1));
	}
	md->nf = dk->K * md->L;
}

void model_init(model *md, model_ctl *ctl, const sim_params *p, const sim_scene *sc)
{
	memset(md, 0, sizeof *md);
	memset(ctl, 0, sizeof *ctl);
	md->p = *p;
	md->sc = *sc;
	ctl->rotation = p->rotation;
	ctl->omega_ss = p->omega_ss;
	ctl->drive_on = sc->motor_on;
	ctl->beta_rate = p->beta_rate;

	int feed = sc->feed && sc->columns > 0 && sc->layers > 0 && sc->feed_model == SIM_FEED_COLUMN;
	/* an external feed: no feed coordinates; its weight on the deck until
	 * the caller sets its load (sim_set_deck_load) */
	if (sc->feed && sc->feed_model == SIM_FEED_EXTERNAL && sc->feed_coupling)
		ctl->deck_load[1] = -(double)sc->columns * (double)sc->layers * p->m_n * p->g;
	int sym = !sc->trough_rotation && model_machine_symmetric(p);
	int ideal = sc->drive == SIM_DRIVE_IDEAL;
	if (!feed)
		md->reductions |= SIM_RED_NO_FEED;
	if (sym)
		md->reductions |= SIM_RED_SYMMETRIC;
	if (ideal)
		md->reductions |= SIM_RED_IDEAL_DRIVE;
	if (feed && !sc->feed_coupling)
		md->reductions |= SIM_RED_ONE_WAY;

	reduce_coordinates(md, sym, ideal);
	md->alpha_fixed = sym;
	md->phi_prescribed = ideal;
	model_solve_layout(md);

	md->dk.h_d = p->h_d;
	if (feed)
		place_columns(md, p, sc, sym);
	md->npos = md->nq + 2 * md->nf;
	md->n = 2 * md->npos + ACC_N;

	preload(p, md->F0);
	/* the settling's damping: critical for the trough's translation on
	 * its two spring sets, sqrt(2 k M) a set (4,990 N s/m in czubak2016) */
	double M = p->M_r + p->m + p->m1 + p->m2;
	md->settle_damping[0] = sqrt(2.0 * p->k_x * M);
	md->settle_damping[1] = sqrt(2.0 * p->k_y * M);

	ramp_hold(&ctl->beta_ramp, 0.0, p->beta, 0.0);
	double speed = ideal && sc->motor_on ? (double)p->rotation * p->omega_ss : 0.0;
	ramp_hold(&ctl->psi_ramp, 0.0, -M_PI / 2.0, speed);
}

