/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_rate_memo.c - the machine's fastest rate (model_machine_rate, which
 * bounds every fixed step) is kept per thread for the last few machines
 * asked (core/setup.c). Whatever the order the machines are asked in, each
 * answer is the one a thread that never asked before computes: a kept
 * answer is never another machine's.
 */
#include <pthread.h>

#include "model.h"
#include "testutil.h"

#define MACHINES 7

/* Machine i: the preset with its eliminators' masses and the unbalance's
 * eccentricity changed, beta and rotation apart (not in the key). */
static setup machine(int i)
{
	setup u = preset_defaults();
	char v[32];
	snprintf(v, sizeof v, "%g", 1.0 + 0.5 * i);
	set(&u, "m1", v);
	snprintf(v, sizeof v, "%g", 0.02 + 0.004 * (i % 3));
	set(&u, "e", v);
	return u;
}

/* Each machine's rate on a thread of its own: nothing kept before. */
static void *fresh(void *arg)
{
	setup u = machine((int)(intptr_t)arg);
	double *r = malloc(sizeof *r);
	*r = model_machine_rate(&u.p, &u.sc);
	return r;
}

static void answers_are_each_machines_own(void **state)
{
	(void)state;
	double ref[MACHINES];
	for (int i = 0; i < MACHINES; i++) {
		pthread_t t;
		void *r;
		assert_int_equal(pthread_create(&t, NULL, fresh, (void *)(intptr_t)i), 0);
		assert_int_equal(pthread_join(t, &r), 0);
		ref[i] = *(double *)r;
		free(r);
		if (i > 0)
			assert_true(ref[i] != ref[i - 1]); /* the machines differ */
	}
	/* more machines than are kept, asked in an order that hits and misses
	 * (each twice in a row, back and forth, a beta and rotation change) */
	static const int order[] = {0, 0, 1, 2, 1, 3, 4, 5, 6, 0, 6, 5, 4, 3, 2, 1, 0, 3, 3, 6, 1};
	for (size_t k = 0; k < sizeof order / sizeof *order; k++) {
		setup u = machine(order[k]);
		if (k % 2) {
			set(&u, "beta", "123");
			set(&u, "rotation", "ccw");
		}
		double r = model_machine_rate(&u.p, &u.sc);
		if (r != ref[order[k]])
			fail_msg("ask %zu, machine %d: %.17g, computed alone %.17g", k, order[k], r,
				 ref[order[k]]);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(answers_are_each_machines_own),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
