/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * feed.h - internal: the feed of docs/MODEL.md (paper eqs. 6-9): columns of
 * zero-thickness layers of point masses on the deck, normal contact with
 * the loading/unloading switch and Coulomb (or, as an explicit option,
 * regularised) friction between neighbouring layers and with the deck.
 *
 * The feed is a function of the deck's motion: every entry point takes the
 * deck points' positions and velocities (deck.h) and returns the forces or
 * impulses on the deck; it calls no machine function. It reads the layout
 * and parameters from the const model. SI units throughout.
 */
#ifndef CONVSIM_FEED_H
#define CONVSIM_FEED_H

#include "model.h"

/* Feed part of dy (positions' rates and accelerations) for the deck motion
 * dm; F[k] receives the force (N) of column k on its deck point, and the
 * friction and contact powers (W, all columns counted) are written. */
void feed_rhs(const model *md, const double *y, const deck_motion *dm, double *dy,
	      double (*F)[2], double *fric_power, double *contact_power);

/* The force (N) of each column on its deck point alone, F[k] as feed_rhs
 * gives it (the bottom layers' contacts; nothing else is evaluated). */
void feed_deck_forces(const model *md, const double *y, const deck_motion *dm,
		      double (*F)[2]);

/* Kinetic and gravitational energy of the feed (written, J). */
void feed_energy(const model *md, const double *y, double *kinetic, double *potential);

/* Elastic energy (J) held in the contacts now (in the current loading mode). */
double feed_contact_energy(const model *md, const double *y, const deck_motion *dm);

/* Place the feed settled at rest on the deck points dm->pos. */
void feed_settle(const model *md, double *y, const deck_motion *dm);

/* Scale every closed contact's compression (delta > 0, the deck's
 * included, deck points dm->pos) by factor, moving each layer with the
 * contacts below it; open gaps are kept as they are, and horizontal
 * positions and all velocities untouched. With factor (m_new /
 * m_old)^(1/p) a column settled under elements of mass m_old is settled
 * under m_new (sim_set_feed, docs/MODEL.md "Disturbances"). */
void feed_scale_contacts(const model *md, double *y, const deck_motion *dm, double factor);

/* Mean horizontal position (m) of column k's elements (all columns: k = -1). */
double feed_mean_xi(const model *md, const double *y, int k);
/* Mean horizontal velocity (m/s) of all elements; 0 without feed. */
double feed_mean_xi_rate(const model *md, const double *y);

/* How the deck yields to the feed within a machine step (dem's coupling),
 * as the machine's inverse mass matrix seen at the deck points, in
 * factored form: column j's impulse E_j on the deck is the generalized
 * impulse J_j^T E_j on (x, y, alpha) (J_j = [[1, 0, -Rd_y], [0, 1, Rd_x]],
 * Rd[j] the deck point's arm from G), and column k's deck velocity moves
 * by T[k] (2 x 3, 1/kg, all the physical columns an integrated column
 * stands for counted) times the sum of those. nb = 2 where alpha is fixed
 * (the third row and column then unused), 3 where the trough turns. F[j]
 * (N) is the reaction of column j that the machine's step already holds.
 * With K columns a sub-step costs O(K), where the K x K matrix of the
 * pairs' compliances T_k J_j^T cost O(K^2). */
typedef struct feed_yield {
	int nb;
	double T[SIM_MAX_COLUMNS][2][3];
	double Rd[SIM_MAX_COLUMNS][2];
	double F[SIM_MAX_COLUMNS][2];
} feed_yield;

/* The deck points' compliance from the reduced accelerations qr[c] that
 * unit generalized forces on x, y (and alpha, nb = 3) give the machine
 * (model_force_response), the deck turned by R. */
void feed_yield_compliance(const model *md, int nb, const double (*qr)[NQ_FULL], const deck_rot *R,
			   feed_yield *yl);
/* The change of each of the K columns' deck velocities, dv[k], that the
 * columns' impulses E[j] on the deck give it. */
void feed_yield_velocity(const feed_yield *yl, int K, const double (*E)[2], double (*dv)[2]);

/* The work a feed step of dem does (J; the integrated columns, each
 * counted once): the friction and the normal contacts' on the relative
 * motion, the deck's on the bottom layers, each impulse's at the
 * velocities the sub-step gives it (feed.c, column_substep). The feed's
 * kinetic and gravitational energy changes by deck - friction - contact
 * to round-off, but for gravity's m g h (v1 - v0) / 2 per layer and
 * sub-step (the leapfrog's positions advance with the new velocity v1),
 * which sums to a bounded term, not a drift. */
typedef struct feed_work {
	double friction, contact, deck;
} feed_work;

/* The feed's part of one macro step of the split method "dem": ns
 * sub-steps of length h of every column, each semi-implicit and staggered
 * as leapfrog: impulse bounds from the compressions at its start, then the
 * normal and friction impulses of the whole column solved for the
 * velocities over the sub-step (those of its middle), with which the
 * positions advance. At zero relative velocity the laws are set-valued
 * (normal impulse in [R^2 k delta^p h, k delta^p h], friction in [-mu, mu]
 * times it), so resting and sticking layers rest and stick exactly instead
 * of chattering. The column's impulses are solved exactly (an active-set
 * solve over bonded clusters of layers, warm-started from modes[2 nf]:
 * normal then tangential contact modes). With events, a slipping contact
 * that stops or reverses inside a sub-step is located there (feed.c,
 * friction_events) instead of taking its end's friction over the whole
 * sub-step. The deck moves as prescribed (borrowed; column k's rows start
 * at k ns and k (ns + 1)): deck_pos[i] at sub-step i's start,
 * deck_vel[i + 1] at its middle and deck_vel[0] at the middle of the
 * sub-step before the first; with yield (else NULL) it also yields to the
 * feed's impulses as they come, the columns then stepped side by side.
 * Writes each column's impulse on the deck into impulse[k] and adds the
 * step's work to *work. */
void feed_dem_step(const model *md, double *y, int ns, double h, const double (*deck_pos)[2],
		   const double (*deck_vel)[2], int events, const feed_yield *yield,
		   signed char *modes, double (*impulse)[2], feed_work *work);

#endif
