/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_decimal.c - the rule for a number given as text (core/decimal.h):
 * a plain decimal number is read, anything strtod would also take
 * (hexadecimal, inf, nan, spaces, a trailing 'e') is refused, and the
 * settings' text form (sim_set_user_str) follows the same rule.
 */
#include "testutil.h"
#include "decimal.h"

static void reads_plain_decimals(void **state)
{
	(void)state;
	static const struct {
		const char *text;
		double value;
	} good[] = {
		{"1", 1},	 {"-2.5", -2.5}, {"1e-3", 1e-3}, {".5", 0.5},	 {"5.", 5},
		{"+1", 1},	 {"-0", 0},	 {"1E3", 1000},	 {"2.5e+2", 250}, {"007", 7},
		{"1e-400", 0}, /* below the smallest double: 0, as strtod rounds it */
	};
	for (size_t i = 0; i < sizeof good / sizeof good[0]; i++) {
		double v = -99;
		if (!sim_decimal(good[i].text, &v))
			fail_msg("'%s' refused", good[i].text);
		assert_true(v == good[i].value);
	}
}

static void refuses_everything_else(void **state)
{
	(void)state;
	static const char *const bad[] = {
		"0x10", "0x1p4", "0X1A", " 1", "1 ",	 "",	"1e",	   "1e+", "nan",
		"NAN",	"inf",	 "-inf", "infinity", "1,5", ".",  "-",	   "+",	  "e5",
		"--1",	"+-1",	 "1..2", "1.2.3",    "1e5x", "1e999", "\t1", "1\n", "１",
	};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		double v = -99;
		if (sim_decimal(bad[i], &v))
			fail_msg("'%s' read as %g", bad[i], v);
		assert_true(v == -99); /* unchanged */
	}
	double v = -99;
	assert_false(sim_decimal(NULL, &v));
}

static void reads_a_span(void **state)
{
	(void)state;
	double v = 0;
	/* the number a longer text starts with */
	assert_int_equal(sim_decimal_len("2.5:7", 5), 3);
	assert_int_equal(sim_decimal_len("1e:7", 4), 1);
	assert_int_equal(sim_decimal_len("0x10", 4), 1);
	assert_int_equal(sim_decimal_len("x1", 2), 0);
	assert_int_equal(sim_decimal_len("123", 2), 2); /* at most n read */
	assert_true(sim_decimal_n("2.5:7", 3, &v) && v == 2.5);
	/* a span that cuts a number short is not that number */
	assert_false(sim_decimal_n("123", 2, &v));
	assert_false(sim_decimal_n("1e5", 1, &v));
	assert_false(sim_decimal_n("1", 0, &v));
}

static void settings_text_follows_the_rule(void **state)
{
	(void)state;
	setup u = preset();
	char msg[200];
	double before = u.p.beta;
	static const char *const bad[] = {"0x1e", " 30", "30 ", "0x1p4", "nan", "inf"};
	for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
		assert_int_equal(sim_set_user_str(&u.p, &u.sc, &u.m, "beta", bad[i], msg, sizeof msg),
				 SIM_EPARAM);
		assert_string_equal(msg, "beta must be a finite number in [0, 180] deg");
		assert_true(u.p.beta == before);
	}
	set(&u, "beta", "+30");
	assert_close(u.p.beta, 30 * RAD_PER_DEG, 1e-15);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(reads_plain_decimals),
		cmocka_unit_test(refuses_everything_else),
		cmocka_unit_test(reads_a_span),
		cmocka_unit_test(settings_text_follows_the_rule),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
