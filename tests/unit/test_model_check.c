/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_model_check.c - sim_model_check: the model error of a scene from the
 * DEM map compiled in (tests/bench/results/model_check.csv, docs/dem.md
 * "Model error"). Known answers from that table: at a map point the error
 * is |v_column - v_DEM| plus the DEM's seed spread; between points it is
 * interpolated in beta; the measured angles' bounds are inside, beyond them
 * is not checked; another depth, machine or contact is not checked and the
 * note names the nearest checked point; no column feed, no check.
 * sim_feed_pick (feed_model auto): column where that error plus its
 * uncertainty is within model_tol, bounds included; else LIGGGHTS within
 * its limit; else none, naming model_tol and the smallest that fits.
 */
#include <pthread.h>

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
	/* at 140, w = 3/13 of the way from 137 to 150: weighted toward 137's
	 * row (the midway above cannot tell the weights apart), the
	 * interpolation's share 2 w times half the change (rounded to 0.01
	 * um/s) */
	double w = 3.0 / 13.0;
	set(&u, "beta", "140");
	assert_int_equal(check(&u, &me), 1);
	assert_close(me.error, (1 - w) * (D137 + SD137) + w * (D150 + SD150), 1e-8);
	assert_close(me.error_uncertainty, (1 - w) * SD137 + w * SD150 + w * (D150 - D137), 1e-8);
	/* anywhere between: rounded to 0.01 um/s, so JSON prints no float noise */
	set(&u, "beta", "141.3");
	assert_int_equal(check(&u, &me), 1);
	assert_true(me.error > 0 && me.error_uncertainty > 0);
	assert_true(fabs(me.error * 1e8 - round(me.error * 1e8)) < 1e-6);
	assert_true(fabs(me.error_uncertainty * 1e8 - round(me.error_uncertainty * 1e8)) < 1e-6);
	char buf[64];
	snprintf(buf, sizeof buf, "%.15g", me.error);
	assert_true(strtod(buf, NULL) == me.error && strlen(buf) <= 10);
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
	/* the preset as it is at a depth the map has not: the nearest depth
	 * of its entries (2 and 4 are as near; the first in the table) */
	setup c = preset_defaults();
	set(&c, "layers", "3");
	assert_int_equal(check(&c, &me), 0);
	assert_string_equal(me.note, "not checked against DEM for 3-layer beds: nearest checked "
				     "bed is 2 layers, czubak2016 against glass");
	/* another machine: the nearest depth's entry names it */
	set(&c, "layers", "2");
	set(&c, "omega_ss", "140");
	assert_int_equal(check(&c, &me), 0);
	assert_string_equal(me.note, "not checked against DEM at omega_ss = 140 rad/s: the DEM "
				     "map's machine is czubak2016's (2 layers, czubak2016 against "
				     "glass)");
	/* the controls' ramps and the coupling are not part of the check */
	u = bed4();
	set(&u, "beta_rate", "5");
	set(&u, "feed_coupling", "false");
	assert_int_equal(check(&u, &me), 1);
}

/* the table's rows of the preset as it is, 2 layers, 150 deg cw: glass
 * and wheat (v_column, v_dem, v_dem_sd) */
#define G150 (-0.0739112 + 0.103018 + 0.0016)
#define W150 (-0.0739112 + 0.0955908 + 0.00427)

/* The preset as it is, checked against each material's bed at its depth:
 * the larger error, the note naming both. */
static void the_preset_against_each_material(void **state)
{
	(void)state;
	sim_model_error me;
	setup c = preset_defaults();
	set(&c, "layers", "2");
	set(&c, "beta", "150");
	assert_int_equal(check(&c, &me), 1);
	assert_true(G150 > W150);
	assert_close(me.error, G150, 1e-12);
	assert_close(me.error_uncertainty, 0.0016, 1e-12);
	assert_string_equal(me.note, "DEM check: within ±0.031 m/s here (czubak2016 against glass, "
				     "2 layers; against wheat ±0.026)");
	/* its mirror image, 30 deg ccw: the same distances */
	sim_model_error mm;
	set(&c, "beta", "30");
	set(&c, "rotation", "ccw");
	assert_int_equal(check(&c, &mm), 1);
	assert_close(mm.error, me.error, 1e-12);
	assert_string_equal(mm.note, me.note);
}

static void assert_same_error(const sim_model_error *a, const sim_model_error *b)
{
	assert_int_equal(a->checked, b->checked);
	assert_true(a->error == b->error || (isnan(a->error) && isnan(b->error)));
	assert_true(a->error_uncertainty == b->error_uncertainty ||
		    (isnan(a->error_uncertainty) && isnan(b->error_uncertainty)));
	assert_string_equal(a->note, b->note);
}

/* The check of u in a thread of its own: no earlier check in it. */
typedef struct {
	setup *u;
	sim_model_error me;
	int rc;
} fresh_check;

static void *fresh_thread(void *arg)
{
	fresh_check *f = arg;
	f->rc = sim_model_check(&f->u->p, &f->u->sc, &f->me);
	return NULL;
}

static int fresh(setup *u, sim_model_error *me)
{
	fresh_check f = {.u = u};
	pthread_t th;
	assert_int_equal(pthread_create(&th, NULL, fresh_thread, &f), 0);
	assert_int_equal(pthread_join(th, NULL), 0);
	*me = f.me;
	return f.rc;
}

/* The entries' matches are kept per thread for the last scene (a closed
 * loop checks it at a new beta every period): a check gives a fresh
 * thread's answer whether it follows one of the same scene at another
 * angle, or one of a scene that differs in a setting, both ways. */
static void the_same_answer_after_any_check(void **state)
{
	(void)state;
	const char *betas[] = {"30", "45", "137", "150", "170"};
	const char *other[][2] = {{"beta", "90"}, {"layers", "16"}, {"omega_ss", "140"},
				  {"beta_rate", "5"}, {"k_c", "1e7"}};
	for (size_t i = 0; i < sizeof betas / sizeof *betas; i++)
		for (size_t j = 0; j < sizeof other / sizeof *other; j++) {
			setup u = bed4(), o = bed4();
			set(&u, "beta", betas[i]);
			set(&o, other[j][0], other[j][1]);
			sim_model_error ref_u, ref_o, me;
			int rc_u = fresh(&u, &ref_u), rc_o = fresh(&o, &ref_o);
			assert_int_equal(check(&o, &me), rc_o);
			assert_same_error(&me, &ref_o);
			assert_int_equal(check(&u, &me), rc_u);
			assert_same_error(&me, &ref_u);
			assert_int_equal(check(&u, &me), rc_u);
			assert_same_error(&me, &ref_u);
			assert_int_equal(check(&o, &me), rc_o);
			assert_same_error(&me, &ref_o);
		}
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

static void pick_at(setup *u, double tol, const sim_feed_liggghts *lg, sim_feed_choice *k,
		    int expect)
{
	char v[32];
	snprintf(v, sizeof v, "%.9g", tol);
	set(u, "model_tol", v);
	assert_int_equal(sim_feed_pick(&u->p, &u->sc, lg, k), expect);
}

static void feed_pick_rule(void **state)
{
	(void)state;
	sim_feed_choice k;
	setup u = bed4();
	set(&u, "beta", "150");
	set(&u, "feed_model", "auto");
	/* at a map point the uncertainty is the seeds' spread */
	double bound = D150 + SD150 + SD150;
	sim_feed_liggghts cheap = {.available = 1, .cost = 1.0, .max_cost = 10.0, .limit = "L"};
	sim_feed_liggghts dear = {.available = 1, .cost = 20.0, .max_cost = 10.0, .limit = "L"};
	pick_at(&u, bound + 1e-6, &cheap, &k, 0);
	assert_int_equal(k.model, SIM_FEED_COLUMN);
	assert_true(isnan(k.expected_cpu_s_per_s));
	assert_non_null(strstr(k.why, "column: DEM check within ±0.008 m/s here"));
	pick_at(&u, bound - 1e-6, &cheap, &k, 0);
	assert_int_equal(k.model, SIM_FEED_EXTERNAL);
	assert_true(k.expected_cpu_s_per_s == 1.0);
	pick_at(&u, bound - 1e-6, &dear, &k, -1);
	assert_string_equal(k.field, "model_tol");
	assert_true(fabs(k.min - bound) < 1e-12);
	assert_non_null(strstr(k.why, "would cost about 20 CPU s a simulated second, over L 10"));
	pick_at(&u, bound - 1e-6, NULL, &k, -1);
	/* the bound is a float: it reads back as written */
	double tol;
	set(&u, "model_tol", "0.005");
	assert_int_equal(sim_get_user(&u.p, &u.sc, &u.m, "model_tol", &tol), SIM_OK);
	assert_true(tol == 0.005);
	/* no bound, no pick; no feed, nothing to pick */
	pick_at(&u, 0, &cheap, &k, -1);
	assert_string_equal(k.field, "model_tol");
	set(&u, "feed", "false");
	pick_at(&u, 0, &cheap, &k, 0);
	assert_int_equal(k.model, SIM_FEED_COLUMN);
	/* auto is never an instance's model */
	set(&u, "feed", "true");
	int err = SIM_OK;
	char msg[160];
	assert_null(sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg));
	assert_int_equal(err, SIM_EPARAM);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(at_map_points_and_between),
		cmocka_unit_test(the_same_answer_after_any_check),
		cmocka_unit_test(bounds_included_and_beyond),
		cmocka_unit_test(other_scenes_name_the_nearest),
		cmocka_unit_test(the_preset_against_each_material),
		cmocka_unit_test(no_column_feed),
		cmocka_unit_test(feed_pick_rule),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
