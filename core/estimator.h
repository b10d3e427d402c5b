/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * estimator.h - internal: the transport-velocity estimator of a sim
 * (docs/MODEL.md "Observables"). It samples the mean feed displacement at the
 * excitation period boundaries and reports the slope over whole periods.
 */
#ifndef CONVSIM_ESTIMATOR_H
#define CONVSIM_ESTIMATOR_H

#include "model.h"

enum { EST_RECORDS = 64 };
/* Most period boundaries one step can pass; a phase jump beyond it
 * restarts the estimate (estimator_step). */
enum { EST_STEP_PERIODS = 64 };

typedef struct estimator {
	/* phi - alpha, the mean feed position and the drive's input energy,
	 * with rates, after the last step */
	double psi_prev, psid_prev, X_prev, Xd_prev, E_prev;
	double start;         /* s: the estimate starts at the first boundary after */
	int pending;          /* waiting for that boundary */
	int n_bound;          /* whole periods since the first boundary */
	double tb_first, Xb_first, Eb_first, tb_last, Xb_last, Eb_last, tb_prev, Xb_prev;
	/* every stride-th boundary from the first (t, X): batch edges for the
	 * error bar; when full, every second is dropped and stride doubles */
	double rec_t[EST_RECORDS], rec_X[EST_RECORDS];
	int n_rec, stride;
	double speed_max;     /* m/s: the trough's largest speed in the window */
	struct {              /* the error bar's parts as of the latest boundary */
		double uncertainty, drift, se_drift;
	} bar;
} estimator;

/* Start over: probe the state y at t, wait for the first period boundary
 * at or after start (s). */
void estimator_init(estimator *e, const model *md, const model_ctl *ctl, double t,
		    const double *y, double start);
/* Restart the estimate at the next boundary at or after start (s). */
void estimator_restart(estimator *e, double start);
/* After a step from t0 to t1 that ended in state y, whose machine has the
 * full coordinates q, qd (model_full_coords at t1): locate the period
 * boundaries within the step. */
void estimator_step(estimator *e, const model *md, double t0, double t1, const double *y,
		    const double q[NQ_FULL], const double qd[NQ_FULL]);

/* The estimate (NaN before one whole period; see sim_status).
 * uncertainty: the batch velocities (between records) fitted by a straight
 * line over time; the standard error of their mean and half the drift (the
 * line's change over the window), added in quadrature; NaN with fewer than
 * 4 batches. steady: at least 8 periods and 4 batches, a drift within 3
 * of its standard errors (no trend the scatter cannot explain) or below
 * 0.5 % of |v|, and an error bar (scatter and drift) within 1 % of |v| plus
 * 0.5 % of the trough's vibration speed (its largest over the window), the
 * scale of v where v itself is near zero. rotor_speed_mean: 2 pi n over the window's time (signed like
 * phi'); power_mean: the drive's input over it; torque_mean: their ratio
 * (the torque averaged over the angle turned). */
typedef struct estimate {
	double transport_velocity, transport_periods, feed_velocity, period;
	double uncertainty;
	int steady;
	double rotor_speed_mean, torque_mean, power_mean;
} estimate;
void estimator_read(const estimator *e, estimate *out);

/* The estimate's bar (the standard error of the batches' mean and half the
 * drift, in quadrature) with that standard error taken as the largest of
 * the batches' own and that of the batches merged 2 and 4 at a time, where
 * at least min_blocks merged ones remain: against a motion correlated
 * beyond a batch (a blocked standard error). */
double estimator_blocked_bar(const estimator *e, int min_blocks);

#endif
