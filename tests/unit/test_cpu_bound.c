/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_cpu_bound.c - the calling thread's CPU bound on the calls that run
 * long in one piece (core/cpu_bound.c): sim_new_bounded stops a steady
 * start's settling past its deadline with SIM_ECPU, how far it settled and
 * nothing built, within a few ms of CPU of the deadline, through the full
 * model's settling (dopri5) and the symmetric reduction's (dem, a rocking
 * trough); a deadline not reached changes nothing, bit for bit; and
 * sim_advance_bounded stops short of t_end without freezing the instance,
 * which goes on from there; sim_measure_bounded stops its runs and their
 * shadows.
 */
#include "testutil.h"

/* CPU s past its deadline a bounded call may stop: the stride's
 * CPU_READ_S (1 ms) twice over, and a loaded machine's slack. */
#define LATE 0.01

static setup dopri5(void)
{
	setup u = preset_defaults();
	set(&u, "method", "dopri5");
	return u;
}

/* The default scene with dopri5 settles for seconds (docs/load.md "What
 * settling costs": 4.35 CPU s); a bound of 0.05 CPU s stops it there. */
static void settling_stops_at_its_deadline(void **state)
{
	(void)state;
	setup u = dopri5();
	char msg[200] = "";
	int err = SIM_OK;
	double settled = -1, limit = 0.05, cpu0 = sim_thread_cpu();
	sim *s = sim_new_bounded(&u.p, &u.sc, &u.m, cpu0 + limit, &settled, &err, msg,
				 sizeof msg);
	double spent = sim_thread_cpu() - cpu0;
	assert_null(s);
	assert_int_equal(err, SIM_ECPU);
	assert_string_equal(sim_strerror(SIM_ECPU), "stopped at the caller's CPU limit");
	assert_true(strstr(msg, "the settling stopped at the CPU limit") != NULL);
	assert_true(settled > 0.0 && settled < u.sc.settle);
	if (!(spent >= limit && spent < limit + LATE))
		fail_msg("stopped after %.4g CPU s, the limit %.3g", spent, limit);
}

/* A deadline already passed stops the symmetric reduction's settling (a
 * rocking trough on the symmetric machine settles through it, sim.c) at
 * its first read of the clock, after one step. */
static void reduced_settling_stops_too(void **state)
{
	(void)state;
	setup u = preset_defaults();
	u.sc.trough_rotation = 1;
	char msg[200] = "";
	int err = SIM_OK;
	double settled = -1;
	sim *s = sim_new_bounded(&u.p, &u.sc, &u.m, sim_thread_cpu(), &settled, &err, msg,
				 sizeof msg);
	assert_null(s);
	assert_int_equal(err, SIM_ECPU);
	assert_true(strstr(msg, "the settling stopped at the CPU limit") != NULL);
	assert_true(settled > 0.0 && settled < 0.01);
}

/* A deadline not reached: the instance sim_new builds, bit for bit, and
 * all of scene.settle settled; so is an advance under one. */
static void a_deadline_not_reached_changes_nothing(void **state)
{
	(void)state;
	setup u = preset_defaults();
	char msg[200] = "";
	int err = SIM_OK;
	double settled = -1;
	sim *a = sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg);
	sim *b = sim_new_bounded(&u.p, &u.sc, &u.m, sim_thread_cpu() + 60.0, &settled, &err, msg,
				 sizeof msg);
	assert_non_null(a);
	assert_non_null(b);
	assert_true(fabs(settled - u.sc.settle) < 1e-9);
	assert_int_equal(sim_advance(a, 0.2), SIM_OK);
	assert_int_equal(sim_advance_bounded(b, 0.2, sim_thread_cpu() + 60.0), SIM_OK);
	sim_status sa, sb;
	sim_get_status(a, &sa);
	sim_get_status(b, &sb);
	assert_memory_equal(sa.q, sb.q, sizeof sa.q);
	assert_memory_equal(sa.qd, sb.qd, sizeof sa.qd);
	assert_true(sa.steps == sb.steps && sa.feed_displacement == sb.feed_displacement);
	sim_free(a);
	sim_free(b);
}

/* An advance past its deadline stops a whole step short of t_end,
 * observed there, not frozen: the next call reaches t_end. */
static void advance_stops_and_goes_on(void **state)
{
	(void)state;
	setup u = dopri5();
	u.sc.start = SIM_START_REST; /* no settling: the advance is the work */
	char msg[200] = "";
	int err = SIM_OK;
	sim *s = sim_new(&u.p, &u.sc, &u.m, &err, msg, sizeof msg);
	assert_non_null(s);
	double cpu0 = sim_thread_cpu(), limit = 0.02;
	assert_int_equal(sim_advance_bounded(s, 1.0, cpu0 + limit), SIM_ECPU);
	double spent = sim_thread_cpu() - cpu0;
	if (!(spent >= limit && spent < limit + LATE))
		fail_msg("stopped after %.4g CPU s, the limit %.3g", spent, limit);
	sim_status st;
	sim_get_status(s, &st);
	assert_true(st.t > 0.0 && st.t < 1.0 && st.t == st.t_int);
	assert_string_equal(sim_last_error(s), "");
	double t = st.t + 1e-3;
	assert_int_equal(sim_advance(s, t), SIM_OK);
	sim_get_status(s, &st);
	assert_true(st.t == t);
	sim_free(s);
}

/* A measurement under a deadline: stopped (dem, its shadow beside it, and
 * dopri5 in its settling) with SIM_ECPU near the deadline; one not
 * reached measures what sim_measure does, bit for bit. */
static void measure_stops_and_one_within_is_the_same(void **state)
{
	(void)state;
	setup u = preset_defaults();
	double t_end = u.sc.transient + 8.0, limit = 0.005;
	char msg[200] = "";
	sim_measurement a, b;
	for (int k = 0; k < 2; k++) {
		if (k)
			u = dopri5();
		double cpu0 = sim_thread_cpu();
		int e = sim_measure_bounded(&u.p, &u.sc, &u.m, t_end, cpu0 + limit, &a, msg,
					    sizeof msg);
		double spent = sim_thread_cpu() - cpu0;
		assert_int_equal(e, SIM_ECPU);
		if (!(spent >= limit && spent < limit + LATE))
			fail_msg("%s stopped after %.4g CPU s, the limit %.3g", u.m.name, spent, limit);
	}
	u = preset_defaults();
	assert_int_equal(sim_measure(&u.p, &u.sc, &u.m, t_end, &a, msg, sizeof msg), SIM_OK);
	assert_int_equal(sim_measure_bounded(&u.p, &u.sc, &u.m, t_end, sim_thread_cpu() + 60.0,
					     &b, msg, sizeof msg),
			 SIM_OK);
	assert_true(a.transport_velocity == b.transport_velocity && a.uncertainty == b.uncertainty &&
		    a.step_error == b.step_error && a.refinements == b.refinements);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(settling_stops_at_its_deadline),
		cmocka_unit_test(reduced_settling_stops_too),
		cmocka_unit_test(a_deadline_not_reached_changes_nothing),
		cmocka_unit_test(advance_stops_and_goes_on),
		cmocka_unit_test(measure_stops_and_one_within_is_the_same),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
