/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_fit_band.c - the 95 % band of a fitted curve (delta method from
 * the parameters' covariance) against what it claims: over 20 fits of
 * fresh noise on data the model made at known parameters, the true curve
 * lies inside the band at >= 90 % of the beta grid; and the band agrees
 * with the one from sampling the covariance (fit_band_sampled). The cheap
 * scene of fit_fixture.h and a 15-deg grid keep it to some 20 s.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "fit_fixture.h"

#define FITS 20
#define GRID_STEP 15.0 /* deg */
#define NGRID 13       /* 0..180 deg */

static void fit_with_curve(fit_point *pts, fit_request *r, fit_result *res)
{
	cheap_request(r);
	r->free[0].start = TRUE_E;
	r->free[1].start = TRUE_MU;
	r->points = pts;
	r->npoints = NPTS;
	r->curve_step = GRID_STEP * RAD_PER_DEG;
	char field[48], msg[FIT_MSG];
	assert_int_equal(fit_check(r, field, sizeof field, msg, sizeof msg), SIM_OK);
	assert_int_equal(fit_run(r, res), FIT_CONVERGED);
	assert_int_equal(res->ncurve, NGRID);
	assert_int_equal(res->nrot, 1);
}

static void true_curve_inside_the_band(void **state)
{
	(void)state;
	fit_point clean[NPTS], pts[NPTS];
	truth(clean);
	double v_true[NGRID];
	for (int k = 0; k < NGRID; k++)
		v_true[k] = cheap_v(TRUE_E, TRUE_MU, k * GRID_STEP * RAD_PER_DEG, SIM_CW);
	unsigned long long seed = 31;
	int inside = 0, total = 0;
	double width = 0;
	for (int f = 0; f < FITS; f++) {
		noisy(clean, pts, &seed);
		fit_request r;
		fit_result res;
		fit_with_curve(pts, &r, &res);
		assert_true(fabs(res.band_quantile - 1.959964) < 1e-5); /* sigma given */
		for (int k = 0; k < NGRID; k++) {
			assert_true(res.band_lo[k] < res.curve_fit[k] && res.curve_fit[k] < res.band_hi[k]);
			inside += res.band_lo[k] <= v_true[k] && v_true[k] <= res.band_hi[k];
			width += (res.band_hi[k] - res.band_lo[k]) / (FITS * NGRID);
			total++;
		}
		fit_result_free(&res);
	}
	printf("  the true curve inside the 95 %% band at %d of %d grid points (%.1f %%); mean "
	       "width %.4f m/s\n", inside, total, 100.0 * inside / total, width);
	assert_true(inside >= 0.9 * total);
	/* and the band says something: narrower than the noise's 4 sigma */
	assert_true(width < 4 * SIGMA);
}

/* The delta band's part from the covariance (without the curve's own
 * error bar u, which sampling does not see: the samples' jitter is well
 * below u) and the sampled band: widths within 25 % where that part is
 * ten times the measure's jitter between nearby parameters (1e-4 m/s). */
static void band_agrees_with_sampling(void **state)
{
	(void)state;
	fit_point pts[NPTS];
	noisy_data(pts, 4242);
	fit_request r;
	fit_result res;
	fit_with_curve(pts, &r, &res);
	double lo[NGRID], hi[NGRID];
	assert_int_equal(fit_band_sampled(&r, &res, 200, 7, lo, hi), 0);
	int compared = 0;
	for (int k = 0; k < NGRID; k++) {
		double q = res.band_quantile, whole = 0.5 * (res.band_hi[k] - res.band_lo[k]);
		double delta = 2 * sqrt(fmax(whole * whole - pow(q * res.curve_fit_u[k], 2), 0));
		double sampled = hi[k] - lo[k];
		printf("  beta %3.0f deg: v %.4f, delta band %.5f, sampled %.5f (ratio %.2f)\n",
		       k * GRID_STEP, res.curve_fit[k], delta, sampled, sampled / delta);
		if (delta < 1e-3)
			continue;
		compared++;
		assert_true(sampled / delta > 0.75 && sampled / delta < 1.25);
		/* centred alike: the sampled band's middle within a quarter width */
		assert_true(fabs(0.5 * (lo[k] + hi[k]) - res.curve_fit[k]) < 0.25 * delta);
	}
	assert_true(compared >= NGRID / 2);
	fit_result_free(&res);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(true_curve_inside_the_band),
		cmocka_unit_test(band_agrees_with_sampling),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
