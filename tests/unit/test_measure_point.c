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
 * its bar holding a long-window reference, and the long run's check reads
 * the running shadow as its end would. The machine step's a-priori term
 * in the bar is held to its formula on a machine with its own period. A
 * feed thrown hard is measured over a later window.
 */
#include "testutil.h"

#include "sim_int.h" /* the estimator's largest trough speed; shadow_peek */
#include "study.h"

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

/* A curve's own peak (core/study.h): where the feed barely throws (g = 60
 * m/s^2: the trough's acceleration about half of g) the run's peak
 * estimate, half the trough's largest speed, is several times the curve's
 * peak, and a point's tol_met by it allows a bar of more than 1 % of |v|
 * where the convention, with the curve's peak, asks 1 % of |v|. Judged
 * again with the largest |v| of a curve every 30 deg (150 deg's), that
 * point says tol is not met; which betas make a curve; the rule itself by hand. */
static void curve_peak_judges_tol_again(void **state)
{
	(void)state;
	static const double every30[] = {180, 0, 30, 60, 90, 120, 150}, half[] = {0, 90, 180},
			    to_180[] = {0, 30, 60, 90, 120, 150, 170, 180};
	assert_true(sim_curve_covers(every30, 7));
	assert_false(sim_curve_covers(every30, 1));
	assert_false(sim_curve_covers(every30 + 1, 6)); /* 0 to 150 */
	assert_false(sim_curve_covers(half, 3));
	assert_true(sim_curve_covers(to_180, 8));
	assert_false(sim_curve_covers(to_180, 7)); /* to 170 */
	sim_measurement r = {.transport_velocity = -0.01, .uncertainty = 2e-4, .tol_met = 1};
	assert_true(sim_tol_met_at_peak(&r, 0.01, 0.1));   /* |v| < 0.3 peak: 1e-3 allowed */
	assert_false(sim_tol_met_at_peak(&r, 0.01, 1.0 / 30.0)); /* |v| = 0.3 peak: 1e-4 */
	assert_true(sim_tol_met_at_peak(&r, 0.03, 0.02));  /* 3e-4 */
	r.tol_met = 0;
	assert_false(sim_tol_met_at_peak(&r, 0.01, 1.0)); /* never from false to true */

	static const char *const heavy[] = {"g", "60", NULL};
	double peak = 0.0;
	sim_measurement m[7];
	for (int i = 0; i < 7; i++) {
		m[i] = point(30.0 * i, "cw", heavy);
		peak = fmax(peak, fabs(m[i].transport_velocity));
	}
	setup u = preset_defaults();
	set(&u, "g", "60");
	u.p.beta = 30.0 * RAD_PER_DEG;
	sim *s = make(&u);
	advance(s, 1.2);
	double estimate = 0.5 * s->est.speed_max;
	sim_free(s);
	if (!(estimate > 5.0 * peak))
		fail_msg("the estimate %.4g m/s, the curve's peak %.4g m/s", estimate, peak);
	/* 150 deg: the curve's peak, its bar beyond 1 % of |v| */
	assert_true(fabs(m[5].transport_velocity) == peak);
	assert_true(m[5].tol_met && m[5].uncertainty > 0.01 * peak);
	assert_false(sim_tol_met_at_peak(&m[5], 0.01, peak));
	/* 90 deg: v near 0, its bar within 1 % of the curve's peak: still met */
	assert_true(m[3].tol_met && sim_tol_met_at_peak(&m[3], 0.01, peak));
}

/* A fast machine whose stability bound cuts the machine step below two
 * feed steps (M_ut 269.4 N m, k_y 27670 N/m, mu 0.4803: 2.4e-4 s) gets
 * the shadow's least sub-steps, 3, not 1, so that its bar is measured
 * (sim_default_substeps): with 1 it was the preset's calibrated term, and
 * 60 deg cw read 0.08327 m/s with a bar of 7.2e-4 against v_ref 0.082321
 * (dem 1.25e-4 s / 40 sub-steps without events, the same to 1e-7 m/s over
 * [0, 8], [10, 18] and [20, 28] s after the steady start). */
static void fast_machine_gets_a_shadow(void **state)
{
	(void)state;
	static const char *const fast[] = {"M_ut", "269.4", "k_y", "27670", "mu", "0.4803", NULL};
	setup u = preset_defaults();
	for (int i = 0; fast[i]; i += 2)
		set(&u, fast[i], fast[i + 1]);
	double dt = sim_default_dt(&u.p, &u.sc, &u.m);
	assert_true(dt == 2.4e-4);
	assert_int_equal(sim_default_substeps(&u.p, &u.sc, &u.m, dt), 3);
	sim_measurement m = point(60.0, "cw", fast);
	assert_int_equal(m.substeps, 3);
	assert_true(m.tol_met);
	holds(&m, 0.082321, 0.1505, 60.0);
}

/* The machine step's a-priori term (sim_status.c) is first order in the
 * step counted in the machine's own excitation periods: 0.5 % of |v| plus
 * 0.025 % of the trough's largest speed at 32 steps a period, that times
 * dt / (T / 32) with T = 2 pi / omega_ss. A motor of 300 rad/s (J_w and
 * M_ut raised so the slip mode stays stable and the motor keeps up) at 32
 * and at 16 steps of its own period gives one and two times the two
 * fractions; the preset's period (157.08 rad/s) would give 0.52 and 1.05. */
static void machine_step_term_in_the_machines_own_period(void **state)
{
	(void)state;
	static const double steps[] = {32.0, 16.0};
	for (int i = 0; i < 2; i++) {
		setup u = preset_defaults();
		set(&u, "omega_ss", "300");
		set(&u, "J_w", "0.002");
		set(&u, "M_ut", "80");
		set(&u, "rotation", "cw");
		u.p.beta = 30.0 * RAD_PER_DEG;
		u.m.dt = 2.0 * M_PI / 300.0 / steps[i];
		sim *s = make(&u);
		advance(s, 0.6);
		sim_status st = status(s);
		double speed = s->est.speed_max, v = fabs(st.transport_velocity);
		sim_free(s);
		assert_true(st.dt == u.m.dt && v > 0.01 && speed > 0.0);
		double want = (0.005 * v + 0.00025 * speed) * 32.0 / steps[i];
		if (!(fabs(st.machine_error - want) <= 1e-12 * want))
			fail_msg("%g steps a period: machine_error %.9g, want %.9g", steps[i],
				 st.machine_error, want);
	}
}

/* A point within 1 % of v_ref or not tol_met, its bar holding v_ref. */
static void within_or_says(const sim_measurement *m, double v_ref)
{
	double e = fabs(m->transport_velocity - v_ref);
	if (m->tol_met && !(e <= 0.01 * fabs(v_ref)))
		fail_msg("v %.4f within tol, v_ref %.4f", m->transport_velocity, v_ref);
	if (!(e <= m->uncertainty))
		fail_msg("|v - v_ref| = %.3g outside the bar %.3g", e, m->uncertainty);
}

/* A feed thrown hard (e 0.05195 m, k_c 3.827e6: a throw of about 9): on
 * the steady start's orbit the machine is steady for about 3 s, then
 * leaves it (at the default steps v -0.2906 m/s over [0, 4] s, -0.2708
 * over [10, 18] s), and a sweep's point over [0, 4] s was within tol at
 * -0.2916. Measured over [8, 12] s instead (measure.c,
 * MEASURE_LATE_THROW), at four times the scene's feed sub-steps (its shadow
 * at twice them): within 1 % of the reference (dt 1.25e-4 s / 40 sub-steps
 * without feed events over [10, 18] s: -0.27101; 6.25e-5 s: -0.27097;
 * 1.25e-4 s over [20, 30] s: -0.27117), inside its bar. */
static void hard_throw_measured_late(void **state)
{
	(void)state;
	static const char *const hard[] = {"e", "0.05195", "k_c", "3827000", NULL};
	sim_measurement m = point(120.0, "cw", hard);
	holds(&m, -0.27100, 0.45, 120.0);
	setup u = preset_defaults();
	for (int i = 0; hard[i]; i += 2)
		set(&u, hard[i], hard[i + 1]);
	u.p.beta = 120.0 * RAD_PER_DEG;
	double dt = sim_default_dt(&u.p, &u.sc, &u.m);
	int n = sim_default_substeps(&u.p, &u.sc, &u.m, dt);
	if (!(m.substeps >= 4 * n))
		fail_msg("%d sub-steps, the scene's %d", m.substeps, n);
}

/* A feed thrown hard whose feed step picks its motion (e 0.05593 m, R
 * 0.1926, k_c 882600, 150 deg cw, a throw of about 9): at the scene's
 * feed step (5 sub-steps of 2.5e-4 s) the feed settles into a motion at
 * -0.393 m/s and keeps it over [20, 30] s, and its shadow (3 sub-steps)
 * agrees: a point within tol 11 % off. At 6.25e-5 s and finer it moves
 * at -0.440 to -0.4415 (the references of docs/random-machines.md: dt
 * 1.25e-4 s / 40 sub-steps over [10, 18] s and 6.25e-5 s / 80 over [20,
 * 28] s, -0.4415). The later window at four times the sub-steps, its
 * shadow at twice them: the point is within 1 % of the reference or says
 * it is not, and its bar holds the reference. */
static void hard_throw_feed_step(void **state)
{
	(void)state;
	static const char *const hard[] = {"e", "0.05593", "R", "0.1926", "k_c", "882600", NULL};
	sim_measurement m = point(150.0, "cw", hard);
	within_or_says(&m, -0.4415);
}

/* A feed thrown harder still (e 0.09624 m, 30 deg cw, a throw of about
 * 18) whose feed step error stalls before it shrinks: over [8, 12] s 5
 * and 10 sub-steps give 0.7101 and 0.7082 m/s, 20, 40, 80 and 160 give
 * 0.7148, 0.7154, 0.7165 and 0.7172; the references (as above) 0.7194.
 * At 10 sub-steps against 5 the point was within tol 1.6 % off; at 20
 * against 10, then at half the machine step, it is within 1 %, its bar
 * holding the reference, and meets tol (10 against 5 with the half
 * machine step says it does not: 0.7153 +- 0.0083). */
static void hard_throw_feed_step_stalls(void **state)
{
	(void)state;
	static const char *const hard[] = {"e", "0.09624", NULL};
	sim_measurement m = point(30.0, "cw", hard);
	if (!m.tol_met)
		fail_msg("v %.4f +- %.4f: tol not met", m.transport_velocity, m.uncertainty);
	within_or_says(&m, 0.7194);
}

/* A hard-thrown feed on stiff contacts (e 0.04322 m, k_c 1.717e7, mu
 * 0.2682, 30 deg cw, a throw of about 7) whose machine step moves v: over
 * [8, 12] s at 1.25e-3 s, 0.2762 to 0.2768 m/s from 20 to 80 feed
 * sub-steps; at 6.25e-4 s 0.2740, at 1.5625e-4 s 0.2732 (the references,
 * as above: 0.27297). At four times the sub-steps alone the point said
 * 0.2768 within tol, 1.4 % off, the machine step's a-priori term (0.5 %
 * of v) too small here; refined once at half the machine step, the run
 * before its shadow, it is within 1 % or says it is not, its bar holding
 * the reference. */
static void hard_throw_machine_step(void **state)
{
	(void)state;
	static const char *const hard[] = {"e", "0.04322", "k_c", "17170000", "mu", "0.2682", NULL};
	sim_measurement m = point(30.0, "cw", hard);
	within_or_says(&m, 0.27297);
}

/* A feed thrown between the check's threshold and the later window's (e
 * 0.0413 m, omega_ss 130.1 rad/s, 150 deg cw, a throw of about 4.5) whose
 * shadow stalls with it: over [0, 4] s v is -0.2039, -0.2045, -0.2069
 * and -0.2066 m/s at 3, 5, 10 and 20 feed sub-steps (the references of
 * docs/random-machines.md: -0.2069). 5 against its shadow at 3 said
 * -0.2046 +- 0.0020 within tol, 1.1 % off; run again at twice the
 * sub-steps, the first run its shadow, the point is within 1 % and meets
 * tol, its bar holding the reference. */
static void thrown_feed_step_stalls(void **state)
{
	(void)state;
	static const char *const thrown[] = {"e", "0.0413", "omega_ss", "130.1", NULL};
	sim_measurement m = point(150.0, "cw", thrown);
	if (!m.tol_met)
		fail_msg("v %.4f +- %.4f: tol not met", m.transport_velocity, m.uncertainty);
	within_or_says(&m, -0.2069);
}

/* Issue 37's chaotic feed (R = 0.5, mu = 0.6): the run and its shadow
 * drift apart and their difference is scatter, which the shadow's bar
 * divided by r - 1 (up to 7 times the true error on main at f416208, the
 * refinements taking up to 80 sub-steps). Where the first run's
 * difference is within two of its paired standard errors the point is
 * measured again from its settled start at 12 sub-steps with its shadow
 * (6) throughout: to a first check at most 6 windows on (aimed at
 * scatter_scale, as before the convention's allowance near v = 0), and on
 * where the bar misses what tol allows and a longer window (at most 25)
 * can bring it within. Held against the long-window reference
 * (tests/bench/zoo/chaos_ref.tsv: the mean of 15 16-s windows at 1.25e-4
 * s / 40 sub-steps, se its standard error): v_ref inside the bar and
 * tol_met. 80 and 145 deg cw meet tol at the first check (599 periods);
 * 70 deg cw (near v = 0) and 150 deg cw go on past it (1,862 and 1,635
 * periods); at 6 sub-steps against 3, 145 and 150 deg cw did not meet tol
 * (their shadow's difference significant and beyond it). */
static void chaotic_feed_long_run(void **state)
{
	(void)state;
	static const char *const chaotic[] = {"R", "0.5", "mu", "0.6", NULL};
	static const double beta[] = {70.0, 80.0, 145.0, 150.0};
	static const double v_ref[] = {0.0062980, -0.0009942, -0.1180664, -0.1192285};
	static const double se[] = {1.6e-4, 9.8e-5, 4.7e-5, 5.5e-5};
	/* whole periods at the run's end (6 windows: 599), tol_met */
	static const double periods_min[] = {1000.0, 590.0, 590.0, 1000.0};
	static const double periods_max[] = {2500.0, 610.0, 610.0, 2500.0};
	for (int i = 0; i < 4; i++) {
		sim_measurement m = point(beta[i], "cw", chaotic);
		assert_int_equal(m.refinements, 0);
		assert_int_equal(m.substeps, 12);
		assert_true(m.tol_met);
		if (!(m.periods >= periods_min[i] && m.periods <= periods_max[i]))
			fail_msg("beta %g: %g periods", beta[i], m.periods);
		double e = fabs(m.transport_velocity - v_ref[i]);
		if (!(e <= m.uncertainty))
			fail_msg("beta %g: |v - v_ref| = %.3g outside the bar %.3g (se %.2g)", beta[i],
				 e, m.uncertainty, se[i]);
	}
}

/* The long run's check (measure.c) reads the running shadow's step error
 * with shadow_peek: at the shadow's end it is what shadow_finish then
 * sets, bit for bit (the chaotic feed at 70 deg cw, 6 sub-steps against
 * 3 over a 4-s shadow window), and nothing before a whole period. */
static void peek_is_what_the_shadows_end_sets(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "R", "0.5");
	set(&u, "mu", "0.6");
	set(&u, "rotation", "cw");
	u.p.beta = 70.0 * RAD_PER_DEG;
	u.m.dt = DT_PRESET;
	u.m.substeps = 6;
	int err;
	char msg[200] = "";
	sim *s = sim_new_windowed(&u.p, &u.sc, &u.m, 4.0, INFINITY, NULL, &err, msg,
				  sizeof msg);
	if (!s)
		fail_msg("sim_new_windowed: %s", msg);
	double raw = -1.0, se = -1.0;
	assert_int_equal(shadow_peek(s, &raw, &se), 0);
	assert_true(raw == -1.0 && se == -1.0);
	assert_int_equal(s->shadow->cfg.substeps, 3);
	double until = s->shadow_until;
	assert_int_equal(sim_advance(s, until), SIM_OK);
	assert_int_equal(shadow_peek(s, &raw, &se), 1);
	assert_non_null(s->shadow);
	assert_true(raw >= 0.0 && se > 0.0 && isfinite(se));
	assert_int_equal(sim_advance(s, nextafter(until, INFINITY)), SIM_OK);
	assert_null(s->shadow);
	assert_true(s->step_error == raw);
	assert_true(s->step_se == se);
	sim_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(refinement_against_the_run_before),
		cmocka_unit_test(beyond_tol_stops_at_the_shadows_end),
		cmocka_unit_test(own_shadow_where_the_run_before_misses),
		cmocka_unit_test(tol_allows_the_conventions_error),
		cmocka_unit_test(curve_peak_judges_tol_again),
		cmocka_unit_test(fast_machine_gets_a_shadow),
		cmocka_unit_test(machine_step_term_in_the_machines_own_period),
		cmocka_unit_test(hard_throw_measured_late),
		cmocka_unit_test(hard_throw_feed_step),
		cmocka_unit_test(hard_throw_feed_step_stalls),
		cmocka_unit_test(hard_throw_machine_step),
		cmocka_unit_test(thrown_feed_step_stalls),
		cmocka_unit_test(chaotic_feed_long_run),
		cmocka_unit_test(peek_is_what_the_shadows_end_sets),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
