/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_feed_events.c - dem's located slip reversals and yielding deck
 * (feed_events) against known answers: a reversal inside a sub-step is
 * exact where the forces are constant (a block on a deck accelerating
 * faster than friction can follow), the feed step's order in v is two with
 * events and one without, and the yielding deck removes the machine
 * step's error in v (at 20 deg cw, against a machine step 8 x finer); its
 * compliance is the machine's response at the deck points.
 */
#include "feed.h"
#include "testutil.h"

/* One element resting on a deck that moves horizontally with velocity
 * a t (a > mu g), sliding ahead of it at u0 at t = -h/2 (the leapfrog's
 * velocities are those of the sub-steps' middles). Its velocity relative
 * to the deck falls at mu g + a until it crosses zero u0 / (mu g + a)
 * later (t*, counted from -h/2), then, friction reversed, at a - mu g: at
 * t = (n - 1/2) h it is -(a - mu g)(n h - t*) exactly. With the reversal located, dem gets that
 * to round-off; without, it gives the whole sub-step of the crossing the
 * new friction, off by 2 mu g (t*'s share of that sub-step) h. */
static double reversal_error(int events, double frac)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	sc.columns = 1;
	sc.layers = 1;
	model md;
	model_ctl ctl;
	model_init(&md, &ctl, &p, &sc);
	const int ns = 8;
	const double h = 1e-4, g = p.g, mu = p.mu, a = 3.0 * mu * g;
	/* the crossing falls at frac of sub-step 3's velocity interval */
	const double tstar = (3.0 + frac) * h;
	const double u0 = (mu * g + a) * tstar;
	double *y = calloc((size_t)md.n, sizeof *y);
	signed char modes[2] = {0, 0}; /* normal, tangential: bonded */
	assert_non_null(y);
	/* at rest on the deck under its weight, sliding ahead of it at u0
	 * (the deck's velocity at t = -h/2 is -a h/2) */
	y[md.nq + md.nf] = -p.m_n * g / p.k_c;
	y[md.npos + md.nq] = u0 - 0.5 * a * h;
	/* the contact slips with the deck slower than the element: friction
	 * pushes the element back, impulse -mu P_n on it: mode LO */
	modes[1] = 2;
	double pos[ns][2], vel[ns + 1][2];
	for (int i = 0; i < ns; i++) {
		pos[i][0] = 0.5 * a * (i * h) * (i * h);
		pos[i][1] = 0.0;
	}
	for (int i = 0; i <= ns; i++) {
		vel[i][0] = a * (i - 0.5) * h;
		vel[i][1] = 0.0;
	}
	double imp[1][2];
	feed_work work = {0.0, 0.0, 0.0};
	feed_dem_step(&md, y, ns, h, (const double(*)[2])pos, (const double(*)[2])vel, events, NULL,
		      modes, imp, &work);
	double t_end = (ns - 0.5) * h;
	double exact = a * t_end - (a - mu * g) * (ns * h - tstar);
	double err = fabs(y[md.npos + md.nq] - exact) / (mu * g * h);
	free(y);
	return err;
}

static void reversal_inside_a_substep_is_exact(void **state)
{
	(void)state;
	const double fracs[] = {0.1, 0.5, 0.9};
	for (int i = 0; i < 3; i++) {
		double with = reversal_error(1, fracs[i]), without = reversal_error(0, fracs[i]);
		/* in units of mu g h: round-off with the event located; without,
		 * 2 frac (the new friction over the part before t*), or, where
		 * the end's bond is within the friction bound, (a / mu g - 1)
		 * (1 - frac) (stuck at the sub-step's end instead of slipping
		 * back since t*), whichever the set-valued solve picked */
		print_message("reversal at %.1f of a sub-step: error %.2e mu g h located, %.3f not\n",
			      fracs[i], with, without);
		if (!(with < 1e-9))
			fail_msg("located reversal at %.1f of a sub-step: error %.3g mu g h", fracs[i], with);
		double slip = 2.0 * fracs[i], stuck = 2.0 * (1.0 - fracs[i]);
		if (!(fabs(without - slip) < 1e-6 || fabs(without - stuck) < 1e-6))
			fail_msg("unlocated reversal: error %.6f mu g h, neither %.3f nor %.3f", without,
				 slip, stuck);
	}
}

/* Feed displacement after 2 s of one element, one-way coupled (the same
 * deck motion at every feed step), at beta = 0 (slip and its reversals
 * only) and 155 deg (hopping), with `substeps` sub-steps of a 1e-3-s
 * machine step. */
static double displacement(const char *beta, int substeps, const char *events)
{
	setup u = preset_defaults();
	char n[16];
	snprintf(n, sizeof n, "%d", substeps);
	set(&u, "beta", beta);
	set(&u, "feed_coupling", "false");
	set(&u, "layers", "1");
	set(&u, "substeps", n);
	set(&u, "feed_events", events);
	sim *s = make(&u);
	advance(s, 2.0);
	double d = status(s).feed_displacement;
	sim_free(s);
	return d;
}

/* Observed order of the feed step in the displacement: the least-squares
 * slope of log2 |d(n) - d_ref| against log2 n over n = 8, 16, 32, 64
 * sub-steps (4 are not yet in the asymptotic range), d_ref at 512
 * sub-steps with events (both schemes converge to it; the scheme without
 * is itself 1e-5 off there, well below its errors at 64). A slope from
 * three neighbouring steps alone, (d8 - d16) / (d16 - d32), moves by a
 * few tenths with the start. */
static double feed_order(const char *beta, const char *events, double ref)
{
	const int n[] = {8, 16, 32, 64};
	double sx = 0.0, sy = 0.0, sxx = 0.0, sxy = 0.0;
	for (int i = 0; i < 4; i++) {
		double x = log2((double)n[i]);
		double y = log2(fabs(displacement(beta, n[i], events) - ref));
		sx += x;
		sy += y;
		sxx += x * x;
		sxy += x * y;
	}
	return -(4.0 * sxy - sx * sy) / (4.0 * sxx - sx * sx);
}

static void feed_step_order_two_with_events(void **state)
{
	(void)state;
	const char *betas[] = {"0", "155"};
	for (int b = 0; b < 2; b++) {
		double ref = displacement(betas[b], 512, "true");
		double with = feed_order(betas[b], "true", ref),
		       without = feed_order(betas[b], "false", ref);
		print_message("beta %s: feed-step order %.2f with events, %.2f without\n", betas[b],
			      with, without);
		assert_true(with > 1.8);
		assert_true(without < 1.3);
	}
}

/* v at 20 deg cw (steady start, 4-s window) at the default machine step
 * (1.25e-3 s, 5 feed sub-steps of 2.5e-4 s) against a machine step 10 x
 * finer with one feed sub-step each (half the feed step): the yielding deck
 * keeps them within 0.3 % (the feed not seeing its own reaction within the
 * step cost 1 % here at 1e-3 s). */
static void yielding_deck_removes_the_machine_steps_error(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "beta", "20");
	double v = run_velocity(&u, 4.0);
	set(&u, "dt", "1.25e-4");
	set(&u, "substeps", "1");
	double fine = run_velocity(&u, 4.0);
	print_message("v(20 deg cw) = %.6f at the default steps, %.6f at 1.25e-4 s\n", v, fine);
	assert_rel(v, fine, 3e-3);
}

/* The yielding deck's compliance in its factored form (feed_yield: the
 * columns' impulses summed as one generalized impulse on x, y, alpha, then
 * seen at each deck point) against the machine's own response: a unit
 * impulse of column j along x or y, as the generalized force deck_forces
 * gives it, through model_force_response's reduced accelerations, seen at
 * every column k's deck point (its Jacobian on x, y, alpha, times the
 * columns it stands for). On the full model (5 columns, the deck turned
 * and turning, alpha = 0.02) and on the defaults (one column standing for
 * five, alpha fixed), at random machine states. */
static void yield_is_the_machines_response_at_the_deck_points(void **state)
{
	(void)state;
	for (int full = 0; full < 2; full++) {
		setup u = preset_defaults();
		if (full)
			set(&u, "trough_rotation", "true");
		model md;
		model_ctl ctl;
		model_init(&md, &ctl, &u.p, &u.sc);
		const int K = md.dk.K, nb = md.alpha_fixed ? 2 : 3;
		assert_int_equal(K, full ? 5 : 1);
		assert_true(md.col_weight == (full ? 1.0 : 5.0));
		double *y = calloc((size_t)md.n, sizeof *y);
		assert_non_null(y);
		srand(11);
		for (int trial = 0; trial < 20; trial++) {
			for (int r = 0; r < md.nq; r++) {
				y[r] = 2e-3 * (2.0 * rand() / RAND_MAX - 1.0);
				y[md.npos + r] = 0.3 * (2.0 * rand() / RAND_MAX - 1.0);
			}
			double q[NQ_FULL], qd[NQ_FULL];
			if (full) {
				model_full_coords(&md, &ctl, 0.0, y, q, qd);
				for (int r = 0; r < md.nq; r++) /* alpha's own entry */
					if (md.ncol[r] == 1 && md.col[r][0] == Q_ALPHA)
						y[r] = 0.02;
			}
			model_full_coords(&md, &ctl, 0.0, y, q, qd);
			deck_rot R = deck_rotation(q);
			assert_true(full ? R.s != 0.0 : R.s == 0.0);
			double unit[3][NQ_FULL] = {{0}}, qr[3][NQ_FULL];
			for (int c = 0; c < nb; c++) {
				unit[c][c] = 1.0; /* Q_X, Q_Y, Q_ALPHA */
				model_force_response(&md, &ctl, 0.0, y, unit[c], qr[c]);
			}
			feed_yield yl;
			feed_yield_compliance(&md, nb, (const double(*)[NQ_FULL])qr, &R, &yl);
			for (int j = 0; j < K; j++)
				for (int c = 0; c < 2; c++) {
					double E[SIM_MAX_COLUMNS][2] = {{0}}, dv[SIM_MAX_COLUMNS][2];
					E[j][c] = 1.0;
					feed_yield_velocity(&yl, K, (const double(*)[2])E, dv);
					double Q[NQ_FULL] = {0}, qrdd[NQ_FULL], a[NQ_FULL] = {0};
					deck_forces(&md.dk, &R, (const double(*)[2])E, 1.0, Q);
					model_force_response(&md, &ctl, 0.0, y, Q, qrdd);
					model_add_reduced(&md, qrdd, a);
					for (int k = 0; k < K; k++) {
						double b[2] = {md.dk.d[k], md.dk.h_d}, Rd[2];
						deck_rotate(&R, b, Rd);
						double want[2] = {
							md.col_weight * (a[Q_X] - Rd[1] * a[Q_ALPHA]),
							md.col_weight * (a[Q_Y] + Rd[0] * a[Q_ALPHA])};
						double size = fabs(want[0]) + fabs(want[1]);
						assert_true(size > 1e-4); /* 1/kg: a machine of ~1e2 kg */
						for (int e = 0; e < 2; e++)
							assert_true(fabs(dv[k][e] - want[e]) <= 1e-12 * size);
					}
				}
		}
		free(y);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(reversal_inside_a_substep_is_exact),
		cmocka_unit_test(feed_step_order_two_with_events),
		cmocka_unit_test(yielding_deck_removes_the_machine_steps_error),
		cmocka_unit_test(yield_is_the_machines_response_at_the_deck_points),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
