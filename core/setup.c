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

double model_slip_rate(const sim_params *p, const sim_scene *sc)
{
	if (sc->drive != SIM_DRIVE_MOTOR)
		return 0.0;
	/* the mass matrix does not depend on the feed (it acts as a force);
	 * the largest over the rotor's angle and the guides' (beta moves
	 * the eliminators' masses: 0.15 % for czubak2016), so that one bound
	 * holds for every beta a session, sweep or experiment may take */
	sim_scene bare = *sc;
	bare.feed = 0;
	double inv_inertia = 0.0;
	for (int b = 0; b < 4; b++) {
		sim_params pb = *p;
		pb.beta = (double)b * M_PI / 4.0;
		model md;
		model_ctl ctl;
		model_init(&md, &ctl, &pb, &bare);
		int r_phi = -1;
		for (int r = 0; r < md.nq; r++)
			for (int a = 0; a < md.ncol[r]; a++)
				if (md.col[r][a] == Q_PHI)
					r_phi = r;
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

