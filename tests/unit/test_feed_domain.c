/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_feed_domain.c - sim_feed_validated: the column model's domain as
 * checked against LIGGGHTS beds (docs/dem.md): inside at 1-2 layers, at
 * up to 8 with stiff contacts away from the DEM bed's second peak, and for
 * the preset fitted to a 4-diameter bed; outside beyond, with a reason
 * that names the layers, the angle and the way out; no answer without a
 * column feed.
 */
#include "testutil.h"

static int validated(setup *u, char *why, size_t len)
{
	return sim_feed_validated(&u->p, &u->sc, why, len);
}

static void domain_by_depth_and_stiffness(void **state)
{
	(void)state;
	char why[400];
	setup u = preset();
	assert_int_equal(validated(&u, why, sizeof why), 0); /* 8 layers, soft contacts */
	assert_non_null(strstr(why, "8 layers"));
	assert_non_null(strstr(why, "feed_model=liggghts"));
	set(&u, "layers", "2");
	assert_int_equal(validated(&u, NULL, 0), 1);
	set(&u, "layers", "3");
	assert_int_equal(validated(&u, why, sizeof why), 0);
	set(&u, "k_c", "1e7"); /* k_c / m_n = 2e7 */
	assert_int_equal(validated(&u, NULL, 0), 1);
	set(&u, "layers", "8");
	assert_int_equal(validated(&u, NULL, 0), 1);
	set(&u, "layers", "9");
	assert_int_equal(validated(&u, NULL, 0), 0);
	/* stiff contacts, but the DEM bed's second peak (150 cw, 30 ccw) */
	static const struct { const char *rotation, *beta; int inside; } angles[] = {
		{"cw", "150", 0}, {"cw", "137", 1}, {"ccw", "30", 0}, {"ccw", "60", 1}, {"cw", "38", 1}};
	set(&u, "layers", "8");
	for (size_t i = 0; i < sizeof angles / sizeof angles[0]; i++) {
		set(&u, "rotation", angles[i].rotation);
		set(&u, "beta", angles[i].beta);
		assert_int_equal(validated(&u, why, sizeof why), angles[i].inside);
	}
	set(&u, "beta", "150");
	assert_int_equal(validated(&u, why, sizeof why), 0);
	assert_non_null(strstr(why, "beta 150 deg cw"));
	set(&u, "beta", "38");
	set(&u, "k_c", "9.9e6");
	assert_int_equal(validated(&u, NULL, 0), 0);
	/* the preset fitted to a 4-diameter bed */
	setup f;
	assert_int_equal(sim_preset("liggghts-bed4", &f.p, &f.sc, &f.m), SIM_OK);
	assert_int_equal(f.sc.layers, 4);
	assert_int_equal(validated(&f, NULL, 0), 1);
	set(&f, "layers", "5");
	assert_int_equal(validated(&f, NULL, 0), 0);
	/* no column feed: no answer */
	setup n = preset();
	set(&n, "feed", "false");
	assert_int_equal(validated(&n, NULL, 0), -1);
	set(&n, "feed", "true");
	set(&n, "feed_model", "liggghts");
	assert_int_equal(validated(&n, NULL, 0), -1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(domain_by_depth_and_stiffness),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
