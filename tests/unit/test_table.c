/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_table.c - core/table.h's number text: sim_fmt_double writes, byte
 * for byte, the first of "%.15g", "%.16g" and "%.17g" that strtod reads
 * back as the value (the three printf calls it replaces, kept here as the
 * reference), for random bit patterns of every exponent, random decimals
 * of 1 to 17 digits (those a person writes, and the ties where the 17
 * digits end in 5 and zeros), and the edges: powers of ten and two, the
 * largest, smallest and subnormal doubles, both zeros, non-finite values.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "table.h"

/* The reference: three printf calls and their strtod. */
static int reference(char *buf, size_t len, double v)
{
	if (!isfinite(v))
		return snprintf(buf, len, "%s", "null");
	if (v == 0.0)
		return snprintf(buf, len, signbit(v) ? "-0" : "0");
	int n = 0;
	for (int prec = 15; prec <= 17; prec++) {
		n = snprintf(buf, len, "%.*g", prec, v);
		if (strtod(buf, NULL) == v)
			break;
	}
	return n;
}

static unsigned long long state = 0x9e3779b97f4a7c15ULL;
static unsigned long long next(void)
{
	state ^= state >> 12;
	state ^= state << 25;
	state ^= state >> 27;
	return state * 2685821657736338717ULL;
}

static int same(double v)
{
	char a[64], b[64];
	int na = sim_fmt_double(a, sizeof a, v, "null"), nb = reference(b, sizeof b, v);
	if (na != nb || strcmp(a, b) != 0) {
		print_message("%.17g: \"%s\" (%d) against \"%s\" (%d)\n", v, a, na, b, nb);
		return 0;
	}
	if (isfinite(v) && na > SIM_FMT_DOUBLE_MAX) { /* the bound --out's estimate takes */
		print_message("%.17g: \"%s\" is longer than SIM_FMT_DOUBLE_MAX\n", v, a);
		return 0;
	}
	return 1;
}

static void random_bit_patterns(void **st)
{
	(void)st;
	int bad = 0;
	for (int i = 0; i < 300000 && bad < 5; i++) {
		unsigned long long u = next();
		double v;
		memcpy(&v, &u, sizeof v);
		bad += !same(v);
	}
	assert_int_equal(bad, 0);
}

static void random_decimals(void **st)
{
	(void)st;
	int bad = 0, ties = 0;
	for (int i = 0; i < 300000 && bad < 5; i++) {
		char text[64];
		int digits = 1 + (int)(next() % 17), exp10 = (int)(next() % 40) - 20;
		unsigned long long mant = 0;
		for (int d = 0; d < digits; d++)
			mant = mant * 10 + (d == digits - 1 && next() % 3 == 0 ? 5 : next() % 10);
		snprintf(text, sizeof text, "%s%llue%d", next() % 2 ? "-" : "", mant, exp10);
		double v = strtod(text, NULL);
		char e17[40];
		snprintf(e17, sizeof e17, "%.16e", fabs(v));
		ties += strncmp(e17 + 17, "50", 2) == 0 || e17[17] == '5';
		bad += !same(v);
	}
	assert_int_equal(bad, 0);
	assert_true(ties > 1000); /* the rounding-tie path was taken */
}

static void edges(void **st)
{
	(void)st;
	const double v[] = {1, -1, 0.1, 0.052, 1e-6, 9.9999999999999995e-07, 123456789012345678.0,
			    1e15, 1e16, 1e17, 1e21, 1e22, 1e23, 9.999999999999999e22, 0.5, 2.5e-5,
			    DBL_MAX, -DBL_MAX, DBL_MIN, DBL_TRUE_MIN, 5e-324, 2.2250738585072009e-308,
			    0.30000000000000004, 1.0 / 3, 2.0 / 3, M_PI, 1e-4, 9.99999e-5, 0.0001,
			    99999.999999999985, 999999999999999.9, 0.15, 0.25, 1.5, 2.5, 1e300, 1e-300};
	for (size_t i = 0; i < sizeof v / sizeof *v; i++)
		assert_true(same(v[i]) && same(-v[i]));
	/* SIM_FMT_DOUBLE_MAX is met: 17 digits, a sign, a three-digit exponent */
	char b[64];
	assert_int_equal(sim_fmt_double(b, sizeof b, -1.0000000000000002e-300, ""),
			 SIM_FMT_DOUBLE_MAX);
	for (int k = -330; k <= 310; k++) {
		double p = pow(10.0, k);
		assert_true(same(p));
		assert_true(same(nextafter(p, 0)));
		assert_true(same(nextafter(p, INFINITY)));
	}
	for (int k = -1074; k <= 1023; k++)
		assert_true(same(ldexp(1.0, k)));
	assert_int_equal(sim_fmt_double(b, sizeof b, 0.0, "null"), 1);
	assert_string_equal(b, "0");
	sim_fmt_double(b, sizeof b, -0.0, "null");
	assert_string_equal(b, "-0");
	sim_fmt_double(b, sizeof b, NAN, "");
	assert_string_equal(b, "");
	sim_fmt_double(b, sizeof b, -INFINITY, "null");
	assert_string_equal(b, "null");
	/* a short buffer: truncated as snprintf, the full length returned */
	char small[4];
	assert_int_equal(sim_fmt_double(small, sizeof small, 0.052, "null"), 5);
	assert_string_equal(small, "0.0");
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(random_bit_patterns),
		cmocka_unit_test(random_decimals),
		cmocka_unit_test(edges),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
