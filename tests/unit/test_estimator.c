/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_estimator.c - a known answer of the transport estimator: its v is
 * the mean feed position's change over the time between its first and
 * last period boundaries, each boundary placed on the step's cubic
 * Hermite of the rotor's phase and the position read from the Hermite of
 * the position at that moment. The test steps an instance one machine
 * step at a time, keeps the ends of every step (phase, position and
 * their rates, from the estimator's own probe), places the boundaries by
 * bisection (not the estimator's Newton) and compares; and the last
 * period's feed velocity and length, and the statistical part of the
 * error bar from the same boundaries.
 */
#include <math.h>

#include "testutil.h"

#include "ode.h"     /* ode_hermite */
#include "sim_int.h" /* the estimator's probe of each step's end */

/* u in [0, 1] where the phase's Hermite passes target, by bisection. */
static double bisect(double p0, double v0, double p1, double v1, double H, double target)
{
	int up = p1 > p0;
	double lo = 0.0, hi = 1.0;
	for (int it = 0; it < 200 && hi - lo > 1e-17; it++) {
		double mid = 0.5 * (lo + hi);
		if ((ode_hermite(p0, v0, p1, v1, H, mid) < target) == up)
			lo = mid;
		else
			hi = mid;
	}
	return 0.5 * (lo + hi);
}

static void v_is_dX_over_dt_between_its_crossings(void **state)
{
	(void)state;
	setup u = preset_defaults();
	sim *s = make(&u);
	const estimator *e = &s->est;
	double dt = s->cfg.dt, start = e->start;
	double t_first = NAN, X_first = NAN, t_last = NAN, X_last = NAN, tb[64], Xb[64];
	int n = 0;
	for (long k = 1; k <= (long)(1.2 / dt); k++) {
		double t0 = s->t_int, psi0 = e->psi_prev, psid0 = e->psid_prev;
		double X0 = e->X_prev, Xd0 = e->Xd_prev;
		advance(s, (double)k * dt); /* one fixed machine step */
		double H = s->t_int - t0, psi1 = e->psi_prev, psid1 = e->psid_prev;
		double n0 = floor(psi0 / (2 * M_PI)), n1 = floor(psi1 / (2 * M_PI));
		assert_true(fabs(n1 - n0) <= 1); /* the preset's steps pass one at most */
		if (n0 == n1)
			continue;
		double nb = n1 > n0 ? n1 : n0;
		double w = bisect(psi0, psid0, psi1, psid1, H, nb * 2 * M_PI);
		double t = t0 + w * H;
		double X = ode_hermite(X0, Xd0, e->X_prev, e->Xd_prev, H, w);
		if (t < start - 1e-12)
			continue;
		if (n++ == 0) {
			t_first = t;
			X_first = X;
		}
		t_last = t;
		X_last = X;
		if (n <= 64) {
			tb[n - 1] = t;
			Xb[n - 1] = X;
		}
	}
	assert_true(n >= 25); /* 25 Hz over 1.2 s */
	double v = (X_last - X_first) / (t_last - t_first);
	sim_status st = status(s);
	assert_int_equal((int)st.transport_periods, n - 1);
	if (!(fabs(st.transport_velocity - v) <= 1e-9 * fabs(v)))
		fail_msg("v %.17g, dX/dt between the crossings %.17g (relative %.3g)",
			 st.transport_velocity, v, (st.transport_velocity - v) / v);
	assert_true(fabs(v) > 1e-3); /* the preset moves its feed */
	/* the last period's feed velocity and length */
	assert_true(n <= 64);
	double fv = (Xb[n - 1] - Xb[n - 2]) / (tb[n - 1] - tb[n - 2]);
	assert_close(st.feed_velocity, fv, 1e-9 * fabs(fv));
	assert_close(st.period, tb[n - 1] - tb[n - 2], 1e-12);
	/* the statistical bar: the n - 1 one-period velocities v_i at their
	 * mid-times c_i, a least-squares line through them; the residuals'
	 * scatter s (n - 3 degrees of freedom: the line takes two) gives the
	 * mean's standard error s / sqrt(n - 1), the slope times the window
	 * the drift D; the bar is sqrt(se^2 + (D / 2)^2) */
	int nb = n - 1;
	double vi[63], ci[63], cm = 0.0, vm = 0.0, scc = 0.0, scv = 0.0, ss = 0.0;
	for (int i = 0; i < nb; i++) {
		vi[i] = (Xb[i + 1] - Xb[i]) / (tb[i + 1] - tb[i]);
		ci[i] = 0.5 * (tb[i] + tb[i + 1]);
		cm += ci[i] / nb;
		vm += vi[i] / nb;
	}
	for (int i = 0; i < nb; i++) {
		scc += (ci[i] - cm) * (ci[i] - cm);
		scv += (ci[i] - cm) * (vi[i] - vm);
	}
	for (int i = 0; i < nb; i++) {
		double r = vi[i] - vm - scv / scc * (ci[i] - cm);
		ss += r * r;
	}
	double se = sqrt(ss / (nb - 2)) / sqrt((double)nb), D = scv / scc * (t_last - t_first);
	double bar = sqrt(se * se + 0.25 * D * D);
	assert_close(st.transport_velocity_uncertainty - st.step_error, bar, 1e-6 * bar); /* 1e-13 seen */
	/* the drift and its standard error, which the steady flag compares:
	 * the slope's, s / sqrt(sum (c_i - c)^2), times the window */
	double se_D = sqrt(ss / (nb - 2)) / sqrt(scc) * (t_last - t_first);
	assert_close(e->bar.drift, D, 1e-6 * fabs(D));
	assert_close(e->bar.se_drift, se_D, 1e-6 * se_D);
	sim_free(s);
}

/* The estimator's probe of a state (the mean feed position and its rate
 * it interpolates at the boundaries) is the mean over every element of
 * every column: on the full model (five columns integrated, each with its
 * own motion) against the means taken here from the state itself. */
static void probe_is_the_mean_over_every_element(void **state)
{
	(void)state;
	setup u = preset();
	set(&u, "h", "0.1"); /* asymmetric: the columns move apart */
	sim *s = make(&u);
	const model *md = &s->md;
	assert_int_equal(md->dk.K, 5);
	for (int k = 1; k <= 3; k++) {
		advance(s, 0.1 * k);
		double X = 0.0, Xd = 0.0;
		for (int e = 0; e < md->nf; e++) {
			X += s->y[md->nq + e] / md->nf;
			Xd += s->y[md->npos + md->nq + e] / md->nf;
		}
		assert_close(s->est.X_prev, X, 1e-12);
		assert_close(s->est.Xd_prev, Xd, 1e-12);
		assert_true(fabs(Xd) > 1e-4); /* the feed moves */
	}
	sim_free(s);
}

/* A closed loop's steps of beta (sim_steer_beta) leave the trajectory
 * bit for bit as sim_set_beta's, but the estimate goes on across them:
 * after a restart and 25 steps of one period each, it counts the whole
 * periods since the restart (sim_set_beta's starts over at each), and its
 * step error's shadow took every step. */
static void steered_beta_keeps_the_estimate(void **state)
{
	(void)state;
	setup u = preset_defaults();
	sim *a = make(&u), *b = make(&u);
	advance(a, 1.0);
	advance(b, 1.0);
	sim_restart_transport(b);
	sim_status s0 = status(b);
	double t = 1.0, beta = s0.beta;
	int shadowed = 0;
	for (int k = 0; k < 25; k++) {
		beta += (k % 2 ? -0.2 : 0.3) * M_PI / 180;
		assert_int_equal(sim_set_beta(a, beta, 0), SIM_OK);
		assert_int_equal(sim_steer_beta(b, beta, 0), SIM_OK);
		if (b->shadow)
			shadowed++, assert_true(status(b->shadow).beta_target == beta);
		t += 0.04;
		advance(a, t);
		advance(b, t);
	}
	assert_int_equal(shadowed, 25); /* the preset's dem measures its step error */
	assert_int_equal(sim_steer_beta(b, 200 * M_PI / 180, 0), SIM_EPARAM);
	sim_status sa = status(a), sb = status(b);
	assert_true(sa.feed_displacement == sb.feed_displacement && sa.q[3] == sb.q[3]);
	assert_true(sa.transport_periods <= 1);
	assert_true(sb.transport_periods >= 23);
	double mean = (sb.feed_displacement - s0.feed_displacement) / (sb.t - s0.t);
	assert_close(sb.transport_velocity, mean, 0.05 * fabs(mean));
	assert_true(isfinite(sb.feed_velocity));
	sim_free(a);
	sim_free(b);
}

/* steady asks a drift within its own standard error (or within 0.5 % of
 * |v|) as well as a bar within its gate: with beta steered at 0.5 deg/s
 * the window's speed falls steadily, by 1 to 3 % of v over it, its drift
 * many times its standard error while half of it, the bar, stays within
 * the gate, and the estimate is not steady; the same instance with beta
 * held is. */
static void a_steady_drift_is_not_steady(void **state)
{
	(void)state;
	setup u = preset_defaults();
	sim *held = make(&u), *steered = make(&u);
	advance(held, 1.0);
	advance(steered, 1.0);
	sim_restart_transport(held);
	sim_restart_transport(steered);
	double beta = status(steered).beta, t = 1.0;
	for (int k = 0; k < 75; k++) {
		beta += 0.5 * 0.04 * M_PI / 180;
		assert_int_equal(sim_steer_beta(steered, beta, 0), SIM_OK);
		t += 0.04;
		advance(held, t);
		advance(steered, t);
	}
	const estimator *e = &steered->est;
	sim_status st = status(steered);
	double v = fabs(st.transport_velocity), gate = 0.005 * e->speed_max + 0.01 * v;
	assert_true(e->n_bound >= 8);
	/* the case the rule is for: a drift beyond its error and 0.5 % of v,
	 * a bar within the gate */
	assert_true(fabs(e->bar.drift) > 10.0 * e->bar.se_drift);
	assert_true(fabs(e->bar.drift) > 0.01 * v && fabs(e->bar.drift) < 0.03 * v);
	assert_true(e->bar.uncertainty <= gate);
	assert_false(st.steady);
	assert_true(status(held).steady);
	sim_free(held);
	sim_free(steered);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(v_is_dX_over_dt_between_its_crossings),
		cmocka_unit_test(steered_beta_keeps_the_estimate),
		cmocka_unit_test(probe_is_the_mean_over_every_element),
		cmocka_unit_test(a_steady_drift_is_not_steady),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
