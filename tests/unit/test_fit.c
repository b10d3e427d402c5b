/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_fit.c - the fitting module (fit/) against known answers: data
 * made by the model itself from known parameters plus Gaussian noise of
 * known sigma (fixed seed) must give back those parameters within two
 * standard errors, and the standard errors must match the scatter of the
 * estimates over repeated noisy fits within a factor of 1.5. Bad input is
 * refused by fit_check / fit_parse_csv with the field named, before any
 * evaluation. A cheap scene keeps it to seconds: ideal drive, one column
 * of two layers, 2-s windows, six points.
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

#define REPEATS 10

static void recovers_known_parameters(void **state)
{
	(void)state;
	fit_point pts[NPTS];
	noisy_data(pts, 20160601);
	fit_result res;
	fit_points(pts, 0.018, 0.5, &res);
	const double want[2] = {TRUE_E, TRUE_MU};
	for (int j = 0; j < 2; j++) {
		printf("  %s = %.6g +- %.3g (true %g)\n", j ? "mu" : "e", res.x[j], res.se[j], want[j]);
		assert_true(isfinite(res.se[j]) && res.se[j] > 0);
		assert_true(fabs(res.x[j] - want[j]) < 2 * res.se[j]);
		/* and the data say something: the error is not the whole range */
		assert_true(res.se[j] < 0.3 * want[j]);
	}
	assert_true(res.sigma_given);
	assert_int_equal(res.dof, NPTS - 2);
	assert_true(fabs(res.corr[1] - res.corr[2]) < 1e-12 && fabs(res.corr[0] - 1) < 1e-9);
	/* the residuals are those of the data: chi2 of order dof */
	assert_true(res.chi2 < 5 * res.dof);
	assert_true(res.evaluations > 0);
	fit_result_free(&res);
}

/* The batches take the mirror reduction: with the data in mirrored pairs
 * ((cw, beta) and (ccw, 180 deg - beta)) each pair's second point is the
 * image of its first, so half the evaluations run, and the fit is the one
 * that runs every point (mirror = false) within a tenth of its standard
 * errors. */
static void mirror_reduction_in_batches(void **state)
{
	(void)state;
	fit_point clean[NPTS], pts[2 * NPTS];
	truth(clean);
	unsigned long long seed = 20161124;
	for (int i = 0; i < NPTS; i++) {
		pts[2 * i] = clean[i];
		pts[2 * i + 1] = (fit_point){SIM_PI - clean[i].beta, SIM_CCW, -clean[i].v, SIGMA, 0};
	}
	for (int i = 0; i < 2 * NPTS; i++)
		pts[i].v += SIGMA * fit_normal(&seed);
	fit_result res[2];
	for (int mirror = 0; mirror < 2; mirror++) {
		fit_request r;
		cheap_request(&r);
		r.sc.mirror = mirror;
		r.free[0].start = 0.018;
		r.free[1].start = 0.5;
		r.points = pts;
		r.npoints = 2 * NPTS;
		char field[48], msg[FIT_MSG];
		assert_int_equal(fit_check(&r, field, sizeof field, msg, sizeof msg), SIM_OK);
		assert_int_equal(fit_run(&r, &res[mirror]), FIT_CONVERGED);
	}
	printf("  evaluations: %ld every point, %ld with the mirror reduction\n", res[0].evaluations,
	       res[1].evaluations);
	assert_true(res[1].evaluations <= res[0].evaluations * 6 / 10);
	for (int j = 0; j < 2; j++)
		assert_true(fabs(res[1].x[j] - res[0].x[j]) <= 0.1 * res[0].se[j]);
	fit_result_free(&res[0]);
	fit_result_free(&res[1]);
}

/* Repeated fits, each from the truth, each with fresh noise: the scatter of
 * the estimates against the mean standard error. */
static void standard_errors_match_scatter(void **state)
{
	(void)state;
	fit_point clean[NPTS], pts[NPTS];
	truth(clean);
	unsigned long long seed = 977;
	double sum[2] = {0}, sum2[2] = {0}, se[2] = {0};
	for (int k = 0; k < REPEATS; k++) {
		noisy(clean, pts, &seed);
		fit_result res;
		fit_points(pts, TRUE_E, TRUE_MU, &res);
		for (int j = 0; j < 2; j++) {
			sum[j] += res.x[j];
			sum2[j] += res.x[j] * res.x[j];
			se[j] += res.se[j] / REPEATS;
		}
		fit_result_free(&res);
	}
	for (int j = 0; j < 2; j++) {
		double mean = sum[j] / REPEATS;
		double sd = sqrt(fmax(sum2[j] / REPEATS - mean * mean, 0) * REPEATS / (REPEATS - 1));
		printf("  %s: scatter %.3g, mean standard error %.3g, ratio %.2f\n", j ? "mu" : "e", sd,
		       se[j], sd / se[j]);
		assert_true(sd / se[j] < 1.5 && se[j] / sd < 1.5);
	}
}

/* fit_check's verdict on r: the field it names (or "" when accepted). */
static const char *verdict(const fit_request *r)
{
	static char field[48];
	char msg[FIT_MSG];
	field[0] = '\0';
	if (fit_check(r, field, sizeof field, msg, sizeof msg) != SIM_OK)
		printf("  refused: %s: %s\n", field, msg);
	return field;
}

static void refuses_bad_input(void **state)
{
	(void)state;
	fit_point pts[3] = {{30 * RAD_PER_DEG, SIM_CW, 0.1, NAN, 0},
			    {60 * RAD_PER_DEG, SIM_CW, 0.05, NAN, 0},
			    {120 * RAD_PER_DEG, SIM_CW, -0.07, NAN, 0}};
	fit_request r;
	cheap_request(&r);
	r.points = pts;
	r.npoints = 3;
	assert_string_equal(verdict(&r), "");
	pts[1].beta = NAN;
	assert_string_equal(verdict(&r), "points[1].beta");
	pts[1].beta = 200 * RAD_PER_DEG;
	assert_string_equal(verdict(&r), "points[1].beta");
	pts[1].beta = 30 * RAD_PER_DEG; /* a duplicate of points[0] */
	assert_string_equal(verdict(&r), "points[1]");
	pts[1].beta = 60 * RAD_PER_DEG;
	pts[2].sigma = 0.01; /* sigma for some points only */
	assert_string_equal(verdict(&r), "points[2].sigma");
	pts[2].sigma = NAN;
	r.npoints = 1; /* fewer data than free parameters */
	assert_string_equal(verdict(&r), "points");
	r.npoints = 3;
	r.t_end = 0;
	assert_string_equal(verdict(&r), "t_end");
	/* names: unknown, fixed-only, not real */
	char field[48], msg[FIT_MSG];
	const char *bad[] = {"ee", "beta", "rotation", "layers", "dt", "beta_rate"};
	for (size_t i = 0; i < sizeof bad / sizeof *bad; i++) {
		int rc = fit_add_free(&r, bad[i], NAN, NAN, field, sizeof field, msg, sizeof msg,
				      NULL);
		printf("  --free %s: %s\n", bad[i], msg);
		assert_int_equal(rc, i == 0 ? SIM_EUNKNOWN : SIM_EPARAM);
		assert_non_null(strstr(msg, bad[i]));
	}
	assert_non_null(strstr((fit_add_free(&r, "ee", NAN, NAN, field, sizeof field, msg,
					     sizeof msg, NULL), msg), "did you mean 'e'"));
	assert_int_equal(r.nfree, 2);
	fit_range range;
	assert_int_equal(fit_add_free(&r, "b_s1", 10, 5, field, sizeof field, msg, sizeof msg,
				      &range), SIM_EPARAM); /* min above max: max in (10, 1e6] */
	assert_string_equal(field, "max");
	assert_true(range.has && range.min == 10 && range.max == sim_setting_find("b_s1")->max);
	assert_int_equal(fit_add_free(&r, "b_s1", -1, 5, field, sizeof field, msg, sizeof msg,
				      &range), SIM_EPARAM); /* min below the setting's range */
	assert_string_equal(field, "min");
	assert_true(range.has && range.min == 0 && range.max == sim_setting_find("b_s1")->max);
	assert_int_equal(fit_add_free(&r, "e", NAN, NAN, field, sizeof field, msg, sizeof msg,
				      &range), SIM_EPARAM); /* named twice */
	assert_false(range.has);
}

static void parses_csv(void **state)
{
	(void)state;
	fit_point *pts;
	size_t n;
	char msg[FIT_MSG];
	assert_int_equal(fit_parse_csv("v,beta,rotation,sigma\n0.1,30,cw,0.002\n-0.05, 120 ,ccw,"
				       "0.003\n",
				       &pts, &n, msg, sizeof msg, NULL),
			 SIM_OK);
	assert_int_equal(n, 2);
	assert_true(fabs(pts[1].beta - 120 * RAD_PER_DEG) < 1e-15);
	assert_int_equal(pts[1].rotation, SIM_CCW);
	assert_true(pts[0].v == 0.1 && pts[1].sigma == 0.003);
	free(pts);
	/* a missing column, a short row, a bad number, a bad rotation; numbers
	 * strtod would have read (hexadecimal, inf) are no numbers here */
	const char *bad[] = {"beta,v\n30,0.1\n",
			     "beta,rotation,v\n30,cw\n",
			     "beta,rotation,v\n30,cw,fast\n",
			     "beta,rotation,v\n30,left,0.1\n",
			     "beta,rotation,v\n30,cw,0x10\n",
			     "beta,rotation,v,sigma\n30,cw,0.1, inf \r\n"};
	const char *says[] = {"'rotation' is missing",
			      "line 2",
			      "v must be a number",
			      "rotation must be cw or ccw",
			      "CSV line 2: v must be a number, got '0x10'",
			      "CSV line 2: sigma must be a number, got 'inf'"};
	for (int i = 0; i < 6; i++) {
		fit_range range;
		assert_int_equal(fit_parse_csv(bad[i], &pts, &n, msg, sizeof msg, &range),
				 SIM_EPARAM);
		printf("  %s\n", msg);
		assert_non_null(strstr(msg, says[i]));
		assert_null(pts);
		/* the rotation's refusal has its choices, the others none */
		assert_false(range.has);
		if (i == 3)
			assert_string_equal(range.choices, "cw|ccw");
		else
			assert_null(range.choices);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(refuses_bad_input),
		cmocka_unit_test(parses_csv),
		cmocka_unit_test(recovers_known_parameters),
		cmocka_unit_test(standard_errors_match_scatter),
		cmocka_unit_test(mirror_reduction_in_batches),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
