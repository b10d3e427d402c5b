/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * shadow.c - the measured step error of dem's transport velocity: a second
 * instance with fewer feed sub-steps, stepped beside an instance (sim.c
 * steps both) over the first part of each estimate's window.
 *
 * dem's transport velocity is first order in the feed step h once the
 * step resolves the contact (docs/machine-zoo.md): v(h) = v* + C h. A
 * second instance with fewer feed sub-steps (the same machine steps, so
 * the same time grid, and the same controls), restored from this one's
 * checkpoint where an estimate starts, is stepped beside it over the
 * first shadow_window seconds of the estimate; then the two estimates
 * over the same whole periods give Richardson's estimate of this run's
 * feed-step error, |v(r h) - v(h)| / (r - 1) (exact for a first-order
 * error, an overestimate for a higher order), and the shadow is freed. A
 * shadow that fails (the coarser step too coarse for the contact) makes
 * the error infinite. The shadow takes ceil(n / 2) sub-steps, so r = n /
 * ceil(n / 2) (5/3 for the preset's 5): halving them would put the
 * preset's shadow at a seventh of the contact period, outside dem's
 * first-order regime, where ceil(n / 2) keeps it within a tenth. The
 * machine step cannot be lengthened alike (the motor's slip mode bounds
 * it; a shadow at 0.9 of that bound gave estimates both far over and far
 * under the error on czubak2016), so its error is an a-priori term
 * (sim_status.c). The shadow needs n >= 3 (dem's corrector needs 2
 * sub-steps on each side) and feed events: without them (the former dem)
 * the first-order error of the deck that ignores the feed's reaction
 * within the step is the machine step's, which the shadow keeps (the
 * 74-point curve put 14 points outside such bars). With fewer sub-steps,
 * without events, without feed or with another method there is none and
 * the error bar keeps the preset's calibrated step term. The shadow
 * costs about 0.8 of this instance while it runs: 40 periods after each
 * estimate's start (a control, a restart), and SHADOW_MEASURE_SHARE of a
 * measurement's window (sim_measure). It is not checkpointed: a restored
 * instance keeps the calibrated term until its next estimate starts.
 * The difference's standard error (step_se) comes from the two
 * estimates' paired batch velocities; where a measurement asks it
 * (step_bounded: a chaotic feed's long run, measure.c) a difference
 * within SHADOW_SIGNIFICANT of it is scatter, and the step error is
 * bounded by that standard error instead. */

#include <math.h>
#include <stdlib.h>

#include "sim_int.h"

/* Fewer whole periods than this in the shadow's window (a measurement of
 * a fraction of a second) leave the step error as it was: a difference
 * over a few periods is the feed's scatter more than the step's error. */
#define SHADOW_MIN_PERIODS 8

/* paired_se: at least this many paired batches, lag-1 correlation read
 * at most this (beyond it the batches say little about their mean) */
#define SHADOW_PAIRED_BATCHES 8
#define SHADOW_RHO_MAX 0.8

void shadow_stop(sim *s)
{
	sim_free(s->shadow);
	s->shadow = NULL;
}

void sim_drop_shadow(sim *s)
{
	shadow_stop(s);
}

/* Start a shadow from the present state, to run until the estimate's
 * start plus the shadow's window. */
void shadow_begin(sim *s)
{
	shadow_stop(s);
	if (!s->ode->info.shadow || !s->cfg.feed_events || s->md.nf == 0 ||
	    s->cfg.substeps < SIM_SHADOW_SUBSTEPS ||
	    s->failed)
		return;
	sim_method m = s->cfg;
	m.substeps = (s->cfg.substeps + 1) / 2;
	size_t len = sim_checkpoint_size(s);
	void *buf = malloc(len);
	if (!buf)
		return;
	if (sim_checkpoint(s, buf, len) == SIM_OK)
		s->shadow = sim_restore(&s->md.p, &s->md.sc, &m, buf, len, NULL, NULL, 0);
	if (s->shadow) /* stepped beside s: bounded as s is (cpu_bound.c) */
		s->shadow->cpu = s->cpu;
	free(buf);
	s->shadow_until = fmax(s->t_int, s->est.start) + s->shadow_window;
}

/* The standard error of the difference of two estimates over the same
 * periods (a and b from the same start, the same machine steps: their
 * batch edges fall at the same period boundaries), from their paired
 * batch velocity differences; NaN where the batches do not pair or are
 * too few. The batches' lag-1 correlation, where positive, widens it as
 * for an AR(1) series, (1 + rho) / (1 - rho) on the variance. */
static double paired_se(const estimator *a, const estimator *b)
{
	int n = a->n_rec < b->n_rec ? a->n_rec : b->n_rec;
	if (a->stride != b->stride || n - 1 < SHADOW_PAIRED_BATCHES)
		return NAN;
	double d[EST_RECORDS], mean = 0.0, span = 0.0;
	int nb = n - 1;
	for (int i = 0; i < nb; i++) {
		double ta = a->rec_t[i + 1] - a->rec_t[i], tb = b->rec_t[i + 1] - b->rec_t[i];
		if (!(ta > 0.0 && tb > 0.0))
			return NAN;
		d[i] = (a->rec_X[i + 1] - a->rec_X[i]) / ta - (b->rec_X[i + 1] - b->rec_X[i]) / tb;
		mean += d[i] * ta;
		span += ta;
	}
	mean /= span;
	double ss = 0.0, lag = 0.0;
	for (int i = 0; i < nb; i++) {
		ss += (d[i] - mean) * (d[i] - mean);
		if (i > 0)
			lag += (d[i] - mean) * (d[i - 1] - mean);
	}
	if (!(ss > 0.0))
		return 0.0;
	double rho = fmin(SHADOW_RHO_MAX, fmax(0.0, lag / ss));
	return sqrt(ss / (nb - 1) / nb * (1.0 + rho) / (1.0 - rho));
}

/* A running shadow's step error as shadow_finish would set it now, the
 * shadow left running: *raw the difference over (r - 1), *se its standard
 * error (paired_se; NaN where the batches do not pair). 0 where it has
 * measured nothing yet (no shadow, too few periods, failed). */
int shadow_peek(const sim *s, double *raw, double *se)
{
	if (!s->shadow || s->shadow->failed)
		return 0;
	estimate a, b;
	estimator_read(&s->est, &a);
	estimator_read(&s->shadow->est, &b);
	if (a.transport_periods < SHADOW_MIN_PERIODS || b.transport_periods < SHADOW_MIN_PERIODS)
		return 0;
	double r = (double)s->cfg.substeps / (double)s->shadow->cfg.substeps;
	*raw = fabs(b.transport_velocity - a.transport_velocity) / (r - 1.0);
	*se = paired_se(&s->est, &s->shadow->est) / (r - 1.0);
	return 1;
}

/* The shadow's estimate against this instance's, both at shadow_until. */
void shadow_finish(sim *s)
{
	estimate a, b;
	estimator_read(&s->est, &a);
	estimator_read(&s->shadow->est, &b);
	double r = (double)s->cfg.substeps / (double)s->shadow->cfg.substeps;
	s->shadow_v = NAN;
	s->step_se = NAN;
	if (s->shadow->failed) {
		s->step_error = INFINITY;
	} else if (a.transport_periods >= SHADOW_MIN_PERIODS &&
		   b.transport_periods >= SHADOW_MIN_PERIODS) {
		double d = fabs(b.transport_velocity - a.transport_velocity);
		s->step_error = d / (r - 1.0);
		s->shadow_v = a.transport_velocity;
		s->step_se = paired_se(&s->est, &s->shadow->est) / (r - 1.0);
		if (s->step_bounded && isfinite(s->step_se) &&
		    s->step_error <= SHADOW_SIGNIFICANT * s->step_se)
			s->step_error = s->step_se;
	}
	shadow_stop(s);
}

/* A refinement's shadow without a shadow: s, restored from the checkpoint
 * the coarser run v_coarse came from (feed step h_coarse, both estimates
 * from the same start), at that run's shadow_until, the coarser run as
 * its shadow (sim_measure_point's refinements, measure.c). */
void shadow_against(sim *s, double v_coarse, double h_coarse)
{
	estimate a;
	estimator_read(&s->est, &a);
	double r = h_coarse / (s->cfg.dt / s->cfg.substeps);
	if (a.transport_periods >= SHADOW_MIN_PERIODS && r > 1.0 && !s->failed) {
		s->step_error = fabs(v_coarse - a.transport_velocity) / (r - 1.0);
		s->shadow_v = a.transport_velocity;
	}
	sim_update_status(s);
}
