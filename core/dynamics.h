/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dynamics.h - internal: the whole system, machine plus feed, as the
 * integrators and the observables see it. The layer above model.c (the
 * machine) and feed.c (the feed as a function of the deck's motion): it
 * computes the deck's motion from the machine state, the feed's reaction
 * on the deck, and hands that to the machine as a generalized force. Also
 * the stored energy and the initial static equilibrium. SI units.
 *
 * Counting: dyn_rhs and dyn_machine_rhs, the integrators' entry points,
 * count right-hand-side evaluations in the dyn they are given; the
 * dynamics_* functions (used for observation and set-up) count nothing.
 */
#ifndef CONVSIM_DYNAMICS_H
#define CONVSIM_DYNAMICS_H

#include <stdint.h>

#include "model.h"

/* What an integrator steps: the const model, the controls (read only
 * during a step) and the evaluation counter, the one thing a step changes
 * besides the state. */
typedef struct dyn {
	const model *md;
	const model_ctl *ctl;
	uint64_t rhs_evals;
} dyn;

/* dy = f(t, y) for machine and feed (length md->n; the feed's friction and
 * contact powers included). ev may be NULL. Never allocates. */
void dynamics_eval(const model *md, const model_ctl *ctl, double t, const double *y, double *dy,
		   model_eval *ev);

/* What dynamics_eval shows in ev, for observation: the feed's reaction
 * from its bottom contacts alone (the same to the last bit), the feed's
 * part of dy and the ACC_FRIC and ACC_CONTACT powers not written. */
void dynamics_observe(const model *md, const model_ctl *ctl, double t, const double *y,
		      double *dy, model_eval *ev);

/* The feed's part of dy (written) and its reaction on the machine, added
 * to Qfeed (nothing under one-way coupling); no feed: nothing. */
void dynamics_feed_reaction(const model *md, const model_ctl *ctl, double t, const double *y,
			    double *dy, double Qfeed[NQ_FULL]);

/* dynamics_eval without ev, counted. */
static inline void dyn_rhs(dyn *d, double t, const double *y, double *dy)
{
	d->rhs_evals++;
	dynamics_eval(d->md, d->ctl, t, y, dy, NULL);
}

/* model_machine_rhs, counted (split methods). */
static inline void dyn_machine_rhs(dyn *d, double t, const double *y, const double Qfeed[NQ_FULL],
				   double *dy, model_eval *ev)
{
	d->rhs_evals++;
	model_machine_rhs(d->md, d->ctl, t, y, Qfeed, dy, ev);
}

/* Stored energy (J) of machine and feed: kinetic and potential written,
 * their sum returned. Contact work and the other accumulators are in y. */
double dynamics_energy_stored(const model *md, const model_ctl *ctl, double t, const double *y,
			      double *kinetic, double *potential);

/* Elastic energy (J) in the feed's contacts for the machine state q, qd. */
double dynamics_contact_energy(const model *md, const double *y, const double q[NQ_FULL],
			       const double qd[NQ_FULL]);

/* Add to Qfeed the generalized force of the feed's weight resting on the
 * deck points for the machine configuration q (nothing without a feed or
 * under one-way coupling). */
void dynamics_feed_weight(const model *md, const double q[NQ_FULL], double Qfeed[NQ_FULL]);

/* Solve A x = b (A: n x n, row stride lda, overwritten) by Gaussian
 * elimination with partial pivoting; x into b. */
void dynamics_dense_solve(int n, int lda, double *A, double *b);

/* The `steady` start (steady.c): replace the machine part of the
 * equilibrium state y by the periodic forced response at the loaded motor
 * speed (frequency domain or shooting), move the settled feed with its
 * deck points, and write the response's trough orbit into *orbit (sense 0
 * where there is none). The motor off: y is kept, no orbit. */
void dynamics_steady_start(const model *md, model_ctl *ctl, double *y, trough_orbit *orbit);

/* Fill y (length md->n) with the static equilibrium with the feed settled;
 * the ideal drive's psi ramp is re-anchored to it. */
void dynamics_equilibrium(const model *md, model_ctl *ctl, double *y);

#endif
