/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_fopdt.c - the first-order-plus-dead-time fit (fit/fopdt.c) against
 * known answers: a response made from known K, T, L and four steps (up,
 * back, down, back) with Gaussian noise of known sigma (fixed seed) must
 * give those back within three standard errors, and noise-free data
 * exactly; too few samples are refused.
 */
#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdlib.h>

#include <cmocka.h>

#include "fopdt.h"

#define N 400

static const double ts[4] = {1, 3, 5, 7};
static const double d[4] = {4, -4, -4, 4};

/* Gaussian noise of unit sigma (Box-Muller on a 64-bit LCG). */
static double gauss(uint64_t *s)
{
	*s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
	double u = ((double)(*s >> 11) + 0.5) / 9007199254740992.0;
	*s = *s * 6364136223846793005ULL + 1442695040888963407ULL;
	double v = ((double)(*s >> 11) + 0.5) / 9007199254740992.0;
	return sqrt(-2 * log(u)) * cos(2 * M_PI * v);
}

static void data(double sigma, double *t, double *y)
{
	fopdt_result m = {.y0 = 0.08, .k = -0.0032, .t = 0.35, .l = 0.12};
	uint64_t seed = 20261128;
	for (int i = 0; i < N; i++) {
		t[i] = 0.5 + 8.0 * i / N;
		y[i] = fopdt_eval(&m, ts, d, 4, t[i]) + sigma * gauss(&seed);
	}
}

/* The fit of the N samples with noise of sigma, which must succeed. */
static fopdt_result fit_of(double sigma)
{
	double t[N], y[N];
	data(sigma, t, y);
	fopdt_result r;
	assert_int_equal(fopdt_fit(t, y, N, ts, d, 4, 2, &r), 0);
	return r;
}

static void exact_without_noise(void **state)
{
	(void)state;
	fopdt_result r = fit_of(0);
	assert_true(fabs(r.k + 0.0032) < 1e-9);
	assert_true(fabs(r.t - 0.35) < 1e-6);
	assert_true(fabs(r.l - 0.12) < 1e-6);
	assert_true(fabs(r.y0 - 0.08) < 1e-9);
}

static void within_standard_errors(void **state)
{
	(void)state;
	fopdt_result r = fit_of(0.0005);
	assert_true(r.ok && r.k_se > 0 && r.t_se > 0 && r.l_se > 0);
	assert_true(fabs(r.k + 0.0032) < 3 * r.k_se);
	assert_true(fabs(r.t - 0.35) < 3 * r.t_se);
	assert_true(fabs(r.l - 0.12) < 3 * r.l_se);
	/* the noise's sigma comes back as the residual */
	assert_true(fabs(r.rms - 0.0005) < 0.0001);
}

static void too_few_samples(void **state)
{
	(void)state;
	double t[N], y[N];
	data(0, t, y);
	fopdt_result r;
	assert_int_equal(fopdt_fit(t, y, 7, ts, d, 4, 2, &r), -1);
	assert_int_equal(r.ok, 0);
	assert_int_equal(fopdt_fit(t, y, N, ts, d, 0, 2, &r), -1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(exact_without_noise),
		cmocka_unit_test(within_standard_errors),
		cmocka_unit_test(too_few_samples),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
