/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_plural.c - the word a problem's detail puts after a count
 * (api/api.h): api_plural for a count, api_plural_g for a figure as the
 * detail prints it with %.<digits>g, singular exactly where the printed
 * figure reads "1" ("this session needs 1 core").
 */
#include "testutil.h"
#include "api.h"

static void a_count(void **state)
{
	(void)state;
	assert_string_equal(api_plural(1, "", "s"), "");
	assert_string_equal(api_plural(0, "", "s"), "s");
	assert_string_equal(api_plural(2, "is", "are"), "are");
	assert_string_equal(api_plural(0.9996, "", "s"), "s"); /* a count as it is */
}

static void a_figure_as_printed(void **state)
{
	(void)state;
	static const struct {
		double n;
		int digits;
		const char *word;
	} cases[] = {
		{1, 3, ""},	    {0.9996, 3, ""},  {1.0004, 3, ""},  {0.9994, 3, "s"},
		{1.0006, 3, ""},  {1.006, 3, "s"},   {0.5, 3, "s"},	{0, 3, "s"},
		{2, 3, "s"},	    {-1, 3, "s"},	{1.0000001, 6, ""}, {1.00001, 6, "s"},
		{1e-300, 3, "s"},
	};
	for (size_t i = 0; i < sizeof cases / sizeof cases[0]; i++) {
		const char *got = api_plural_g(cases[i].n, cases[i].digits, "", "s");
		if (strcmp(got, cases[i].word) != 0)
			fail_msg("%.17g at %d digits: \"core%s\", expected \"core%s\"", cases[i].n,
				 cases[i].digits, got, cases[i].word);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(a_count),
		cmocka_unit_test(a_figure_as_printed),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
