/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_deck_load.c - the core's hook for an external feed (feed_model =
 * liggghts, sim_set_deck_load): the load's static answers on the
 * suspension (a force sinks the trough by F / (2 k_y), a moment turns it
 * by M / (k_y (l1^2 + l2^2))), the feed's weight at the start, the energy
 * balance with a load that changes every step, one-way coupling, and the
 * refusals.
 */
#include "testutil.h"

/* The preset with an external feed, the ideal drive switched off (the
 * rotor held, no pendulum), trough rotation integrated, heavily damped
 * so that it settles within a second. */
static setup external_at_rest(void)
{
	setup u = preset();
	set(&u, "feed_model", "liggghts");
	set(&u, "motor_on", "false");
	set(&u, "drive", "ideal");
	set(&u, "trough_rotation", "true");
	set(&u, "start", "rest");
	set(&u, "b_x", "5000");
	set(&u, "b_y", "5000");
	set(&u, "b_s1", "3000");
	set(&u, "b_s2", "3000");
	set(&u, "method", "rk4");
	set(&u, "dt", "1e-4");
	return u;
}

static void load_sinks_and_turns_the_trough(void **state)
{
	(void)state;
	setup u = external_at_rest();
	sim *s = make(&u);
	const double W = 5 * 8 * 0.5 * 9.81, k_y = 75000;
	sim_status a = status(s);
	/* the feed's weight carried from the start, as the column model's */
	assert_close(a.q[1], -W / (2 * k_y), 1e-12);
	assert_close(a.q[2], 0.0, 1e-14);
	assert_int_equal(a.n_dof, 5); /* x, y, alpha, s1, s2: no feed coordinates */
	const double dF = 300, M = 120;
	assert_int_equal(sim_set_deck_load(s, 0.0, -W - dF, M), SIM_OK);
	advance(s, 2.0);
	sim_status b = status(s);
	assert_close(b.q[1], -(W + dF) / (2 * k_y), 1e-9);
	/* to 1e-4: the springs' geometry turns with alpha (second order) */
	assert_rel(b.q[2], M / (k_y * (1.0 + 1.0)), 1e-4);
	/* a horizontal force moves it by F / (2 k_x) */
	assert_int_equal(sim_set_deck_load(s, 500.0, -W, 0.0), SIM_OK);
	advance(s, 4.0);
	b = status(s);
	assert_close(b.q[0], 500.0 / (2 * 75000.0), 1e-9);
	assert_close(b.e_residual, 0.0, 1e-6 * fabs(b.e_dissipated) + 1e-9);
	sim_free(s);
}

/* With the motor on and a load that changes every step (a harmonic force
 * and moment), stored + dissipated - input closes: the load's work is in
 * e_input. */
static void energy_closes_with_a_changing_load(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "feed_model", "liggghts");
	set(&u, "trough_rotation", "true");
	set(&u, "h_d", "0.1");
	set(&u, "method", "rk4");
	set(&u, "dt", "2e-4");
	sim *s = make(&u);
	double e_no_load = 0;
	for (int k = 1; k <= 2500; k++) {
		double t = k * 2e-4, w = 157.0;
		assert_int_equal(sim_set_deck_load(s, 80 * sin(w * t), -196.2 + 150 * cos(w * t), 20 * sin(2 * w * t)),
				 SIM_OK);
		advance(s, t);
	}
	sim_status b = status(s);
	assert_true(fabs(b.e_input) > 10);
	assert_close(b.e_residual, 0.0, 1e-6 * b.e_dissipated);
	/* the load did work: the input differs from the same run without it */
	setup v = u;
	set(&v, "feed_model", "column");
	set(&v, "feed", "false");
	sim *r = make(&v);
	advance(r, 0.5);
	e_no_load = status(r).e_input;
	assert_true(fabs(b.e_input - e_no_load) > 1e-3 * fabs(e_no_load));
	sim_free(r);
	sim_free(s);
}

static void one_way_and_refusals(void **state)
{
	(void)state;
	setup u = external_at_rest();
	set(&u, "feed_coupling", "false");
	sim *s = make(&u);
	assert_close(status(s).q[1], 0.0, 1e-13); /* the weight never reaches the trough */
	assert_int_equal(sim_set_deck_load(s, 0.0, -1000.0, 0.0), SIM_OK);
	advance(s, 0.5);
	assert_close(status(s).q[1], 0.0, 1e-13);
	assert_int_equal(sim_set_deck_load(s, NAN, 0.0, 0.0), SIM_EPARAM);
	assert_int_equal(sim_set_deck_load(s, 0.0, INFINITY, 0.0), SIM_EPARAM);
	sim_free(s);
	setup c = preset();
	s = make(&c);
	assert_int_equal(sim_set_deck_load(s, 0.0, -1.0, 0.0), SIM_EPARAM);
	sim_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(load_sinks_and_turns_the_trough),
		cmocka_unit_test(energy_closes_with_a_changing_load),
		cmocka_unit_test(one_way_and_refusals),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
