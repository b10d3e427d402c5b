/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim_check.h - the divergence guards of a simulation instance: a machine
 * or a feed that runs away (bounded displacements, rotation, strokes,
 * rotor speed, the feed's layers) ends the run with SIM_EDIVERGED and the
 * cause. Static functions included by sim.c only, where they were, so
 * that its stepping compiles exactly as before.
 */
#ifndef CONVSIM_SIM_CHECK_H
#define CONVSIM_SIM_CHECK_H

#include <math.h>
#include <stdio.h>

#include "feed.h"
#include "sim_int.h"

/* Divergence guard, machine: bounded displacements, rotation, strokes and
 * rotor speed; NULL or the cause. */
static const char *machine_runaway(const model *md, const double q[NQ_FULL],
				   const double qd[NQ_FULL])
{
	if (fabs(q[Q_X]) > 1.0 || fabs(q[Q_Y]) > 1.0)
		return "trough displacement beyond 1 m";
	if (fabs(q[Q_ALPHA]) > 0.5)
		return "trough rotation beyond 0.5 rad";
	if (fabs(q[Q_S1]) > MODEL_STROKE_MAX || fabs(q[Q_S2]) > MODEL_STROKE_MAX)
		return "eliminator stroke beyond 1 m";
	if (fabs(qd[Q_PHI] - qd[Q_ALPHA]) > 100.0 * md->p.omega_ss + 1e3)
		return "rotor speed beyond 100 omega_ss";
	return NULL;
}

/* Divergence guard, feed: no element sunk into or thrown far from its
 * deck point; NULL or the cause. */
static const char *feed_runaway(const model *md, const double *y, const double q[NQ_FULL],
				const double qd[NQ_FULL])
{
	const double *eta = y + md->nq + md->nf;
	deck_rot R = deck_rotation(q);
	for (int k = 0; k < md->dk.K; k++) {
		double pos[2], vel[2];
		deck_point(&md->dk, md->dk.d[k], &R, q, qd, pos, vel);
		/* the column's lowest and highest element first (a loop without
		 * branches); the elements in order only when one is out */
		const double *col = eta + k * md->L;
		double lo = col[0], hi = col[0];
		for (int j = 1; j < md->L; j++) {
			lo = col[j] < lo ? col[j] : lo;
			hi = col[j] > hi ? col[j] : hi;
		}
		if (!(lo - pos[1] < -MODEL_SAG_MAX || hi - pos[1] > 100.0))
			continue;
		for (int j = 0; j < md->L; j++) {
			double rel = eta[k * md->L + j] - pos[1];
			if (rel < -MODEL_SAG_MAX)
				return "feed element sank 5 cm into the deck (contacts too "
				       "soft for the column's weight, or the step too long "
				       "for them)";
			if (rel > 100.0)
				return "feed element thrown beyond 100 m";
		}
	}
	return NULL;
}

/* Divergence guard: finite state, bounded machine motion and feed; q, qd
 * receive the machine's full coordinates at s->t_int (for the caller's
 * other observers). */
static int check_state(sim *s, double q[NQ_FULL], double qd[NQ_FULL])
{
	const model *md = &s->md;
	/* y - y is 0 for a finite entry and NaN for any other: a sum (four
	 * partial ones, a loop without branches or a serial chain), and the
	 * entries in order only when it is not 0 */
	double part[4] = {0.0, 0.0, 0.0, 0.0};
	int i4 = md->n - md->n % 4;
	for (int i = 0; i < i4; i += 4)
		for (int l = 0; l < 4; l++)
			part[l] += s->y[i + l] - s->y[i + l];
	for (int i = i4; i < md->n; i++)
		part[0] += s->y[i] - s->y[i];
	double nonfinite = (part[0] + part[1]) + (part[2] + part[3]);
	for (int i = 0; nonfinite != 0.0 && i < md->n; i++) {
		if (!isfinite(s->y[i])) {
			snprintf(s->error, sizeof s->error,
				 "diverged at t = %.9g s: non-finite state (component %d); "
				 "try a smaller step",
				 s->t_int, i);
			return SIM_EDIVERGED;
		}
	}
	model_full_coords(md, &s->ctl, s->t_int, s->y, q, qd);
	const char *cause = machine_runaway(md, q, qd);
	if (!cause && md->nf > 0)
		cause = feed_runaway(md, s->y, q, qd);
	if (cause) {
		snprintf(s->error, sizeof s->error, "diverged at t = %.9g s: %s", s->t_int, cause);
		return SIM_EDIVERGED;
	}
	return SIM_OK;
}

#endif
