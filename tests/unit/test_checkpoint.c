/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_checkpoint.c - checkpoints of an instance (core/checkpoint.c):
 * a restored instance continues bit for bit as the uninterrupted one, for
 * every integrator, across a beta ramp in progress, a rotation change and
 * an estimator restart; a damaged buffer (cut off anywhere, any bit
 * flipped, another version, another model) is refused with
 * SIM_ECHECKPOINT and never crashes; a phase that jumped (what a checkpoint
 * with a right checksum and a wrong estimator gives: found by the fuzz
 * harness tests/fuzz/fuzz_store.c) restarts the estimate instead of
 * counting every period in between.
 */
#include "testutil.h"

#include "sim_int.h" /* the estimator's phase, set as a damaged checkpoint would */

/* Status and feed of an instance, compared bytewise. */
static void assert_same(const sim *a, const sim *b)
{
	sim_status sa = status(a), sb = status(b);
	if (memcmp(&sa, &sb, sizeof sa) != 0)
		fail_msg("status differs: t %.17g / %.17g, x %.17g / %.17g, v %.17g / %.17g", sa.t,
			 sb.t, sa.q[0], sb.q[0], sa.transport_velocity, sb.transport_velocity);
	int n = sim_columns(a) * sim_layers(a);
	assert_int_equal(n, sim_columns(b) * sim_layers(b));
	double xa[SIM_MAX_COLUMNS * 4], ea[SIM_MAX_COLUMNS * 4], xb[SIM_MAX_COLUMNS * 4],
		eb[SIM_MAX_COLUMNS * 4];
	assert_true(n <= SIM_MAX_COLUMNS * 4);
	sim_feed_state(a, xa, ea);
	sim_feed_state(b, xb, eb);
	assert_memory_equal(xa, xb, sizeof(double) * (size_t)n);
	assert_memory_equal(ea, eb, sizeof(double) * (size_t)n);
}

static void *checkpoint_of(const sim *s, size_t *len)
{
	*len = sim_checkpoint_size(s);
	void *buf = malloc(*len);
	assert_non_null(buf);
	assert_int_equal(sim_checkpoint(s, buf, *len), SIM_OK);
	return buf;
}

static sim *restore(const setup *u, const void *buf, size_t len)
{
	char msg[200] = "";
	int err = -1;
	sim *s = sim_restore(&u->p, &u->sc, &u->m, buf, len, &err, msg, sizeof msg);
	if (!s)
		fail_msg("sim_restore: %s", msg);
	assert_int_equal(err, SIM_OK);
	return s;
}

/* Run a to t1 with controls on the way, checkpoint at an observed time
 * between steps (0.3137 s is no step boundary), restore into b, then run
 * both to t2 observed at different rates: they must agree bitwise. */
static void continues_bit_for_bit(const setup *u, double t1, double t2)
{
	sim *a = make(u);
	advance(a, 0.1);
	assert_int_equal(sim_set_beta(a, 80.0 * RAD_PER_DEG, 0.0), SIM_OK);
	advance(a, 0.2);
	sim_restart_transport(a);
	advance(a, t1);
	size_t len;
	void *buf = checkpoint_of(a, &len);
	sim *b = restore(u, buf, len);
	assert_same(a, b); /* at once, at the observed time */
	/* a ramp still running; a rotation change after the restore */
	for (double t = t1; t < t2;) {
		t = fmin(t2, t + 0.05);
		advance(a, t);
		advance(b, t);
		if (fabs(t - 0.5) < 1e-9) {
			assert_int_equal(sim_set_omega_ss(a, 150.0), SIM_OK);
			assert_int_equal(sim_set_omega_ss(b, 150.0), SIM_OK);
		}
	}
	assert_same(a, b);
	free(buf);
	sim_free(a);
	sim_free(b);
}

/* The reduced scene with the motor (the default steady start) and a small
 * feed keeps every integrator quick. */
static setup small(const char *method)
{
	setup u = preset_defaults();
	set(&u, "layers", "2");
	set(&u, "method", method);
	return u;
}

static void dem_continues(void **state)
{
	(void)state;
	setup u = small("dem");
	/* at several moments: the feed in flight (no reaction held) and in
	 * contact */
	for (double t1 = 0.3037; t1 < 0.33; t1 += 0.0051)
		continues_bit_for_bit(&u, t1, 0.6);
	u = preset_defaults(); /* the defaults themselves, full feed */
	continues_bit_for_bit(&u, 0.3137, 0.6);
}

/* A checkpoint taken while the shadow measures the step error (shadow.c:
 * the first 40 periods after an estimate's start), restored and run on
 * past the shadow's window: the error bar at its end is the same to the
 * bit (the shadow is in the checkpoint). Without it the restored instance
 * kept the calibrated term: another transport_velocity_uncertainty. */
static void dem_shadow_continues(void **state)
{
	(void)state;
	setup u = small("dem");
	sim *a = make(&u);
	advance(a, 0.3);
	assert_non_null(a->shadow); /* measuring */
	double until = a->shadow_until;
	size_t len;
	void *buf = checkpoint_of(a, &len);
	sim *b = restore(&u, buf, len);
	assert_non_null(b->shadow);
	assert_same(a, b);
	double t_end = until + 0.5;
	for (double t = 0.3; t < t_end;) {
		t = fmin(t_end, t + 0.25);
		advance(a, t);
		advance(b, t);
		if (t < until) { /* a checkpoint of the restored one, nested again */
			free(buf);
			buf = checkpoint_of(b, &len);
			sim_free(b);
			b = restore(&u, buf, len);
		}
	}
	assert_null(a->shadow); /* its window is over: the error measured */
	assert_true(isfinite(status(a).step_error));
	assert_same(a, b);
	free(buf);
	sim_free(a);
	sim_free(b);
}

static void rk4_continues(void **state)
{
	(void)state;
	setup u = small("rk4");
	continues_bit_for_bit(&u, 0.3137, 0.6);
}

static void euler_continues(void **state)
{
	(void)state;
	setup u = small("euler");
	continues_bit_for_bit(&u, 0.3137, 0.6);
}

static void dopri5_continues(void **state)
{
	(void)state;
	setup u = small("dopri5");
	set(&u, "feed", "false");
	set(&u, "drive", "ideal");
	continues_bit_for_bit(&u, 0.3137, 0.6);
	u = small("dopri5"); /* with feed: sliding modes at the step floor */
	set(&u, "layers", "1");
	set(&u, "start", "rest");
	continues_bit_for_bit(&u, 0.3137, 0.45);
}

/* A checkpoint taken before the estimate's first period boundary (a
 * session stopped or checkpointed within its first rotor period; the
 * estimator has no batch stride yet) restores and continues bit for bit:
 * the restore once refused it as "values out of range", which a daemon
 * restart would have listed as a damaged session. */
static void checkpoint_before_the_first_period(void **state)
{
	(void)state;
	setup u = small("dem");
	sim *a = make(&u);
	advance(a, 0.01);
	assert_int_equal(sim_set_beta(a, 80.0 * RAD_PER_DEG, 0.0), SIM_OK);
	advance(a, 0.02);
	size_t len;
	void *buf = checkpoint_of(a, &len);
	sim *b = restore(&u, buf, len);
	assert_same(a, b);
	advance(a, 0.4);
	advance(b, 0.4);
	assert_same(a, b);
	free(buf);
	sim_free(a);
	sim_free(b);
}

/* A restore does not settle again: it takes no time at all beyond the
 * allocation, and the restored t is the checkpoint's. */
static void restore_does_not_settle(void **state)
{
	(void)state;
	setup u = preset_defaults();
	sim *a = make(&u);
	advance(a, 0.25);
	size_t len;
	void *buf = checkpoint_of(a, &len);
	sim *b = restore(&u, buf, len);
	assert_true(status(b).t == 0.25);
	assert_true(status(b).rhs_evals == status(a).rhs_evals);
	free(buf);
	sim_free(a);
	sim_free(b);
}

/* Every cut, every bit flipped in the header and payload (sampled), and a
 * checkpoint of another model: SIM_ECHECKPOINT, never a crash (run under
 * ASan by make check). */
/* The estimator's phase 1000 periods behind the state's, as a checkpoint
 * with a right checksum and a wrong estimator restores it: the next step
 * must not count 1000 periods (nor walk 1.6e17 of them for a phase of
 * -1e18, which hung the restored session) but start the estimate over. */
static void phase_jump_restarts(void **state)
{
	(void)state;
	setup u = small("rk4");
	sim *a = make(&u);
	advance(a, 0.3);
	sim_status before = status(a);
	assert_true(before.transport_periods >= 1);
	for (int k = 0; k < 2; k++) {
		a->est.psi_prev -= k == 0 ? 1000 * 2 * M_PI : 1e18;
		double t = status(a).t + 0.01;
		advance(a, t);
		sim_status st = status(a);
		assert_true(st.transport_periods < before.transport_periods + 5);
		assert_true(isnan(st.transport_velocity));
	}
	sim_free(a);
}

/* A checkpoint (right checksum) of an instance failed with a code no step
 * gives (found by the checkpoint fuzz harness: sim_advance then answered
 * SIM_EUNKNOWN) is refused, so is a failure without its reason; one failed
 * by divergence with its reason restores failed, and says why. */
static void failure_code_checked(void **state)
{
	(void)state;
	setup u = small("rk4");
	sim *a = make(&u);
	advance(a, 0.05);
	size_t len;
	unsigned char *buf = checkpoint_of(a, &len);
	/* the header (48 bytes), y, y_obs, y_prev, then t_int, t_obs, t_prev
	 * and three counters before the failure code */
	size_t at = 48 + 3 * sizeof(double) * (size_t)a->md.n + 48;
	const int32_t codes[] = {SIM_EUNKNOWN, SIM_EDIVERGED, SIM_EDIVERGED};
	for (int k = 0; k < 3; k++) {
		memcpy(buf + at, &codes[k], sizeof codes[k]);
		/* the reason follows the code and its padding: none (k = 1), one
		 * (k = 2); a failure without its reason is refused */
		const char *why = k == 2 ? "diverged at t = 0.05 s: test" : "";
		memset(buf + at + 8, 0, 160);
		memcpy(buf + at + 8, why, strlen(why));
		uint64_t sum = sim_checksum(buf + 48, len - 48);
		memcpy(buf + 40, &sum, sizeof sum);
		char msg[200];
		int err;
		sim *b = sim_restore(&u.p, &u.sc, &u.m, buf, len, &err, msg, sizeof msg);
		if (k < 2) {
			assert_null(b);
			assert_int_equal(err, SIM_ECHECKPOINT);
		} else {
			assert_non_null(b);
			assert_int_equal(sim_advance(b, 0.1), SIM_EDIVERGED);
			assert_string_equal(sim_last_error(b), "diverged at t = 0.05 s: test");
			sim_free(b);
		}
	}
	free(buf);
	sim_free(a);
}

static void damage_is_refused(void **state)
{
	(void)state;
	setup u = small("dem");
	sim *a = make(&u);
	advance(a, 0.05);
	size_t len;
	unsigned char *buf = checkpoint_of(a, &len);
	unsigned char *copy = malloc(len);
	assert_non_null(copy);
	char msg[200];
	int err;
	for (size_t cut = 0; cut < len; cut += 1 + cut / 16) {
		memcpy(copy, buf, cut);
		sim *b = sim_restore(&u.p, &u.sc, &u.m, copy, cut, &err, msg, sizeof msg);
		assert_null(b);
		assert_int_equal(err, SIM_ECHECKPOINT);
	}
	uint64_t x = 88172645463325252ULL; /* xorshift64 */
	for (int round = 0; round < 400; round++) {
		x ^= x << 13, x ^= x >> 7, x ^= x << 17;
		size_t bit = round < 64 * 8 ? (size_t)round % (len * 8) : (size_t)(x % (len * 8));
		memcpy(copy, buf, len);
		copy[bit / 8] ^= (unsigned char)(1u << (bit % 8));
		sim *b = sim_restore(&u.p, &u.sc, &u.m, copy, len, &err, msg, sizeof msg);
		assert_null(b);
		assert_int_equal(err, SIM_ECHECKPOINT);
	}
	/* the version field: refused by name */
	memcpy(copy, buf, len);
	copy[8] ^= 2;
	assert_null(sim_restore(&u.p, &u.sc, &u.m, copy, len, &err, msg, sizeof msg));
	assert_non_null(strstr(msg, "version"));
	/* another model (more layers): another layout */
	setup v = small("dem");
	set(&v, "layers", "3");
	assert_null(sim_restore(&v.p, &v.sc, &v.m, buf, len, &err, msg, sizeof msg));
	assert_int_equal(err, SIM_ECHECKPOINT);
	assert_non_null(strstr(msg, "layout"));
	/* and the whole buffer still restores */
	sim *b = restore(&u, buf, len);
	assert_same(a, b);
	sim_free(b);
	free(copy);
	free(buf);
	sim_free(a);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(dem_continues),
		cmocka_unit_test(dem_shadow_continues),
		cmocka_unit_test(rk4_continues),
		cmocka_unit_test(euler_continues),
		cmocka_unit_test(dopri5_continues),
		cmocka_unit_test(restore_does_not_settle),
		cmocka_unit_test(checkpoint_before_the_first_period),
		cmocka_unit_test(damage_is_refused),
		cmocka_unit_test(phase_jump_restarts),
		cmocka_unit_test(failure_code_checked),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
