/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_fit_source.c - a fit's result read back as the source of a study's
 * bands (fit/fit_source.c): the parameters, covariance and quantile
 * read from fit_result_json's text are the fit's own (values bit for bit,
 * the covariance rebuilt from standard errors and correlation to
 * round-off); a study point at a curve point of the fit (the same beta,
 * the fitted values) gets the fit's band; a varied parameter leaves the
 * covariance (the band is then q sqrt(g_e^2 C_ee + u^2), computed here
 * from two runs); and texts that are not a usable result are refused with
 * a reason. The cheap scene of fit_fixture.h.
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

#define CURVE_STEP 30.0 /* deg */

typedef struct fixture {
	fit_request r;
	fit_result res;
	fit_point pts[NPTS];
	char *json;
} fixture;

static fixture fx;

static int fit_once(void **state)
{
	(void)state;
	noisy_data(fx.pts, 7);
	cheap_request(&fx.r);
	fx.r.points = fx.pts;
	fx.r.npoints = NPTS;
	fx.r.curve_step = CURVE_STEP * RAD_PER_DEG;
	char field[48], msg[FIT_MSG];
	if (fit_check(&fx.r, field, sizeof field, msg, sizeof msg) != SIM_OK ||
	    fit_run(&fx.r, &fx.res) != FIT_CONVERGED)
		return -1;
	fx.json = fit_result_json(&fx.r, &fx.res);
	return fx.json ? 0 : -1;
}

static int fit_free_all(void **state)
{
	(void)state;
	free(fx.json);
	fit_result_free(&fx.res);
	return 0;
}

static void read_back_is_the_fit(void **state)
{
	(void)state;
	fit_band_source src;
	char msg[300];
	assert_int_equal(fit_band_source_parse(fx.json, &src, msg, sizeof msg), SIM_OK);
	assert_int_equal(src.nfree, 2);
	assert_string_equal(src.free[0].name, "e");
	assert_string_equal(src.free[1].name, "mu");
	for (int j = 0; j < 2; j++) {
		assert_true(src.x[j] == fx.res.x[j]); /* e in m, mu: user units are SI */
		assert_true(src.free[j].lo == fx.r.free[j].lo && src.free[j].hi == fx.r.free[j].hi);
	}
	for (int a = 0; a < 2; a++)
		for (int b = 0; b < 2; b++) {
			double scale = sqrt(fx.res.cov[a * 2 + a] * fx.res.cov[b * 2 + b]);
			assert_true(fabs(src.cov[a * 2 + b] - fx.res.cov[a * 2 + b]) <= 1e-12 * scale);
		}
	assert_true(src.quantile == fx.res.band_quantile);
	assert_true(src.fd_rel == fx.r.fd_rel);
}

/* The model of the study at a curve point k of the fit (cw). */
static void point_model(const fit_band_source *src, const int *skip, size_t k, sim_params *p,
			sim_scene *s, sim_method *m)
{
	const char *varied[] = {"mu"};
	int local[FIT_MAX_FREE];
	*p = fx.r.p;
	*s = fx.r.sc;
	*m = fx.r.m;
	char msg[200];
	assert_int_equal(fit_band_source_prepare(src, varied, skip ? 1 : 0, local, p, s, m, msg,
						 sizeof msg),
			 SIM_OK);
	if (skip) {
		assert_int_equal(local[1], 1);
		p->mu = src->x[1]; /* the grid's value: here the fitted one */
	}
	p->beta = fx.res.curve_beta[k];
	p->rotation = SIM_CW;
}

static void band_at_the_fits_curve_points(void **state)
{
	(void)state;
	fit_band_source src;
	char msg[300];
	assert_int_equal(fit_band_source_parse(fx.json, &src, msg, sizeof msg), SIM_OK);
	int skip[FIT_MAX_FREE] = {0};
	for (size_t k = 0; k < fx.res.ncurve; k++) {
		sim_params p;
		sim_scene s;
		sim_method m;
		sim_measurement at;
		double lo, hi;
		point_model(&src, NULL, k, &p, &s, &m);
		assert_int_equal(sim_measure(&p, &s, &m, fx.r.t_end, &at, msg, sizeof msg), SIM_OK);
		assert_true(at.transport_velocity == fx.res.curve_fit[k]);
		assert_int_equal(fit_band_point(&src, skip, &p, &s, &m, fx.r.t_end, &at, &lo, &hi, msg,
						sizeof msg),
				 SIM_OK);
		double w = fx.res.band_hi[k] - fx.res.band_lo[k];
		assert_true(w > 0);
		assert_true(fabs(lo - fx.res.band_lo[k]) <= 1e-9 * w);
		assert_true(fabs(hi - fx.res.band_hi[k]) <= 1e-9 * w);
	}
}

static void a_varied_parameter_leaves_the_band(void **state)
{
	(void)state;
	fit_band_source src;
	char msg[300];
	assert_int_equal(fit_band_source_parse(fx.json, &src, msg, sizeof msg), SIM_OK);
	int skip[FIT_MAX_FREE] = {0, 1};
	size_t k = 1; /* 30 deg */
	sim_params p, pe;
	sim_scene s;
	sim_method m;
	sim_measurement at, ate;
	double lo, hi;
	point_model(&src, skip, k, &p, &s, &m);
	assert_int_equal(sim_measure(&p, &s, &m, fx.r.t_end, &at, msg, sizeof msg), SIM_OK);
	assert_int_equal(
		fit_band_point(&src, skip, &p, &s, &m, fx.r.t_end, &at, &lo, &hi, msg, sizeof msg),
		SIM_OK);
	/* by hand: e's share alone */
	double h = fit_step(&src.free[0], src.fd_rel, src.x[0]);
	pe = p;
	pe.e = src.x[0] + h;
	assert_int_equal(sim_measure(&pe, &s, &m, fx.r.t_end, &ate, msg, sizeof msg), SIM_OK);
	double g = (ate.transport_velocity - at.transport_velocity) / h;
	double half = src.quantile * sqrt(g * g * src.cov[0] + at.uncertainty * at.uncertainty);
	assert_true(fabs((hi - lo) / 2 - half) <= 1e-12 * half);
	assert_true(fabs((hi + lo) / 2 - at.transport_velocity) <= 1e-12 * half);
	/* and not the band with mu's share (correlated: it differs) */
	assert_true(fabs(hi - fx.res.band_hi[k]) > 1e-6 * (fx.res.band_hi[k] - fx.res.band_lo[k]));
}

static void unusable_texts_are_refused(void **state)
{
	(void)state;
	const struct {
		const char *text, *why;
	} cases[] = {
		{"beta,rotation,v\n", "not the JSON result"},
		{"{\"parameters\":[]}", "\"parameters\" and a \"correlation\""},
		{"{\"parameters\":[{\"name\":\"e\",\"value\":0.02,\"standard_error\":0.001,\"min\":0,"
		 "\"max\":0.5}],\"correlation\":[[1,0]]}",
		 "not the JSON result"},
		{"{\"parameters\":[{\"name\":\"beta\",\"value\":30,\"standard_error\":1,\"min\":0,"
		 "\"max\":180}],\"correlation\":[[1]],\"dof\":3}",
		 "parameters[0]"},
		{"{\"parameters\":[{\"name\":\"e\",\"value\":0.02,\"standard_error\":null,\"min\":0,"
		 "\"max\":0.5}],\"correlation\":[[1]],\"dof\":3}",
		 "must be finite numbers"},
		{"{\"parameters\":[{\"name\":\"e\",\"value\":0.02,\"standard_error\":0.001,\"min\":0,"
		 "\"max\":0.5}],\"correlation\":[[null]],\"dof\":3}",
		 "covariance is not determined"},
		{"{\"status\":\"failed\",\"parameters\":[{\"name\":\"e\",\"value\":0.02,"
		 "\"standard_error\":0.001,\"min\":0,\"max\":0.5}],\"correlation\":[[1]],\"dof\":3}",
		 "the fit failed"},
		{"{\"parameters\":[{\"name\":\"e\",\"value\":0.02,\"standard_error\":0.001,\"min\":0,"
		 "\"max\":0.5}],\"correlation\":[[1]],\"dof\":0}",
		 "covariance is not determined"}, /* no residual variance: no quantile */
	};
	for (size_t i = 0; i < sizeof cases / sizeof *cases; i++) {
		fit_band_source src;
		char msg[300] = "";
		assert_int_equal(fit_band_source_parse(cases[i].text, &src, msg, sizeof msg),
				 SIM_EPARAM);
		if (!strstr(msg, cases[i].why))
			fail_msg("case %zu: '%s' does not say '%s'", i, msg, cases[i].why);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(read_back_is_the_fit),
		cmocka_unit_test(band_at_the_fits_curve_points),
		cmocka_unit_test(a_varied_parameter_leaves_the_band),
		cmocka_unit_test(unusable_texts_are_refused),
	};
	return cmocka_run_group_tests(tests, fit_once, fit_free_all);
}
