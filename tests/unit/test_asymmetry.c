/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_asymmetry.c - the symmetric reduction (alpha dropped, one column
 * for K; docs/MODEL.md "Model only what a scene needs") is taken on the
 * symmetric machine only: h = 0, l1 = l2, the axle at G and mirrored
 * eliminators (masses, springs, dampers, guide points). A machine that
 * breaks any one of these conditions rocks, and the engine must integrate
 * alpha there by itself; tests/mutate.sh plants the faults this catches.
 */
#include "testutil.h"

/* One condition of the symmetric machine broken: the setting and its
 * value (user units). */
static const char *const breaks[][2] = {
	{"h", "0.1"},      {"l2", "0.9"},      {"w_x", "0.05"},     {"w_y", "0.05"},
	{"m2", "19"},      {"k_s2", "450000"}, {"b_s2", "600"},     {"p2_x", "0.35"},
	{"p2_y", "0.05"},
};

/* Each broken condition alone: the engine keeps alpha by itself, so the
 * defaults (trough_rotation = false) integrate the very model that
 * trough_rotation = true asks for and give its transport velocity to the
 * last bit (1 s, the defaults' steady start and dem). The reduction taken
 * on one of these machines gives another velocity: at b_s2 = 600 N s/m
 * (the dampers unequal, so their reactions turn the trough) 0.135 m/s
 * where the rocking trough's is 0.078 m/s (convsim run, 4 s). */
static void asymmetric_machines_keep_alpha(void **state)
{
	(void)state;
	for (size_t i = 0; i < sizeof breaks / sizeof breaks[0]; i++) {
		setup u = preset_defaults();
		set(&u, breaks[i][0], breaks[i][1]);
		sim_status own = run_status(&u, 1.0);
		set(&u, "trough_rotation", "true");
		sim_status full = run_status(&u, 1.0);
		if (own.reductions & SIM_RED_SYMMETRIC)
			fail_msg("%s=%s: the symmetric reduction taken", breaks[i][0], breaks[i][1]);
		assert_int_equal(own.n_dof, full.n_dof);
		assert_true(isfinite(full.transport_velocity));
		if (!(own.transport_velocity == full.transport_velocity))
			fail_msg("%s=%s: v %.17g without trough_rotation, %.17g with it",
				 breaks[i][0], breaks[i][1], own.transport_velocity,
				 full.transport_velocity);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(asymmetric_machines_keep_alpha),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
