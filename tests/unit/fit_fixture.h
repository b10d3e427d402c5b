/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_fixture.h - what the fitting module's tests share: a cheap scene
 * (ideal drive, one column of two layers, 2-s windows) with e and mu free,
 * six clockwise points at beta = 15..165 deg made by the model at known
 * parameters, and fixed-seed Gaussian noise on them. Include after cmocka.h.
 */
#ifndef CONVSIM_FIT_FIXTURE_H
#define CONVSIM_FIT_FIXTURE_H

#include "fit.h"
#include "units.h"

#define NPTS 6
#define SIGMA 0.003 /* m/s: the noise added, about 3 % of the peak */
#define TRUE_E 0.0215
#define TRUE_MU 0.4

static inline void cheap_request(fit_request *r)
{
	fit_request_init(r);
	r->sc.drive = SIM_DRIVE_IDEAL;
	r->sc.columns = 1;
	r->sc.layers = 2;
	r->t_end = 2.0;
	r->curve_step = 0;
	r->threads = 2;
	char field[48], msg[FIT_MSG];
	assert_int_equal(fit_add_free(r, "e", NAN, NAN, field, sizeof field, msg, sizeof msg, NULL),
			 SIM_OK);
	assert_int_equal(fit_add_free(r, "mu", NAN, NAN, field, sizeof field, msg, sizeof msg, NULL),
			 SIM_OK);
}

/* v at (beta, rotation) of the cheap scene at e, mu. */
static inline double cheap_v(double e, double mu, double beta, int rotation)
{
	fit_request r;
	cheap_request(&r);
	sim_params p = r.p;
	p.e = e;
	p.mu = mu;
	p.beta = beta;
	p.rotation = rotation;
	sim_measurement ms;
	char msg[160];
	assert_int_equal(sim_measure(&p, &r.sc, &r.m, r.t_end, &ms, msg, sizeof msg), SIM_OK);
	return ms.transport_velocity;
}

/* v at the points with the true parameters (the noise-free data). */
static inline void truth(fit_point *pts)
{
	for (int i = 0; i < NPTS; i++) {
		double beta = (15.0 + 30.0 * i) * RAD_PER_DEG;
		pts[i] = (fit_point){beta, SIM_CW, cheap_v(TRUE_E, TRUE_MU, beta, SIM_CW), SIGMA, 0};
	}
}

static inline void noisy(const fit_point *clean, fit_point *pts, unsigned long long *seed)
{
	for (int i = 0; i < NPTS; i++) {
		pts[i] = clean[i];
		pts[i].v += SIGMA * fit_normal(seed);
	}
}

/* The true points plus one draw of noise from seed. */
static inline void noisy_data(fit_point *pts, unsigned long long seed)
{
	fit_point clean[NPTS];
	truth(clean);
	noisy(clean, pts, &seed);
}

/* A fit of the cheap scene's e and mu to NPTS points from (e0, mu0). */
static inline void fit_points(fit_point *pts, double e0, double mu0, fit_result *res)
{
	fit_request r;
	cheap_request(&r);
	r.free[0].start = e0;
	r.free[1].start = mu0;
	r.points = pts;
	r.npoints = NPTS;
	char field[48], msg[FIT_MSG];
	assert_int_equal(fit_check(&r, field, sizeof field, msg, sizeof msg), SIM_OK);
	assert_int_equal(fit_run(&r, res), FIT_CONVERGED);
}

#endif
