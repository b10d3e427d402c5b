/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_hard_feed.c - hard cases of the core's contact and feed (issue 5):
 * stiff, nearly elastic and nearly plastic contact, frictionless and
 * high-friction feed, 1 and 32 layers, a bouncing element (Zeno
 * accumulation), a block sliding to rest under Coulomb friction, and the
 * machine-feed coupling (one-way, and a heavy feed under dem). Each
 * asserts physics, not only survival. Short horizons and the reduced
 * one-column scene keep the file fast (it also runs under ASan+UBSan in
 * `make check`). The machine's hard cases are in test_hard_machine.c.
 */
#include "model.h"
#include "testutil.h"

/* One element on a still deck (testutil.h), stepped by dem with fine
 * feed sub-steps. */
static setup one_element_dem(void)
{
	setup u = one_element();
	set(&u, "method", "dem");
	set(&u, "dt", "1e-4");
	set(&u, "substeps", "10");
	return u;
}

/* Column 0's deck point (sim_deck_points fills every physical column). */
static double deck_top(const sim *s)
{
	double d[2 * 64];
	sim_deck_points(s, d);
	return d[1];
}

/* The single element of a one-column, one-layer scene. */
static double element_eta(const sim *s)
{
	double xi, eta;
	sim_feed_state(s, &xi, &eta);
	return eta;
}

/* Horizontal position of the element relative to the deck point. */
static double element_xi(const sim *s)
{
	double xi, eta, d[2 * 64];
	sim_feed_state(s, &xi, &eta);
	sim_deck_points(s, d);
	return xi - d[0];
}

/* Drop one element from height h0 above its rest level on a still deck;
 * returns the highest rise above the rest level after the first impact. */
static double drop_and_rebound(setup *u, double h0, double t_end, sim **out)
{
	sim *s = make(u);
	double eta0 = element_eta(s) + h0, v0 = 0.0;
	assert_int_equal(sim_place_feed(s, NULL, &eta0, NULL, &v0), SIM_OK);
	double rest = element_eta(s) - h0, peak = -INFINITY;
	int impacted = 0;
	for (double t = 1e-4; t <= t_end + 1e-12; t += 1e-4) {
		advance(s, t);
		double e = element_eta(s) - rest;
		if (!impacted && e < 0.5 * h0 * 1e-3)
			impacted = 1;
		if (impacted)
			peak = fmax(peak, e);
	}
	assert_true(impacted);
	if (out)
		*out = s;
	else
		sim_free(s);
	return peak;
}

/* Maximum compression of an element dropped from h0 onto a still deck
 * (p = 1, loading k delta): m g (h0 + d) = k d^2 / 2. */
static double impact_compression(const setup *u, double h0)
{
	double W = u->p.m_n * u->p.g, k = u->p.k_c;
	return (W + sqrt(W * W + 2.0 * k * W * h0)) / k;
}

/* The paper's contact law, p = 1: loading stores k d^2 / 2, unloading at
 * R^2 k returns R^2 of it, and gravity acts during the contact, so the
 * rebound apex is h1 = R^2 (h0 + d) - d with d the maximum compression.
 * Nearly elastic (R = 0.99): h1 = 0.9797 h0. Nearly plastic (R = 0.001):
 * no rebound, and the element stays at the maximum compression d, where
 * the set-valued force at zero compression rate, [R^2 k d, k d], holds its
 * weight (a permanent indentation, not the static m g / k). */
static void restitution_extremes(void **state)
{
	(void)state;
	setup u = one_element_dem();
	const double h0 = 0.02;
	set(&u, "R", "0.99");
	double d = impact_compression(&u, h0), h1 = 0.9801 * (h0 + d) - d;
	double peak = drop_and_rebound(&u, h0, 0.2, NULL);
	print_message("R = 0.99: rebound %.6g of %.6g (expected %.6g)\n", peak, h0, h1);
	assert_rel(peak, h1, 2e-3);

	set(&u, "R", "0.001");
	sim *s;
	peak = drop_and_rebound(&u, h0, 0.2, &s);
	double delta = deck_top(s) - element_eta(s);
	print_message("R = 0.001: rise after impact %.3g m, rests at compression %.6g (d = %.6g)\n",
		      peak, delta, d);
	assert_true(peak < 1e-6);
	assert_rel(delta, d, 2e-3);
	advance(s, 0.4);
	assert_close(deck_top(s) - element_eta(s), delta, 1e-10);
	sim_free(s);
}

/* k = 1e8 N/m: dem with a sub-step the contact needs (h = 1e-5 s against a
 * contact period of 0.44 ms) settles, transports and keeps the stack's
 * compressions at m g L / k; its transport velocity stays near the
 * k = 1e6 N/m value (stiffer contact, same hopping). */
static void very_stiff_contact(void **state)
{
	(void)state;
	setup u = reduced_ideal();
	set(&u, "k_c", "1e8");
	set(&u, "method", "dem");
	set(&u, "dt", "1e-4");
	set(&u, "substeps", "10");
	setup soft = u;
	set(&soft, "k_c", "1e6");
	sim *s = make(&u);
	/* at rest before the drive: bottom layer compressed by L m g / k
	 * (sim_feed_state fills every physical column: 5 x 8) */
	double eta[5 * 8];
	sim_feed_state(s, NULL, eta);
	assert_rel(deck_top(s) - eta[0], 8 * u.p.m_n * u.p.g / 1e8, 1e-6);
	advance(s, 1.5);
	sim_status st = status(s);
	double v_soft;
	char msg[200];
	assert_int_equal(measure_v(&soft, 1.5, &v_soft, msg,
					      sizeof msg),
			 SIM_OK);
	print_message("k = 1e8: v = %.5f m/s (k = 1e6: %.5f)\n", st.transport_velocity, v_soft);
	assert_true(st.transport_velocity > 0.5 * v_soft);
	assert_true(st.transport_velocity < 1.5 * v_soft);
	/* no layer sank through its support */
	sim_feed_state(s, NULL, eta);
	assert_true(eta[0] > deck_top(s) - 1e-4);
	sim_free(s);
}

/* mu = 0: no horizontal force reaches the feed, so it does not move along
 * the deck at all; mu = 1 transports, at least as fast as mu = 0.4. */
static void friction_extremes(void **state)
{
	(void)state;
	setup u = reduced_ideal();
	set(&u, "rotation", "ccw"); /* phi' < 0: the run the ordering was seen on */
	set(&u, "dt", "4e-4");
	set(&u, "substeps", "1");
	double v[3];
	const char *mus[3] = {"0", "0.4", "1"};
	for (int i = 0; i < 3; i++) {
		setup w = u;
		set(&w, "mu", mus[i]);
		char msg[200];
		assert_int_equal(measure_v(&w, 2.0, &v[i], msg, sizeof msg),
				 SIM_OK);
	}
	print_message("v(mu = 0, 0.4, 1) = %.3g %.5f %.5f m/s\n", v[0], v[1], v[2]);
	assert_true(fabs(v[0]) < 1e-12);
	assert_true(v[1] > 0.05);
	assert_true(v[2] >= v[1]);
}

/* 1 and 32 layers: the 32-layer stack settles with each contact carrying
 * the weight above it and rests to round-off with the motor off; both
 * transport with the drive on. */
static void layer_counts(void **state)
{
	(void)state;
	setup u = reduced_ideal();
	set(&u, "dt", "2e-4");
	set(&u, "substeps", "2");
	set(&u, "layers", "32");
	setup rest = u;
	set(&rest, "motor_on", "false");
	sim *s = make(&rest);
	double eta0[5 * 32], eta1[5 * 32];
	sim_feed_state(s, NULL, eta0);
	advance(s, 0.5);
	sim_feed_state(s, NULL, eta1);
	double gap0 = deck_top(s) - eta1[0], gap_static = 32.0 * u.p.m_n * u.p.g / u.p.k_c;
	assert_rel(gap0, gap_static, 1e-6);
	for (int j = 0; j < 5 * 32; j++)
		assert_close(eta1[j], eta0[j], 1e-12);
	sim_free(s);
	for (int L = 1; L <= 32; L += 31) {
		setup w = u;
		char buf[16];
		snprintf(buf, sizeof buf, "%d", L);
		set(&w, "layers", buf);
		double v;
		char msg[200];
		assert_int_equal(measure_v(&w, 1.5, &v, msg, sizeof msg),
				 SIM_OK);
		print_message("layers %d: v = %.5f m/s\n", L, v);
		assert_true(v > 0.05 && v < 0.5);
	}
}

/* A bouncing element (R = 0.5): the bounces accumulate (Zeno) and the
 * element comes to rest. A fixed-step run takes exactly its steps; dopri5
 * never steps below its floor, so its step count is bounded by the
 * horizon over the floor step. */
static void bouncing_element(void **state)
{
	(void)state;
	setup u = one_element_dem();
	set(&u, "R", "0.5");
	const double h0 = 0.01, T = 0.25;
	sim *s;
	double peak = drop_and_rebound(&u, h0, T, &s);
	double d = impact_compression(&u, h0), h1 = 0.25 * (h0 + d) - d;
	print_message("dem: first rebound %.5g (expected %.5g)\n", peak, h1);
	assert_rel(peak, h1, 5e-3);
	sim_status st = status(s);
	assert_true(st.steps <= (uint64_t)(T / u.m.dt) + 2);
	/* at rest after the accumulation point */
	double g1 = deck_top(s) - element_eta(s);
	advance(s, T + 0.05);
	assert_close(deck_top(s) - element_eta(s), g1, 1e-10);
	/* resting compression where [R^2 k d, k d] holds m g */
	double W = u.p.m_n * u.p.g / u.p.k_c, gap = deck_top(s) - element_eta(s);
	print_message("dem: rests at compression %.4g (m g / k = %.4g)\n", gap, W);
	assert_true(gap >= W * (1 - 1e-9) && gap <= 4.0 * W * (1 + 1e-9));
	sim_free(s);

	setup dp = u;
	set(&dp, "method", "dopri5");
	set(&dp, "dt", "1e-4");
	s = make(&dp);
	double eta0 = element_eta(s) + h0, v0 = 0.0;
	assert_int_equal(sim_place_feed(s, NULL, &eta0, NULL, &v0), SIM_OK);
	const double Td = 0.2;
	advance(s, Td);
	st = status(s);
	print_message("dopri5: %llu steps to %.2f s\n", (unsigned long long)st.steps, Td);
	assert_true(st.steps <= (uint64_t)(Td / 1e-7) + 1000);
	/* past the Zeno point (about 0.045 + 3 x 0.045 s) it rests, in
	 * contact, between the loading and unloading equilibria */
	gap = deck_top(s) - element_eta(s);
	print_message("dopri5: compression %.4g at %.2f s\n", gap, Td);
	assert_true(gap >= 0.9 * W && gap <= 4.1 * W);
	sim_free(s);
}

/* A block sliding under Coulomb friction from v0 stops after v0 / (mu g)
 * having slid v0^2 / (2 mu g), and then stays put (no chatter). */
static void sliding_block_stops(void **state)
{
	(void)state;
	setup u = one_element_dem();
	const double v0 = 0.5, mu = u.p.mu, g = u.p.g;
	const double t_stop = v0 / (mu * g), dist = v0 * v0 / (2 * mu * g);
	sim *s = make(&u);
	double x0 = element_xi(s);
	assert_int_equal(sim_place_feed(s, NULL, NULL, &v0, NULL), SIM_OK);
	double t_seen = NAN, prev = x0;
	for (double t = 1e-4; t <= 0.3 + 1e-12; t += 1e-4) {
		advance(s, t);
		double x = element_xi(s);
		if (isnan(t_seen) && fabs(x - prev) < 1e-12)
			t_seen = t - 1e-4;
		prev = x;
	}
	double slid = element_xi(s) - x0;
	print_message("stopped at %.5f s (v0/(mu g) = %.5f), slid %.6f m (%.6f)\n", t_seen, t_stop,
		      slid, dist);
	assert_close(t_seen, t_stop, 2e-4);
	assert_rel(slid, dist, 2e-3);
	/* no chatter: still to the last bit over the following 0.2 s */
	double x_end = element_xi(s);
	for (double t = 0.31; t <= 0.5 + 1e-12; t += 0.01) {
		advance(s, t);
		assert_close(element_xi(s), x_end, 1e-12);
	}
	sim_free(s);
}

/* One-way coupling: the feed never acts on the trough. With the motor
 * running, the machine with a one-way feed moves exactly as the machine
 * without feed (same method and step), while the feed transports. */
static void one_way_machine_ignores_the_feed(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "feed_coupling", "false");
	set(&u, "dt", "5e-4");
	setup bare = u;
	set(&bare, "feed", "false");
	sim *a = make(&u), *b = make(&bare);
	for (int k = 1; k <= 100; k++) {
		advance(a, 0.01 * k);
		advance(b, 0.01 * k);
		sim_status x = status(a), y = status(b);
		for (int i = 0; i < 6; i++)
			assert_close(x.q[i], y.q[i], 1e-12 * (1.0 + fabs(y.q[i])));
	}
	assert_true(status(a).feed_displacement > 0.01);
	sim_free(a);
	sim_free(b);
}

/* Contacts far too soft for the feed's weight: at k_c = 1e3 N/m the
 * preset's column of 8 half-kilogram elements rests sum i m_n g / k_c =
 * 36 x 4.905 mm = 17.7 cm into the deck, beyond the feed's 5-cm guard,
 * so sim_validate refuses it naming the least k_c, 36 x 4.905 N / 5 cm =
 * 3531.6 N/m (p = 2: the sum of the roots). Just above it (4e3 N/m:
 * 4.4 cm at rest) the deck's motion presses the column past 5 cm, and the run
 * stops with SIM_EDIVERGED naming that cause (the check runs after every
 * step). */
static void sinking_feed_is_reported(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "start", "rest");
	set(&u, "k_c", "1e3");
	double w = u.p.m_n * u.p.g;
	assert_close(model_column_sag(&u.p, &u.sc), 36.0 * w / 1e3, 1e-12);
	assert_close(sim_k_c_least(&u.p, &u.sc), 36.0 * w / MODEL_SAG_MAX, 1e-12);
	char msg[256] = "";
	assert_int_equal(sim_validate(&u.p, &u.sc, &u.m, msg, sizeof msg), SIM_EPARAM);
	assert_non_null(strstr(msg, "k_c must be at least 3532 N/m"));
	assert_non_null(strstr(msg, "sinks 17.7 cm"));
	set(&u, "p", "2");
	set(&u, "k_c", "1e4");
	double roots = 0.0;
	for (int i = 1; i <= 8; i++)
		roots += sqrt(i * w);
	assert_close(sim_k_c_least(&u.p, &u.sc), pow(roots / MODEL_SAG_MAX, 2.0), 1e-12);
	set(&u, "p", "1");
	set(&u, "k_c", "4e3");
	assert_int_equal(sim_validate(&u.p, &u.sc, &u.m, msg, sizeof msg), SIM_OK);
	sim *s = make(&u);
	int e = sim_advance(s, 1.0);
	const char *err = sim_last_error(s);
	assert_int_equal(e, SIM_EDIVERGED);
	assert_non_null(strstr(err, "sank 5 cm into the deck (contacts too soft"));
	assert_true(status(s).t < 1.0);
	sim_free(s);
}

/* The corrected machine-feed coupling of dem is unstable under added mass
 * (a feed over ~30 % of the machine's mass): dem corrects only light
 * feeds, and the default step follows. A heavy feed (24 layers, 60 kg on a
 * 166 kg machine) at a long macro step rests exactly; a light one gets
 * the long default step, the heavy one the short one. */
static void heavy_feed_coupling_stays_stable(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "trough_rotation", "false");
	set(&u, "motor_on", "false");
	set(&u, "layers", "24");
	set(&u, "dt", "1e-3");
	set(&u, "substeps", "8");
	sim *s = make(&u);
	sim_status a, b;
	assert_rests(s, 1.0, 1e-12, &a, &b);
	sim_free(s);
	/* running: the lagged coupling stays bounded at the long macro step
	 * (the corrector would grow a perturbation ~1.5x per step here) */
	set(&u, "motor_on", "true");
	set(&u, "transient", "0.5");
	s = make(&u);
	advance(s, 1.0);
	sim_status st = status(s);
	assert_true(fabs(st.q[0]) < 0.01 && fabs(st.q[1]) < 0.01);
	assert_true(fabs(st.transport_velocity) < 0.5); /* finite, and no runaway */
	sim_free(s);
	setup light = preset(), heavy = preset();
	set(&heavy, "layers", "24");
	s = make(&light);
	assert_close(status(s).dt, 1.25e-3, 0.0);
	assert_int_equal(status(s).substeps, 5);
	sim_free(s);
	set(&light, "feed_events", "false"); /* the former dem */
	s = make(&light);
	assert_int_equal(status(s).substeps, 16);
	sim_free(s);
	s = make(&heavy);
	assert_close(status(s).dt, 2.5e-5, 0.0);
	assert_int_equal(status(s).substeps, 1);
	sim_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(very_stiff_contact),
		cmocka_unit_test(restitution_extremes),
		cmocka_unit_test(friction_extremes),
		cmocka_unit_test(layer_counts),
		cmocka_unit_test(bouncing_element),
		cmocka_unit_test(sliding_block_stops),
		cmocka_unit_test(one_way_machine_ignores_the_feed),
		cmocka_unit_test(heavy_feed_coupling_stays_stable),
		cmocka_unit_test(sinking_feed_is_reported),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
