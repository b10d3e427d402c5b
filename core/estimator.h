/*
 * estimator.h - internal: the transport-velocity estimator of a sim
 * (MODEL.md "Observables"). It samples the mean feed displacement at the
 * excitation period boundaries and reports the slope over whole periods.
 */
#ifndef CONVSIM_ESTIMATOR_H
#define CONVSIM_ESTIMATOR_H

#include "model.h"

typedef struct estimator {
	/* phi - alpha and the mean feed position, with rates, after the last step */
	double psi_prev, psid_prev, X_prev, Xd_prev;
	double start;         /* s: the estimate starts at the first boundary after */
	int pending;          /* waiting for that boundary */
	int n_bound;          /* whole periods since the first boundary */
	double tb_first, Xb_first, tb_last, Xb_last, tb_prev, Xb_prev;
} estimator;

/* Start over: probe the state y at t, wait for the first period boundary
 * at or after start (s). */
void estimator_init(estimator *e, const model *md, const model_ctl *ctl, double t,
		    const double *y, double start);
/* Re-probe after the state was replaced at t (the boundaries so far stay). */
void estimator_probe(estimator *e, const model *md, const model_ctl *ctl, double t,
		     const double *y);
/* Restart the estimate at the next boundary at or after start (s). */
void estimator_restart(estimator *e, double start);
/* After a step from t0 to t1 that ended in state y: locate the period
 * boundaries within the step. */
void estimator_step(estimator *e, const model *md, const model_ctl *ctl, double t0, double t1,
		    const double *y);

/* The estimate (NaN before one whole period; see sim_status). */
typedef struct estimate {
	double transport_velocity, transport_periods, feed_velocity, period;
} estimate;
void estimator_read(const estimator *e, estimate *out);

#endif
