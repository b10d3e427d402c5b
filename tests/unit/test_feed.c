/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_feed.c - the feed against known answers: rebound at R times the
 * impact speed, transport direction and its reversal by beta, mirror
 * symmetry with opposite transport, agreement of the symmetric reduction
 * with the full model, the energy balance, a slide under the regularised
 * friction law against its closed form, the deck points shown from their
 * rest, each column's displacement from its own origin (the hopping
 * theory of VDI 2333 runs through the engine in test_accuracy.c).
 */
#include "sim_int.h" /* the state at t = 0, column by column */
#include "testutil.h"

/* One element dropped on a fixed deck (no gravity, so that the contact
 * alone acts): it leaves at R times the impact speed (p = 1: loading
 * stiffness k, unloading R^2 k). */
static void rebound_speed_is_R_times_impact(void **state)
{
	(void)state;
	const char *methods[][3] = {{"rk4", "1e-6", "1"}, {"dem", "1e-5", "1"}, {"dopri5", "1e-5", "1"}};
	const char *Rs[] = {"0.05", "0.5", "0.9"};
	for (int mi = 0; mi < 3; mi++)
		for (int ri = 0; ri < 3; ri++) {
			setup u = one_element();
			set(&u, "g", "0");
			set(&u, "R", Rs[ri]);
			set(&u, "method", methods[mi][0]);
			set(&u, "dt", methods[mi][1]);
			set(&u, "substeps", methods[mi][2]);
			sim *s = make(&u);
			double eta = 1e-3, etad = -0.5;
			assert_int_equal(sim_place_feed(s, NULL, &eta, NULL, &etad), SIM_OK);
			advance(s, 0.2);
			double y0, v;
			/* the velocity after separation, from two positions */
			sim_feed_state(s, NULL, &y0);
			advance(s, 0.25);
			double y1;
			sim_feed_state(s, NULL, &y1);
			v = (y1 - y0) / 0.05;
			double expect = atof(Rs[ri]) * 0.5;
			double tol = mi == 1 ? 0.01 : mi == 2 ? 1e-3 : 2e-4;
			if (fabs(v - expect) > tol * expect)
				fail_msg("%s R=%s: rebound %.6g m/s, expected %.6g", methods[mi][0],
					 Rs[ri], v, expect);
			sim_free(s);
		}
}

/* beta sets the direction: about 38 deg throws right, about 128 deg left
 * (clockwise rotation), and a beta change in a running session reverses
 * the feed without a change of rotation. */
static void beta_sets_and_reverses_direction(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "trough_rotation", "false");
	set(&u, "transient", "1.5");
	set(&u, "beta", "38");
	double right = run_velocity(&u, 3.0);
	set(&u, "beta", "128");
	double left = run_velocity(&u, 3.0);
	if (!(right > 0.08 && left < -0.05))
		fail_msg("v(38) = %.4g, v(128) = %.4g m/s", right, left);
	set(&u, "beta", "38");
	sim *s = make(&u);
	advance(s, 2.5);
	double before = status(s).feed_velocity;
	assert_int_equal(sim_set_beta(s, 128.0 * RAD_PER_DEG, 180.0 * RAD_PER_DEG), SIM_OK);
	sim_restart_transport(s);
	advance(s, 5.0);
	sim_status st = status(s);
	assert_true(before > 0.08);
	assert_true(st.feed_velocity < -0.05);
	assert_close(st.beta * 180 / M_PI, 128.0, 1e-9);
	assert_true(st.transport_velocity < -0.05);
	sim_free(s);
}

/* (cw, beta) and (ccw, 180 - beta) mirror each other, feed included:
 * opposite feed displacement at every instant, opposite velocity. The
 * former dem (feed_events = false) keeps the mirror to round-off (1e-9 of
 * the displacement over 3 s). With its slip reversals located, dem
 * decides per sub-step whether a reversal lies inside it, a threshold
 * decision that the two runs' different round-off (sin 142 deg is not
 * sin 38 deg to the last bit) can take differently once: measured 6.4e-6
 * of the displacement over 3 s, set once at t = 0.172 s and not growing
 * (2.4e-6 m throughout [0.3, 3] s), so 2e-5 there. */
static void mirror_case(const char *events, double tol)
{
	setup a = preset(), b = preset();
	set(&a, "trough_rotation", "true");
	set(&a, "feed_events", events);
	set(&b, "feed_events", events);
	set(&b, "beta", "142");
	set(&b, "rotation", "ccw");
	sim *sa = make(&a), *sb = make(&b);
	double worst = 0.0, scale = 0.0;
	for (int k = 1; k <= 30; k++) {
		advance(sa, 0.1 * k);
		advance(sb, 0.1 * k);
		sim_status x = status(sa), y = status(sb);
		worst = fmax(worst, fabs(x.feed_displacement + y.feed_displacement));
		worst = fmax(worst, fabs(x.q[0] + y.q[0]) + fabs(x.q[1] - y.q[1]));
		scale = fmax(scale, fabs(x.feed_displacement));
	}
	if (worst > tol * scale)
		fail_msg("feed_events=%s: mirror mismatch %.3g (scale %.3g)", events, worst, scale);
	double va = status(sa).transport_velocity, vb = status(sb).transport_velocity;
	/* the period boundaries of the mirrored run fall half a period later */
	assert_true(va > 0.1);
	assert_rel(vb, -va, 2e-3);
	sim_free(sa);
	sim_free(sb);
}

static void mirror_symmetry_with_feed(void **state)
{
	(void)state;
	mirror_case("false", 1e-9);
	mirror_case("true", 2e-5);
}

/* The symmetric reduction (alpha = 0, one column standing for five) is the
 * full model's motion when the trough cannot rotate: pinned by a huge J_r,
 * the two agree to 1e-9 over the first second of the start. */
static void reduction_agrees_with_full_model(void **state)
{
	(void)state;
	setup full = preset(), red = preset();
	set(&full, "J_r", "1e12");
	set(&red, "J_r", "1e12");
	set(&red, "trough_rotation", "false");
	sim *a = make(&full), *b = make(&red);
	assert_int_equal(status(a).reductions, 0);
	assert_int_equal(status(b).reductions, SIM_RED_SYMMETRIC);
	assert_int_equal(status(b).n_dof, 5 + 2 * 8);
	double worst = 0.0;
	const int idx[5] = {0, 1, 3, 4, 5};
	double scale[5] = {0};
	for (int k = 1; k <= 1000; k++) {
		advance(a, k * 1e-3);
		advance(b, k * 1e-3);
		sim_status x = status(a), y = status(b);
		for (int i = 0; i < 5; i++) {
			scale[i] = fmax(scale[i], fabs(x.q[idx[i]]));
			worst = fmax(worst, fabs(x.q[idx[i]] - y.q[idx[i]]) / scale[i]);
		}
	}
	if (worst > 1e-9)
		fail_msg("reduced vs full: %.3g relative", worst);
	double cd[5];
	sim_column_displacement(b, cd);
	for (int k = 1; k < 5; k++)
		assert_close(cd[k], cd[0], 0.0);
	sim_free(a);
	sim_free(b);
}

/* The steady start of the full model on a symmetric machine settles
 * through the symmetric reduction (sim.c, settle_reduced): at t = 0 its
 * machine is the reduced scene's to the last bit with alpha exactly 0, and
 * every column is the reduced scene's one column at its own deck point
 * (the same bits, the horizontal position moved by d_k). An asymmetric
 * machine (l2 != l1) settles its full model as before: it rocks at t = 0. */
static void full_model_settles_through_the_reduction(void **state)
{
	(void)state;
	setup full = preset_defaults(), red = preset_defaults();
	set(&full, "trough_rotation", "true");
	sim *a = make(&full), *b = make(&red);
	sim_status x = status(a), y = status(b);
	assert_int_equal(x.reductions, 0);
	assert_int_equal(y.reductions, SIM_RED_SYMMETRIC);
	assert_true(x.t == 0.0 && y.t == 0.0);
	const int idx[5] = {Q_X, Q_Y, Q_PHI, Q_S1, Q_S2};
	for (int i = 0; i < 5; i++) {
		assert_true(x.q[idx[i]] == y.q[idx[i]]);
		assert_true(x.qd[idx[i]] == y.qd[idx[i]]);
	}
	assert_true(x.q[Q_ALPHA] == 0.0 && x.qd[Q_ALPHA] == 0.0);
	assert_true(y.q[Q_S1] != 0.0);
	const model *ma = &a->md, *mb = &b->md;
	assert_int_equal(ma->dk.K, 5);
	assert_int_equal(mb->dk.K, 1);
	for (int k = 0; k < ma->dk.K; k++)
		for (int j = 0; j < ma->L; j++) {
			int e = k * ma->L + j;
			assert_true(a->y[ma->nq + e] == b->y[mb->nq + j] + ma->dk.d[k]);
			assert_true(a->y[ma->nq + ma->nf + e] == b->y[mb->nq + mb->nf + j]);
			assert_true(a->y[ma->npos + ma->nq + e] == b->y[mb->npos + mb->nq + j]);
			assert_true(a->y[ma->npos + ma->nq + ma->nf + e] ==
				    b->y[mb->npos + mb->nq + mb->nf + j]);
		}
	/* it then runs as the full model: the columns part by round-off */
	advance(a, 0.5);
	assert_true(status(a).t == 0.5);
	sim_free(a);
	sim_free(b);
	setup asym = preset_defaults();
	set(&asym, "trough_rotation", "true");
	set(&asym, "l2", "0.9");
	sim *c = make(&asym);
	assert_true(fabs(status(c).q[Q_ALPHA]) > 1e-6);
	sim_free(c);
}

/* Energy: input = stored change + dissipated, to the method's accuracy;
 * the split method's residual shrinks with its sub-step. */
static void energy_balance_with_feed(void **state)
{
	(void)state;
	double rel[2];
	const char *dts[2] = {"1e-4", "2.5e-5"};
	for (int k = 0; k < 2; k++) {
		setup u = preset();
		set(&u, "trough_rotation", "false");
		set(&u, "rotation", "ccw"); /* phi' < 0: the run the bound was measured on */
		set(&u, "dt", dts[k]);
		set(&u, "substeps", "1");
		sim *s = make(&u);
		advance(s, 1.0);
		sim_status st = status(s);
		assert_true(st.e_input > 50.0);
		assert_true(st.e_dissipated > 0.2 * st.e_input);
		rel[k] = fabs(st.e_residual) / st.e_input;
		sim_free(s);
	}
	if (!(rel[0] < 5e-3 && rel[1] < 0.6 * rel[0]))
		fail_msg("energy residual %.3g, %.3g of the input", rel[0], rel[1]);
}

/* One element sliding on a deck held still under the regularised law,
 * m xi'' = -mu m g tanh(xi' / eps) (settled, so its normal force is m g):
 * d/dt ln sinh(v / eps) = -mu g / eps, so
 *   v(t) = eps asinh(sinh(v0 / eps) exp(-mu g t / eps)),
 * its displacement the integral of that (Simpson's rule, 2000 intervals:
 * 1e-13 m). From v0 = 2 eps over 0.005 s the element loses three quarters
 * of its speed; a width of 2 eps would take it 10 um further (of 58 um).
 * Tolerance as in test_beyond_preset's slide: rk4 far below 1e-8 m, the
 * split method's symplectic Euler |a| h t / 2 = 1e-7 m at h = 1e-5 s. */
static double slide_speed(double v0, double eps, double a, double t)
{
	return eps * asinh(sinh(v0 / eps) * exp(-a * t / eps));
}

static void regularised_slide_slows_as_tanh(void **state)
{
	(void)state;
	const char *methods[][2] = {{"rk4", "1e-8"}, {"dem", "3e-7"}};
	const double mu = 0.4, g = 9.81, eps = 0.01, v0 = 0.02, t = 0.005;
	const int n = 2000;
	double expect = 0.0;
	for (int i = 0; i <= n; i++)
		expect += (i == 0 || i == n ? 1 : i % 2 ? 4 : 2) *
			  slide_speed(v0, eps, mu * g, t * i / n) * t / (3.0 * n);
	for (int mi = 0; mi < 2; mi++) {
		setup u = one_element();
		set(&u, "mu", "0.4");
		set(&u, "R", "1"); /* at rest the law's switch would let it creep down */
		set(&u, "friction", "regularised");
		set(&u, "friction_eps", "0.01");
		set(&u, "method", methods[mi][0]);
		set(&u, "dt", "1e-5");
		set(&u, "substeps", "1");
		sim *s = make(&u);
		double xi0, xi1;
		sim_feed_state(s, &xi0, NULL);
		assert_int_equal(sim_place_feed(s, NULL, NULL, &v0, NULL), SIM_OK);
		advance(s, t);
		sim_feed_state(s, &xi1, NULL);
		sim_free(s);
		if (!(fabs(xi1 - xi0 - expect) <= atof(methods[mi][1])))
			fail_msg("%s: slid %.9g m, the tanh law's %.9g m", methods[mi][0], xi1 - xi0,
				 expect);
	}
}

/* The deck points shown (sim_deck_points) are each column's displacement
 * from its rest: D_k = G + R(alpha) (d_k, h_d) (docs/MODEL.md) less the
 * same at x = y = alpha = 0, with d_k = -0.8 ... 0.8 m evenly (the
 * preset's column_span). A trough rocking (l2 != l1) with its deck above
 * G (h_d = 0.1 m), settled under the feed's weight at the start and in
 * its run-up at 0.3 s: each column's own arm in the rotation. */
static void deck_points_from_their_rest(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "l2", "0.9");
	set(&u, "h_d", "0.1");
	sim *s = make(&u);
	int K = sim_columns(s);
	assert_int_equal(K, 5);
	for (int i = 0; i < 2; i++) {
		advance(s, 0.3 * i);
		sim_status st = status(s);
		double x = st.q[Q_X], y = st.q[Q_Y], a = st.q[Q_ALPHA], h = 0.1, d[2 * 5];
		assert_true(fabs(a) > 1e-7);
		sim_deck_points(s, d);
		for (int c = 0; c < K; c++) {
			double dk = -0.8 + 0.4 * c;
			assert_close(d[2 * c], x + dk * cos(a) - h * sin(a) - dk, 1e-12);
			assert_close(d[2 * c + 1], y + dk * sin(a) + h * cos(a) - h, 1e-12);
		}
	}
	sim_free(s);
}

/* The per-column mean feed displacement (sim_column_displacement,
 * docs/MODEL.md "Observables": xi_k(t) - xi_k(0)) on a machine that rocks
 * (l2 = 0.9 m: five integrated columns): zero for every column at t = 0,
 * and, every column holding L elements, their mean is the whole feed's
 * displacement to round-off at every time. Columns counted from the first
 * column's origin would stand 0.4 m apart. */
static void column_displacements_from_their_own_origins(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "l2", "0.9");
	sim *s = make(&u);
	int K = sim_columns(s);
	assert_int_equal(K, 5);
	assert_false(status(s).reductions & SIM_RED_SYMMETRIC);
	for (int i = 0; i < 3; i++) {
		advance(s, 0.25 * i);
		double cd[5], mean = 0.0;
		sim_column_displacement(s, cd);
		for (int c = 0; c < K; c++) {
			if (i == 0)
				assert_close(cd[c], 0.0, 0.0);
			mean += cd[c] / K;
		}
		sim_status st = status(s);
		assert_close(mean, st.feed_displacement, 1e-12);
		if (i > 0)
			assert_true(fabs(st.feed_displacement) > 1e-3);
	}
	sim_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(rebound_speed_is_R_times_impact),
		cmocka_unit_test(beta_sets_and_reverses_direction),
		cmocka_unit_test(mirror_symmetry_with_feed),
		cmocka_unit_test(reduction_agrees_with_full_model),
		cmocka_unit_test(full_model_settles_through_the_reduction),
		cmocka_unit_test(energy_balance_with_feed),
		cmocka_unit_test(regularised_slide_slows_as_tanh),
		cmocka_unit_test(deck_points_from_their_rest),
		cmocka_unit_test(column_displacements_from_their_own_origins),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
