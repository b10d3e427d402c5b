/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_model_check.c - sim_model_check: the model error of a scene from the
 * DEM map compiled in (tests/bench/results/model_check.csv, docs/dem.md
 * "Model error"). Known answers from that table: at a map point the error
 * is |v_column - v_DEM| plus the DEM's seed spread; between points it is
 * interpolated in beta; the measured angles' bounds are inside, beyond them
 * is not checked; another depth, machine or contact is not checked and the
 * note names the nearest checked point; no column feed, no check.
 */
#include "testutil.h"

/* the table's rows at 30, 137 and 150 deg cw (v_dem, v_dem_sd, v_column) */
#define D30 (0.133669 - 0.131351)
#define SD30 0.00102
#define D137 (0.130244 - 0.130188)
#define SD137 0.000717
#define D150 (0.138111 - 0.13251)
#define SD150 0.0024

static setup bed4(void)
{
	setup u;
	assert_int_equal(sim_preset("liggghts-bed4", &u.p, &u.sc, &u.m), SIM_OK);
	return u;
}

static int check(setup *u, sim_model_error *me)
{
	return sim_model_check(&u->p, &u->sc, me);
}

static void at_map_points_and_between(void **state)
{
	(void)state;
	sim_model_error me;
	setup u = bed4();
	set(&u, "beta", "30");
	assert_int_equal(check(&u, &me), 1);
	assert_true(me.checked);
	assert_close(me.error, D30 + SD30, 1e-12);
	assert_close(me.error_uncertainty, SD30, 1e-12);
	assert_non_null(strstr(me.note, "DEM check: within ±0.003 m/s here"));
	set(&u, "beta", "150");
	assert_int_equal(check(&u, &me), 1);
	assert_close(me.error, D150 + SD150, 1e-12);
	assert_non_null(strstr(me.note, "±0.008 m/s"));
	/* midway between 137 and 150: the means, and half the change of
	 * |v_column - v_DEM| across them as the interpolation's share */
	set(&u, "beta", "143.5");
	assert_int_equal(check(&u, &me), 1);
	assert_close(me.error, (D137 + D150) / 2 + (SD137 + SD150) / 2, 1e-12);
	assert_close(me.error_uncertainty, (SD137 + SD150) / 2 + (D150 - D137) / 2, 1e-12);
}

static void bounds_included_and_beyond(void **state)
{
	(void)state;
	sim_model_error me;
	setup u = bed4();
	set(&u, "beta", "165");
	assert_int_equal(check(&u, &me), 1);
	set(&u, "beta", "15");
	assert_int_equal(check(&u, &me), 1);
	set(&u, "beta", "14");
	assert_int_equal(check(&u, &me), 0);
	assert_false(me.checked);
	assert_true(isnan(me.error));
	assert_string_equal(me.note, "not checked against DEM at beta 14 deg cw: checked 15-165 "
				     "deg cw (4 layers, liggghts-bed4)");
	set(&u, "rotation", "ccw");
	set(&u, "beta", "170");
	assert_int_equal(check(&u, &me), 0);
	assert_non_null(strstr(me.note, "beta 170 deg ccw"));
}

static void other_scenes_name_the_nearest(void **state)
{
	(void)state;
	sim_model_error me;
	setup u = bed4();
	set(&u, "layers", "16");
	assert_int_equal(check(&u, &me), 0);
	assert_string_equal(me.note, "not checked against DEM for 16-layer beds: nearest checked "
				     "bed is 4 layers, liggghts-bed4");
	u = bed4();
	set(&u, "omega_ss", "140");
	assert_int_equal(check(&u, &me), 0);
	assert_non_null(strstr(me.note, "omega_ss = 140 rad/s"));
	u = bed4();
	set(&u, "k_c", "1e7");
	assert_int_equal(check(&u, &me), 0);
	assert_non_null(strstr(me.note, "k_c differs"));
	/* the preset itself: one plain sentence */
	setup c = preset_defaults();
	assert_int_equal(check(&c, &me), 0);
	assert_string_equal(me.note, "czubak2016's column model is not checked against DEM "
				     "(checked: 4 layers, liggghts-bed4)");
	set(&c, "layers", "2");
	set(&c, "beta", "150");
	assert_int_equal(check(&c, &me), 0);
	/* the controls' ramps and the coupling are not part of the check */
	u = bed4();
	set(&u, "beta_rate", "5");
	set(&u, "feed_coupling", "false");
	assert_int_equal(check(&u, &me), 1);
}

static void no_column_feed(void **state)
{
	(void)state;
	sim_model_error me;
	setup u = bed4();
	set(&u, "feed", "false");
	assert_int_equal(check(&u, &me), -1);
	assert_false(me.checked);
	set(&u, "feed", "true");
	set(&u, "feed_model", "liggghts");
	assert_int_equal(check(&u, &me), -1);
	assert_non_null(strstr(me.note, "LIGGGHTS"));
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(at_map_points_and_between),
		cmocka_unit_test(bounds_included_and_beyond),
		cmocka_unit_test(other_scenes_name_the_nearest),
		cmocka_unit_test(no_column_feed),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
