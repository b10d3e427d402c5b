/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_measure_point.c - a sweep's point (sim_measure_point) where its
 * first run's bar is beyond tol and it is measured again at finer steps:
 * the refinement takes the run before it as its shadow, runs its own
 * shadow afterwards where that bar misses tol, and one that can neither
 * meet tol nor refine further stops at its shadow's end. Each answer is
 * held against the converged references (tests/bench/results/vref.tsv,
 * tests/bench/zoo/ref.tsv): within 1 % (docs/MODEL.md's convention) and
 * inside the reported error bar. On a chaotic feed, where the run and its
 * shadow differ by scatter, it is measured over a longer window instead,
 * its bar within 3 times the error of a long-window reference.
 */
#include "testutil.h"

#include "sim_int.h" /* the estimator's largest trough speed */

#define PEAK 0.152557   /* the preset's, vref.tsv */
#define DT_PRESET 1.25e-3 /* the preset's machine step with feed events */

/* A point of the preset's defaults (or with the settings kv, pairs up to
 * NULL) at beta deg, rotation rot, measured as a sweep does over 4 s. */
static sim_measurement point(double beta, const char *rot, const char *const *kv)
{
	setup u = preset_defaults();
	for (int i = 0; kv && kv[i]; i += 2)
		set(&u, kv[i], kv[i + 1]);
	set(&u, "rotation", rot);
	u.p.beta = beta * RAD_PER_DEG;
	sim_measurement out;
	char msg[200] = "";
	if (sim_measure_point(&u.p, &u.sc, &u.m, 4.0, &out, msg, sizeof msg) != SIM_OK)
		fail_msg("beta %g %s: %s", beta, rot, msg);
	return out;
}

/* v within 1 % of v_ref (relative to the peak near v = 0) and v_ref
 * inside the bar. */
static void holds(const sim_measurement *m, double v_ref, double peak, double beta)
{
	double den = fabs(v_ref) >= 0.3 * peak ? fabs(v_ref) : peak;
	double e = fabs(m->transport_velocity - v_ref);
	if (!(e <= 0.01 * den))
		fail_msg("beta %g: v %.6f, v_ref %.6f (%.2f %%)", beta, m->transport_velocity, v_ref,
			 100 * e / den);
	if (!(e <= m->uncertainty))
		fail_msg("beta %g: |v - v_ref| = %.3g outside the bar %.3g", beta, e, m->uncertainty);
}

/* 25 deg cw: the feed step refined (5 to more than 10 sub-steps, so the
 * run before is not the refinement's own shadow), 70 deg cw: the machine
 * step refined. Both meet tol at the refinement's shadow's end (fewer
 * than 40 periods of a 4-s window's 98). */
static void refinement_against_the_run_before(void **state)
{
	(void)state;
	sim_measurement a = point(25.0, "cw", NULL);
	assert_int_equal(a.refinements, 1);
	assert_true(a.dt == DT_PRESET && a.substeps > 10);
	assert_true(a.tol_met && a.steady);
	assert_true(a.periods < 40);
	holds(&a, 0.1326743, PEAK, 25.0);
	sim_measurement b = point(70.0, "cw", NULL);
	assert_true(b.refinements >= 1);
	assert_true(b.dt < 0.7 * DT_PRESET && b.substeps == 5);
	assert_true(b.tol_met && b.steady);
	assert_true(b.periods < 40);
	holds(&b, 0.0502317, PEAK, 70.0);
}

/* 145 deg cw: refined to 9 sub-steps, whose own shadow (5) is the run
 * before; its step error alone stays beyond tol and shrank by less than
 * a first-order one would, with little scatter: no window or further
 * refinement can meet tol, so it stops at its shadow's end, says so and
 * still holds v_ref. */
static void beyond_tol_stops_at_the_shadows_end(void **state)
{
	(void)state;
	sim_measurement m = point(145.0, "cw", NULL);
	assert_int_equal(m.refinements, 1);
	assert_int_equal(m.substeps, 9);
	assert_false(m.tol_met);
	assert_true(m.step_error > 0.01 * fabs(m.transport_velocity));
	assert_true(m.periods < 40);
	holds(&m, -0.1079937, PEAK, 145.0);
}

/* The zoo's `ideal` machine at 150 deg cw, refined from 11 to 20
 * sub-steps: against the run before (pre-asymptotic, which is why it was
 * refined) the bar misses tol, so the refinement's own shadow (10
 * sub-steps) runs afterwards and its bar meets tol, as it did beside the
 * run. */
static void own_shadow_where_the_run_before_misses(void **state)
{
	(void)state;
	static const char *const ideal[] = {"drive", "ideal", "e", "0.03", "k_c", "5e6",
					    "mu", "0.5", NULL};
	sim_measurement m = point(150.0, "cw", ideal);
	assert_int_equal(m.refinements, 1);
	assert_int_equal(m.substeps, 20);
	assert_true(m.tol_met);
	holds(&m, -0.21549833, 0.235, 150.0);
}

/* What tol allows follows docs/MODEL.md's convention with the peak
 * estimated as half the trough's largest speed: tol |v| where |v| >= 0.3
 * of that, else tol times it (formerly tol times 0.3 of it, a third). At
 * 85 deg cw (v = -3 mm/s) that is what a run's status says after 1.2 s;
 * at 30 deg cw, tol |v|. And 75 deg cw (v = 32 mm/s, below 0.3 of the
 * estimate), whose first run's bar missed the former allowance and was
 * refined with a machine step of a third, now meets tol without
 * refinement and holds v_ref. */
static void tol_allows_the_conventions_error(void **state)
{
	(void)state;
	static const double beta[] = {85.0, 30.0};
	for (int i = 0; i < 2; i++) {
		setup u = preset_defaults();
		u.p.beta = beta[i] * RAD_PER_DEG;
		sim *s = make(&u);
		advance(s, 1.2);
		sim_status st = status(s);
		double peak = 0.5 * s->est.speed_max, v = fabs(st.transport_velocity);
		sim_free(s);
		assert_true(i == 0 ? v < 0.3 * peak : v >= 0.3 * peak);
		double want = 0.01 * (i == 0 ? peak : v);
		if (!(fabs(st.tol_allowed - want) <= 1e-12 * want))
			fail_msg("beta %g: tol_allowed %.9g, want %.9g", beta[i], st.tol_allowed, want);
	}
	sim_measurement m = point(75.0, "cw", NULL);
	assert_int_equal(m.refinements, 0);
	assert_true(m.dt == DT_PRESET && m.substeps == 5);
	assert_true(m.tol_met && m.steady);
	holds(&m, 0.0322247, PEAK, 75.0);
}

/* Issue 37's chaotic feed (R = 0.5, mu = 0.6): the run and its shadow
 * drift apart and their difference is scatter, which the shadow's bar
 * divided by r - 1 (up to 7 times the true error on main at f416208, the
 * refinements taking up to 80 sub-steps). Here the first run's difference
 * is within two of its paired standard errors: the point is measured
 * again over 24 s (599 periods) at 6 sub-steps with its shadow (3)
 * throughout, its step error bounded by that standard error. Against the
 * long-window reference (tests/bench/zoo/chaos_ref.tsv: the mean of
 * 15 4-s windows at 1.25e-4 s / 40 sub-steps, its standard error se) the
 * bar holds and is at most 3 times the error, the error taken as at least
 * 2 se (on main: 5.8 and 4.5 times). */
static void chaotic_feed_bar_within_three_errors(void **state)
{
	(void)state;
	static const char *const chaotic[] = {"R", "0.5", "mu", "0.6", NULL};
	static const double beta[] = {70.0, 80.0, 130.0};
	static const double v_ref[] = {0.0060803, -0.0006647, -0.0832866},
			    se[] = {3.1e-4, 1.4e-4, 1.7e-4};
	for (int i = 0; i < 3; i++) {
		sim_measurement m = point(beta[i], "cw", chaotic);
		assert_int_equal(m.refinements, 0);
		assert_int_equal(m.substeps, 6);
		assert_true(m.periods > 500);
		/* near v = 0 (70 and 80 deg) the long run as before, its bar
		 * within what tol allows there (at 80 deg a stop at the first
		 * check, the scatter read against that allowance, left v_ref
		 * outside the bar); at 130 deg beyond it */
		assert_int_equal(m.tol_met, i < 2);
		double e = fabs(m.transport_velocity - v_ref[i]);
		if (!(e <= m.uncertainty))
			fail_msg("beta %g: |v - v_ref| = %.3g outside the bar %.3g", beta[i], e,
				 m.uncertainty);
		if (!(m.uncertainty <= 3.0 * fmax(e, 2.0 * se[i])))
			fail_msg("beta %g: bar %.3g beyond 3 times the error %.3g (se %.2g)",
				 beta[i], m.uncertainty, e, se[i]);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(refinement_against_the_run_before),
		cmocka_unit_test(beyond_tol_stops_at_the_shadows_end),
		cmocka_unit_test(own_shadow_where_the_run_before_misses),
		cmocka_unit_test(tol_allows_the_conventions_error),
		cmocka_unit_test(chaotic_feed_bar_within_three_errors),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
