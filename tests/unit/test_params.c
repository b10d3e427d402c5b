/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_params.c - parameter validation: every setting has a unit and a
 * range; bad values (negative or zero masses, non-finite numbers, sizes
 * that would allocate without bound, unknown names) are refused with a
 * message naming the setting and its range, and change nothing.
 */
#include "testutil.h"
#include "table.h"

static void refuses_out_of_range_with_range_in_message(void **state)
{
	(void)state;
	setup u = preset();
	char msg[200];
	double before = u.p.m1;
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "m1", -1.0, msg, sizeof msg), SIM_EPARAM);
	assert_string_equal(msg, "m1 must be a finite number in [0.001, 10000] kg");
	assert_true(u.p.m1 == before);
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "M_r", 0.0, msg, sizeof msg), SIM_EPARAM);
	assert_string_equal(msg, "M_r must be a finite number in [1, 100000] kg");
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "k_s1", NAN, msg, sizeof msg), SIM_EPARAM);
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "k_s1", INFINITY, msg, sizeof msg), SIM_EPARAM);
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "columns", 1e9, msg, sizeof msg), SIM_EPARAM);
	assert_string_equal(msg, "columns must be an integer in [1, 64]");
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "layers", 2.5, msg, sizeof msg), SIM_EPARAM);
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "beta", 181, msg, sizeof msg), SIM_EPARAM);
	assert_string_equal(msg, "beta must be a finite number in [0, 180] deg");
	assert_int_equal(sim_set_str(&u.p, &u.sc, &u.m, "rotation", "left", msg, sizeof msg),
			 SIM_EPARAM);
	assert_string_equal(msg, "rotation must be one of cw|ccw");
	assert_int_equal(sim_set_str(&u.p, &u.sc, &u.m, "method", "rk45", msg, sizeof msg),
			 SIM_EPARAM);
	assert_string_equal(msg, "method must be one of rk4|dopri5|euler|dem");
	assert_int_equal(sim_set_str(&u.p, &u.sc, &u.m, "dt", "1e-3x", msg, sizeof msg),
			 SIM_EPARAM);
	assert_int_equal(sim_set(&u.p, &u.sc, &u.m, "k_s3", 1.0, msg, sizeof msg), SIM_EUNKNOWN);
	assert_string_equal(msg, "unknown setting 'k_s3'");
	/* nothing changed */
	setup fresh = preset();
	assert_memory_equal(&u.p, &fresh.p, sizeof u.p);
	assert_memory_equal(&u.sc, &fresh.sc, sizeof u.sc);
}

static void converts_units_and_enums(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "beta", "128");
	assert_close(u.p.beta, 128.0 * M_PI / 180.0, 1e-15);
	set(&u, "rotation", "ccw");
	assert_int_equal(u.p.rotation, SIM_CCW);
	set(&u, "drive", "ideal");
	assert_int_equal(u.sc.drive, SIM_DRIVE_IDEAL);
	set(&u, "feed", "false");
	assert_int_equal(u.sc.feed, 0);
	set(&u, "method", "rk4");
	assert_string_equal(u.m.name, "rk4");
	double v;
	assert_int_equal(sim_get_user(&u.p, &u.sc, &u.m, "beta", &v), SIM_OK);
	assert_close(v, 128.0, 1e-12);
	assert_int_equal(sim_get(&u.p, &u.sc, &u.m, "rotation", &v), SIM_OK);
	assert_close(v, 1.0, 0.0);
}

/* Degrees as a person reads them: what goes to SI and comes back through
 * sim_table_user (the trajectories, the CLI, the API) is the number sent,
 * and a beta the model made in mid-ramp (an SI value one ulp off a short
 * decimal's, which the plain quotient shows as 31.48781250000000x) reads
 * with 15 significant digits; a setting without a scale passes untouched. */
static void user_units_come_back_as_written(void **state)
{
	(void)state;
	const double deg[] = {60, 31.4878125, 59.99, 121.9, 0.1, 17.3, 179.999, 1e-7};
	const sim_setting *beta = sim_setting_find("beta");
	assert_non_null(beta);
	int noisy = 0;
	for (size_t i = 0; i < sizeof deg / sizeof deg[0]; i++) {
		double si = sim_setting_to_si(beta, deg[i]);
		assert_true(sim_table_user("beta", si) == deg[i]);
	}
	for (size_t i = 0; i < sizeof deg / sizeof deg[0] - 1; i++) {
		double ramp = nextafter(sim_setting_to_si(beta, deg[i]), 10.0);
		if (sim_setting_from_si(beta, ramp) == deg[i])
			continue; /* one ulp that does not show in degrees */
		assert_true(sim_table_user("beta", ramp) == deg[i]);
		noisy++;
	}
	assert_true(noisy >= 3); /* the rounding is what makes them clean */
	const double e = 0.021500000000000002; /* metres: scale 1, not rounded */
	assert_true(sim_table_user("e", e) == e);
	assert_true(sim_table_user("no_such_setting", 0.1 + 0.2) == 0.1 + 0.2);
	/* the thread keeps its last conversion: the same bits again give the
	 * same degrees, the same bits under another name (or none) are that
	 * name's, and -0 is not 0 */
	double si = sim_setting_to_si(beta, 31.4878125);
	assert_true(sim_table_user("beta", si) == 31.4878125);
	assert_true(sim_table_user("beta", si) == 31.4878125);
	assert_true(sim_table_user("e", si) == si);
	assert_true(sim_table_user("no_such_setting", si) == si);
	assert_true(sim_table_user("beta_rate", si) == 31.4878125);
	assert_true(sim_table_user("beta", 0.0) == 0.0 && !signbit(sim_table_user("beta", 0.0)));
	assert_true(signbit(sim_table_user("beta", -0.0)));
}

static void sim_new_refuses_invalid_sets(void **state)
{
	(void)state;
	setup u = preset();
	u.p.m2 = -3.0; /* written past the checks */
	char msg[200];
	int err = -1;
	assert_null(sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg));
	assert_int_equal(err, SIM_EPARAM);
	assert_string_equal(msg, "m2 must be a finite number in [0.001, 10000] kg");
	u = preset();
	snprintf(u.m.name, sizeof u.m.name, "%s", "magic");
	assert_null(sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg));
	assert_int_equal(err, SIM_EPARAM);
	u = preset();
	u.sc.layers = 100000;
	assert_null(sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg));
	assert_string_equal(msg, "layers must be an integer in [1, 64]");
}

/* sim_preview tells what sim_new builds (the daemon's CPU estimate is made
 * from it before any instance exists): step, sub-steps, reductions,
 * integrated coordinates, feed size, the columns its settling integrates
 * and the feed's mass ratio as the new instance's status, for the preset
 * (symmetric reduction, one column integrated), a rocking trough of 7 x 6
 * (every column integrated, one settled: the symmetric machine's), a
 * scene without feed, an explicit step, the rocking trough on a machine
 * that is not symmetric (every column settled) and a one-way feed (no
 * ratio); and sim_new's refusal with its message. */
static void preview_is_what_sim_new_builds(void **state)
{
	(void)state;
	const int settled[6] = {1, 1, 0, 1, 7, 1};
	for (int k = 0; k < 6; k++) {
		setup u = preset_defaults(); /* the daemon's: a settled start */
		if (k == 1 || k == 4) {
			u.sc.trough_rotation = 1;
			u.sc.columns = 7;
			u.sc.layers = 6;
			u.p.h = k == 4 ? 0.05 : 0.0;
		} else if (k == 2) {
			u.sc.feed = 0;
		} else if (k == 3) {
			u.m.dt = 5e-4;
		} else if (k == 5) {
			u.sc.feed_coupling = 0;
		}
		char msg[200] = "";
		int err = -1, columns = -1, layers = -1;
		sim_status pv, st;
		assert_int_equal(sim_preview(&u.p, &u.sc, &u.m, &pv, &columns, &layers, msg,
					     sizeof msg), SIM_OK);
		sim *s = sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg);
		assert_non_null(s);
		sim_get_status(s, &st);
		assert_true(pv.dt == st.dt);
		assert_int_equal(pv.substeps, st.substeps);
		assert_int_equal(pv.reductions, st.reductions);
		assert_int_equal(pv.n_dof, st.n_dof);
		assert_int_equal(columns, sim_columns(s));
		assert_int_equal(layers, sim_layers(s));
		assert_int_equal(pv.steps, 0); /* nothing was run */
		assert_int_equal(!!(pv.reductions & SIM_RED_SYMMETRIC), k != 1 && k != 4);
		assert_int_equal(pv.settle_columns, st.settle_columns);
		assert_int_equal(pv.settle_columns, settled[k]);
		assert_true(pv.feed_mass_ratio == st.feed_mass_ratio);
		/* the feed's 0.5 kg elements over the machine's 166 kg */
		double feed = u.sc.feed && u.sc.feed_coupling ? 0.5 * u.sc.columns * u.sc.layers : 0;
		assert_true(fabs(pv.feed_mass_ratio - feed / 166.0) < 1e-12);
		sim_free(s);
	}
	setup u = preset_defaults();
	u.p.m2 = -3.0;
	char msg[200];
	int columns = -1, layers = -1;
	sim_status pv;
	assert_int_equal(sim_preview(&u.p, &u.sc, &u.m, &pv, &columns, &layers, msg, sizeof msg),
			 SIM_EPARAM);
	assert_string_equal(msg, "m2 must be a finite number in [0.001, 10000] kg");
	assert_int_equal(columns, 0);
	assert_int_equal(layers, 0);
}

static void every_setting_is_described(void **state)
{
	(void)state;
	size_t n;
	const sim_setting *t = sim_settings(&n);
	assert_true(n > 50);
	setup u = preset();
	for (size_t i = 0; i < n; i++) {
		double v;
		assert_non_null(t[i].doc);
		assert_true(t[i].min <= t[i].max);
		assert_int_equal(sim_get_user(&u.p, &u.sc, &u.m, t[i].name, &v), SIM_OK);
		/* the preset lies inside every range */
		if (!(v >= t[i].min - 1e-9 && v <= t[i].max + 1e-9))
			fail_msg("preset %s = %g outside [%g, %g]", t[i].name, v, t[i].min, t[i].max);
		assert_true(strcmp(t[i].group, "params") == 0 || strcmp(t[i].group, "scene") == 0 ||
			    strcmp(t[i].group, "integrator") == 0);
	}
	size_t nm;
	const sim_method_info *const *mi = sim_methods(&nm);
	assert_int_equal(nm, 4);
	assert_string_equal(mi[0]->name, "rk4");
	assert_int_equal(mi[0]->order, 4);
	assert_string_equal(mi[1]->name, "dopri5");
	assert_int_equal(mi[1]->adaptive, 1);
}

/* The setting "method" offers the registry's integrators, in its order
 * (the list is ODE_REGISTRY's, the names the descriptors'); the default is
 * one of them, and only the split method takes sub-steps and a shadow. */
static void method_choices_are_the_registry(void **state)
{
	(void)state;
	size_t n, nm;
	const sim_setting *t = sim_settings(&n);
	const sim_method_info *const *mi = sim_methods(&nm);
	const sim_setting *method = NULL;
	for (size_t i = 0; i < n; i++)
		if (strcmp(t[i].name, "method") == 0)
			method = &t[i];
	assert_non_null(method);
	char want[128] = "";
	for (size_t i = 0; i < nm; i++) {
		size_t at = strlen(want);
		snprintf(want + at, sizeof want - at, "%s%s", i ? "|" : "", mi[i]->name);
		assert_int_equal(mi[i]->substeps, strcmp(mi[i]->name, "dem") == 0);
		assert_int_equal(mi[i]->shadow, strcmp(mi[i]->name, "dem") == 0);
		assert_true(mi[i]->cost > 0);
	}
	assert_string_equal(method->choices, want);
	assert_string_equal(want, "rk4|dopri5|euler|dem");
	assert_true(method->min == 0 && method->max == (double)nm - 1);
	assert_string_equal(sim_default_method(), "dem");
}

static void errors_have_text(void **state)
{
	(void)state;
	assert_string_equal(sim_strerror(SIM_OK), "ok");
	assert_string_equal(sim_strerror(SIM_EDIVERGED), "simulation diverged");
	assert_string_equal(sim_strerror(999), "unknown error");
	sim_free(NULL);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(refuses_out_of_range_with_range_in_message),
		cmocka_unit_test(converts_units_and_enums),
		cmocka_unit_test(user_units_come_back_as_written),
		cmocka_unit_test(sim_new_refuses_invalid_sets),
		cmocka_unit_test(preview_is_what_sim_new_builds),
		cmocka_unit_test(every_setting_is_described),
		cmocka_unit_test(errors_have_text),
		cmocka_unit_test(method_choices_are_the_registry),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
