/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_fit_robust.c - a calibration that does not give up: a trial point
 * where the model cannot be evaluated (planted with the request's veto) is
 * a rejected step, not the end of the fit; a fit that fails reports why
 * and its best point with undetermined (not zero) standard errors; the
 * peak scan follows a peak that lies beyond it; multi-start runs from a
 * Halton design and keeps the lowest cost; a bound is reached in the
 * solver's scale. The cheap scene of
 * fit_fixture.h keeps it to seconds.
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
#include "fit_int.h"

/* The veto's plan: fail call number `at` (1-based; each parameter set the
 * fit evaluates is one call), or every call from `from` on (0: never). */
typedef struct planted {
	int calls, at, from, vetoed;
} planted;

static int veto(void *ctx, const double *x)
{
	(void)x;
	planted *pl = ctx;
	pl->calls++;
	int no = pl->calls == pl->at || (pl->from && pl->calls >= pl->from);
	pl->vetoed += no;
	return no;
}

static void planted_request(fit_request *r, fit_point *pts, planted *pl)
{
	cheap_request(r);
	r->free[0].start = 0.018;
	r->free[1].start = 0.5;
	r->points = pts;
	r->npoints = NPTS;
	r->veto = veto;
	r->ctx = pl;
}

/* The calls of a 2-parameter fit: the start (1), its Jacobian (2, 3),
 * the first trial point (4). Failing there, the fit rejects the step,
 * shrinks its trust region and goes on to the optimum of the clean run. */
static void failed_trial_point_is_a_rejected_step(void **state)
{
	(void)state;
	fit_point pts[NPTS];
	noisy_data(pts, 20160601);
	fit_result clean, res;
	planted none = {0}, one = {.at = 4};
	fit_request r;
	planted_request(&r, pts, &none);
	assert_int_equal(fit_run(&r, &clean), FIT_CONVERGED);
	assert_int_equal(clean.rejected, 0);
	planted_request(&r, pts, &one);
	int status = fit_run(&r, &res);
	printf("  planted failure at call 4: %s, %d rejected, e = %.6g (clean %.6g +- %.2g), mu = "
	       "%.4g (clean %.4g +- %.2g)\n", fit_status_name(status), res.rejected, res.x[0],
	       clean.x[0], clean.se[0], res.x[1], clean.x[1], clean.se[1]);
	assert_int_equal(one.vetoed, 1);
	assert_int_equal(status, FIT_CONVERGED);
	assert_int_equal(res.rejected, 1);
	assert_true(res.iterations >= 1);
	for (int j = 0; j < 2; j++) {
		assert_true(isfinite(res.se[j]) && res.se[j] > 0);
		assert_true(fabs(res.x[j] - clean.x[j]) < 0.5 * clean.se[j]);
	}
	/* the warning names the rejected point and why */
	int named = 0;
	for (int w = 0; w < res.nwarn; w++)
		named |= strstr(res.warnings[w], "1 trial point could not be evaluated") &&
			 strstr(res.warnings[w], "vetoed");
	assert_true(named);
	fit_result_free(&clean);
	fit_result_free(&res);
}

/* Every call from the first iteration's Jacobian on fails (its steps both
 * ways): the fit fails, says why, and reports the best point it saw (the
 * accepted trial point, below the start's cost) without standard errors. */
static void failed_fit_reports_best_point(void **state)
{
	(void)state;
	fit_point pts[NPTS];
	noisy_data(pts, 20160601);
	planted pl = {.from = 5};
	fit_request r;
	planted_request(&r, pts, &pl);
	fit_result res;
	int status = fit_run(&r, &res);
	printf("  %s: %s; best e = %.6g, mu = %.4g, chi2 %.3g\n", fit_status_name(status), res.error,
	       res.x[0], res.x[1], res.chi2);
	assert_int_equal(status, FIT_FAILED);
	assert_non_null(strstr(res.error, "no Jacobian in iteration 1"));
	assert_non_null(strstr(res.error, "vetoed"));
	/* the best point: not the start, its cost below the start's */
	assert_true(res.x[0] != 0.018 && res.x[1] != 0.5);
	double start_chi2 = 0;
	for (int i = 0; i < NPTS; i++) {
		assert_true(isfinite(res.model[i]));
		start_chi2 += pow((res.model_start[i] - pts[i].v) / SIGMA, 2);
	}
	assert_true(res.chi2 < start_chi2);
	for (int j = 0; j < 2; j++)
		assert_true(isnan(res.se[j]));
	fit_result_free(&res);
}

/* The peak of one model curve, scanned from two centres: 30 deg (the scan
 * holds the peak, near 31 deg) and 52 deg (the scan, 42..62 deg, does not:
 * it must follow the peak down past its lower end). Both the same. */
static void peak_scan_follows_the_peak(void **state)
{
	(void)state;
	double found[2], found_u[2], centre[2] = {30, 52};
	long evals[2];
	for (int k = 0; k < 2; k++) {
		fit_request r;
		cheap_request(&r);
		r.nfree = 1; /* e alone */
		r.npeaks = 1;
		r.peaks[0] = (fit_peak){centre[k] * RAD_PER_DEG, SIM_CW, NAN};
		fit_eval ev;
		assert_int_equal(fit_eval_init(&ev, &r), 0);
		double x = TRUE_E;
		assert_int_equal(fit_eval_data(&ev, 1, &x, &found[k], &found_u[k]), 0);
		evals[k] = ev.evaluations;
		fit_eval_free(&ev);
		printf("  scan around %g deg: peak %.3f +- %.3f deg, %ld runs\n", centre[k],
		       found[k] * DEG_PER_RAD, found_u[k] * DEG_PER_RAD, evals[k]);
	}
	assert_int_equal(evals[0], 11);
	assert_true(evals[1] > 11);
	assert_true(found[0] * DEG_PER_RAD > 25 && found[0] * DEG_PER_RAD < 38);
	assert_true(fabs(found[1] - found[0]) < 0.05 * RAD_PER_DEG);
}

/* Three starts: the request's, then Halton points (1/2, 1/3) and (1/4,
 * 2/3) of the bounds; the result is the run of the lowest cost. */
static void multistart_keeps_the_lowest_cost(void **state)
{
	(void)state;
	fit_point pts[NPTS];
	noisy_data(pts, 20160601);
	fit_request r;
	cheap_request(&r);
	r.free[0] = (fit_free){"e", 0.01, 0.03, 0.018};
	r.free[1] = (fit_free){"mu", 0.1, 1.0, 0.5};
	r.points = pts;
	r.npoints = NPTS;
	r.starts = 3;
	char field[48], msg[FIT_MSG];
	assert_int_equal(fit_check(&r, field, sizeof field, msg, sizeof msg), SIM_OK);
	fit_result res;
	assert_int_equal(fit_run(&r, &res), FIT_CONVERGED);
	assert_int_equal(res.nstarts, 3);
	const double want[3][2] = {{0.018, 0.5}, {0.02, 0.1 + 0.9 / 3}, {0.015, 0.1 + 0.9 * 2 / 3}};
	int best = 0;
	for (int s = 0; s < 3; s++) {
		const fit_start *st = &res.starts[s];
		printf("  start %d (e %.4g, mu %.4g): %s, e = %.6g, mu = %.4g, chi2 %.4g\n", s,
		       st->x0[0], st->x0[1], fit_status_name(st->status), st->x[0], st->x[1],
		       st->chi2);
		for (int j = 0; j < 2; j++)
			assert_true(fabs(st->x0[j] - want[s][j]) < 1e-12);
		if (st->chi2 < res.starts[best].chi2)
			best = s;
	}
	assert_int_equal(res.best_start, best);
	assert_true(res.x[0] == res.starts[best].x[0] && res.x[1] == res.starts[best].x[1]);
	assert_true(fabs(res.x[0] - TRUE_E) < 2 * res.se[0]);
	fit_result_free(&res);
	r.starts = FIT_MAX_STARTS + 1;
	assert_int_equal(fit_check(&r, field, sizeof field, msg, sizeof msg), SIM_EPARAM);
	assert_string_equal(field, "starts");
}

/* A bound is reached in the solver's scale: a stiffness over five decades
 * at 1.1e5 in [1e3, 1e8] is mid-range (u = 0.41), not at its lower bound
 * (linear nearness called everything below 2e5 "lower"); on a linear
 * scale the width is linear. */
static void bound_side_in_the_solvers_scale(void **state)
{
	(void)state;
	fit_free k = {"k_c", 1e3, 1e8, 2.56e4}, r = {"R", 0.01, 0.6, 0.18};
	assert_int_equal(fit_bound_side(&k, 1.1e5), 0);
	assert_int_equal(fit_bound_side(&k, 1.9e5), 0);
	assert_int_equal(fit_bound_side(&k, 1.01e3), -1);
	assert_int_equal(fit_bound_side(&k, 1.03e3), 0);
	assert_int_equal(fit_bound_side(&k, 0.99e8), 1);
	assert_true(fabs(fit_u_of_x(&k, 1e5) - 0.4) < 1e-12);
	assert_int_equal(fit_bound_side(&r, 0.0111), -1);
	assert_int_equal(fit_bound_side(&r, 0.0113), 0);
	assert_int_equal(fit_bound_side(&r, 0.5989), 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(failed_trial_point_is_a_rejected_step),
		cmocka_unit_test(failed_fit_reports_best_point),
		cmocka_unit_test(peak_scan_follows_the_peak),
		cmocka_unit_test(multistart_keeps_the_lowest_cost),
		cmocka_unit_test(bound_side_in_the_solvers_scale),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
