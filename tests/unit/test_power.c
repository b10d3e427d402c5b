/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_power.c - the machine's equations of motion against two answers
 * known without the code.
 *
 * The instantaneous power balance (docs/MODEL.md "Energy"): along any
 * motion the equations give, the rate of change of the stored energy
 * T + V equals the input power (drive, guide actuator, an external load on
 * the deck) less the dissipated power (dampers, bearing drag, load
 * torque), exactly, at every state, not only on average. The test takes
 * random states of an asymmetric machine (every geometric offset the
 * settings have set to nonzero: h, l1 != l2, the axle off G, c, guide
 * points off the x axis, unequal eliminators, h_d) with alpha integrated
 * and alpha' large, with beta held and beta on a ramp, with the Kloss motor
 * and with the ideal drive, and compares dE/dt by a central difference
 * along the computed derivative with the reported powers. A wrong term
 * in the mass matrix, a velocity-product or guide-rate term, a moment arm
 * or a power booked wrong breaks it; the preset's symmetric machine, where
 * most offsets are zero, hides many of these.
 *
 * The Kloss motor against bearing drag and a load torque: with no
 * unbalance the rotor is decoupled, and its steady speed solves
 * M_el(w) = b_phi w |w| + M_L (docs/MODEL.md "Drive"). And what is shown
 * of the machine: the deck point against its kinematics (and the deck
 * points' velocities and accelerations against the rates of their
 * positions and velocities), the observation
 * against the evaluation the integration makes.
 */
#include "dynamics.h"
#include "model.h"
#include "testutil.h"

/* The asymmetric machine without feed, alpha integrated, drive as given. */
static setup asymmetric(const char *drive)
{
	setup u = preset();
	static const char *const changes[][2] = {
		{"feed", "false"}, {"h", "0.15"},   {"l2", "0.8"},    {"w_x", "0.12"},
		{"w_y", "-0.07"},  {"c", "0.04"},   {"p1_y", "0.03"}, {"p2_y", "-0.02"},
		{"m2", "15"},      {"k_s2", "4e5"}, {"b_s2", "35"},   {"b_phi", "2e-4"},
		{"M_load", "3"},   {"h_d", "0.1"},  {"b_x", "80"},    {"b_y", "30"},
		{"k_x", "7e4"},	   {"beta", "52"},
	};
	for (size_t i = 0; i < sizeof changes / sizeof changes[0]; i++)
		set(&u, changes[i][0], changes[i][1]);
	set(&u, "drive", drive);
	return u;
}

/* T + V of state y at time t. */
static double stored(const model *md, const model_ctl *ctl, double t, const double *y)
{
	double T, V;
	model_machine_energy(md, ctl, t, y, &T, &V);
	return T + V;
}

/* The worst mismatch of dE/dt against input - dissipated power over
 * random states, relative to the largest power term seen. */
static double worst_power_gap(const char *drive, int rotation, int ramp, const double load[3])
{
	setup u = asymmetric(drive);
	u.p.rotation = rotation;
	model md;
	model_ctl ctl;
	model_init(&md, &ctl, &u.p, &u.sc);
	assert_int_equal(md.nf, 0);
	assert_true(!md.alpha_fixed);
	memcpy(ctl.deck_load, load, sizeof ctl.deck_load);
	if (ramp) /* beta from 52 deg to 140 deg: accelerating over [0, 0.1] s */
		ramp_to_position(&ctl.beta_ramp, 0.0, 140.0 * RAD_PER_DEG, 3.0, 30.0);
	double y[2 * NQ_FULL + ACC_N], dy[2 * NQ_FULL + ACC_N], yp[2 * NQ_FULL + ACC_N],
		ym[2 * NQ_FULL + ACC_N];
	/* the reduced coordinates are the full ones in order, phi left out
	 * under the ideal drive */
	const double scale[NQ_FULL] = {3e-3, 3e-3, 4e-3, 6.0, 6e-3, 6e-3};
	const double rate[NQ_FULL] = {0.4, 0.4, 5.0, 170.0, 0.8, 0.8};
	srand(3);
	double worst = 0.0;
	for (int trial = 0; trial < 200; trial++) {
		memset(y, 0, sizeof y);
		double t = 0.005 + 0.0004 * trial;
		for (int r = 0; r < md.nq; r++) {
			int i = md.col[r][0];
			y[r] = scale[i] * (2.0 * rand() / RAND_MAX - 1.0);
			y[md.npos + r] = rate[i] * (2.0 * rand() / RAND_MAX - 1.0);
			if (i == Q_PHI) /* the rotor turning in its sense */
				y[md.npos + r] = rotation * (140.0 + fabs(y[md.npos + r]) / 10.0);
		}
		model_machine_rhs(&md, &ctl, t, y, NULL, dy, NULL);
		const double p_in = dy[2 * md.npos + ACC_IN], p_out = dy[2 * md.npos + ACC_DAMP];
		const double eps = 2e-7;
		for (int i = 0; i < 2 * md.npos; i++) {
			yp[i] = y[i] + eps * dy[i];
			ym[i] = y[i] - eps * dy[i];
		}
		double rate_E =
			(stored(&md, &ctl, t + eps, yp) - stored(&md, &ctl, t - eps, ym)) / (2.0 * eps);
		double gap = fabs(rate_E - (p_in - p_out)) / (fabs(p_in) + fabs(p_out) + 1.0);
		worst = fmax(worst, gap);
	}
	return worst;
}

/* dE/dt = input - dissipated power at every state, to the central
 * difference's accuracy (measured 7e-10 of the power terms; a fault
 * of one term of a few watts shows as 1e-4 and more). */
static void power_balance_at_every_state(void **state)
{
	(void)state;
	const double none[3] = {0.0, 0.0, 0.0}, load[3] = {40.0, -300.0, 25.0};
	const char *drives[] = {"motor", "ideal"};
	for (int d = 0; d < 2; d++)
		for (int r = 0; r < 2; r++)
			for (int ramp = 0; ramp < 2; ramp++)
				for (int l = 0; l < 2; l++) {
					double g = worst_power_gap(drives[d], r ? SIM_CCW : SIM_CW,
								   ramp, l ? load : none);
					if (!(g < 1e-8))
						fail_msg("%s drive, %s, beta %s, deck load %s: dE/dt "
							 "misses the powers by %.3g of them",
							 drives[d], r ? "ccw" : "cw",
							 ramp ? "ramping" : "held", l ? "on" : "off", g);
				}
}

/* Kloss torque (paper eq. 10) at relative speed w > 0. */
static double kloss(double w, double Mut, double wss, double sut)
{
	double s = wss - w;
	return 2.0 * Mut * s * sut / (sut * sut + s * s);
}

/* The rotor's steady speed under bearing drag b w^2 and a load torque
 * ML: M_el(w) = b w^2 + ML by bisection on Kloss's stable branch (slip
 * below the breakdown slip sut). */
static double loaded_speed(double Mut, double wss, double sut, double b, double ML)
{
	double lo = wss - sut, hi = wss;
	for (int i = 0; i < 200; i++) {
		double mid = 0.5 * (lo + hi);
		if (kloss(mid, Mut, wss, sut) > b * mid * mid + ML)
			lo = mid;
		else
			hi = mid;
	}
	return 0.5 * (lo + hi);
}

/* The preset's rotor alone (e = 0: the trough is not shaken; J_w = 0.01
 * kg m^2, no feed, RK4 at 1e-4 s), turning cw (ccw if ccw). */
static setup rotor_alone(int ccw)
{
	setup u = preset();
	set(&u, "feed", "false");
	set(&u, "method", "rk4");
	set(&u, "dt", "1e-4");
	set(&u, "e", "0");
	set(&u, "J_w", "0.01");
	set(&u, "rotation", ccw ? "ccw" : "cw");
	return u;
}

/* The rotor alone (e = 0) under bearing drag b_phi w |w| and a load
 * torque: its steady speed solves M_el(w) = b_phi w^2 + M_L (bisection
 * on the stable branch, slip below the breakdown slip), both senses. */
static void kloss_against_drag_and_load(void **state)
{
	(void)state;
	const double Mut = 50.0, wss = 157.08, sut = 15.5, b = 4e-4, ML = 2.0;
	const double w = loaded_speed(Mut, wss, sut, b, ML); /* 155.25 rad/s: drag 9.64 N m, load 2 */
	for (int r = 0; r < 2; r++) {
		setup u = rotor_alone(r);
		set(&u, "b_phi", "4e-4");
		set(&u, "M_load", "2");
		sim *s = make(&u);
		advance(s, 5.0); /* the trough's rocking from the start decays in ~0.5 s */
		sim_status st = status(s);
		double sign = r ? -1.0 : 1.0;
		assert_close(st.rotor_speed, sign * w, 1e-6);
		assert_close(st.motor_torque, sign * (b * w * w + ML), 1e-5);
		/* what is shown of it: the power, and the means over whole
		 * periods (the torque is constant: e = 0) */
		assert_close(st.power, (b * w * w + ML) * w, 2e-3);
		assert_close(st.rotor_speed_mean, sign * w, 1e-5);
		assert_close(st.motor_torque_mean, sign * (b * w * w + ML), 1e-5);
		assert_close(st.power_mean, (b * w * w + ML) * w, 2e-3);
		sim_free(s);
	}
}

/* The load torque acts against the rotor's turning and holds a standing
 * rotor, it does not drive one (core/model.c: near standstill the motor's
 * slip slope k = 2 M_ut / slip_ut times the speed, at most M_L). The rotor
 * alone (e = 0, J_w = 0.01 kg m^2), both senses: with the motor switched
 * off at 155 rad/s under M_L = 2 N m it slows at M_L / J_w, passes 0.5
 * rad/s at (w0 - 0.5) J_w / M_L to the sample, and stays stopped but for
 * the trough's rocking against it (before: it turned backwards, at -244
 * rad/s 2 s on); under M_L = 100 N m, twice the breakdown torque, the
 * motor holds it creeping where M_el(w) = k w (before: diverged). */
static void load_holds_a_standing_rotor(void **state)
{
	(void)state;
	const double Mut = 50.0, wss = 157.08, sut = 15.5, J = 0.01, k = 2.0 * Mut / sut;
	for (int r = 0; r < 2; r++) {
		double sign = r ? -1.0 : 1.0;
		setup u = rotor_alone(r);
		set(&u, "M_load", "2");
		sim *s = make(&u);
		advance(s, 2.0);
		double w0 = sign * status(s).rotor_speed, t0 = status(s).t, stop = NAN;
		assert_true(w0 > 150.0);
		assert_int_equal(sim_set_drive_on(s, 0), SIM_OK);
		for (int i = 1; i <= 2000; i++) {
			advance(s, t0 + 1e-3 * i);
			double w = sign * status(s).rotor_speed;
			assert_true(w > -1e-3); /* the trough's rocking: 3e-5 */
			if (isnan(stop) && w < 0.5)
				stop = 1e-3 * i;
		}
		print_message("below 0.5 rad/s after %.3f s (%.3f s from M_L / J_w)\n", stop,
			      (w0 - 0.5) * J / 2.0);
		assert_true(fabs(stop - (w0 - 0.5) * J / 2.0) <= 1e-3);
		assert_true(fabs(status(s).rotor_speed) < 1e-3);
		sim_free(s);

		set(&u, "M_load", "100");
		s = make(&u);
		advance(s, 2.0);
		double w = 1.0;
		for (int i = 0; i < 100; i++)
			w = kloss(w, Mut, wss, sut) / k;
		print_message("under 100 N m: %.9g rad/s (M_el(w) = k w: %.9g)\n",
			      sign * status(s).rotor_speed, w);
		assert_close(sign * status(s).rotor_speed, w, 1e-6);
		sim_free(s);
	}
}

/* A steady start whose orbit at the synchronous speed asks more torque
 * than the motor's breakdown torque is no steady state of the machine
 * (steady.c): it starts from its static equilibrium, at rest, and the
 * settling runs it up. The preset's rotor alone (e = 0) under M_L = 60 N m
 * (M_ut 50) creeps where M_el(w) = k w (the load near
 * standstill, k = 2 M_ut / slip_ut); the energy dissipated is positive
 * (before: the rotor placed at 157 rad/s on an orbit it could not hold;
 * its load turned it backwards). A machine whose rocking asks 73 N m at
 * 157 rad/s (the axle 2.45 m off G, l2 = 4.41 m, beta 70 deg) runs up
 * from rest, bounded (before: diverged at once, at any step). */
static void orbit_beyond_the_motor_starts_at_rest(void **state)
{
	(void)state;
	const double Mut = 50.0, wss = 157.08, sut = 15.5, k = 2.0 * Mut / sut;
	setup u = preset_defaults();
	set(&u, "feed", "false");
	set(&u, "e", "0");
	set(&u, "M_load", "60");
	sim *s = make(&u);
	advance(s, 1.0);
	double w = 1.0;
	for (int i = 0; i < 100; i++)
		w = kloss(w, Mut, wss, sut) / k;
	sim_status st = status(s);
	print_message("M_L 60 N m: %.6g rad/s (M_el(w) = k w: %.6g), dissipated %.4g J\n",
		      st.rotor_speed, w, st.e_dissipated);
	assert_true(fabs(st.rotor_speed - w) < 1e-3 * w);
	assert_true(st.e_dissipated > 0.0);
	sim_free(s);

	u = preset_defaults();
	set(&u, "w_x", "2.44614");
	set(&u, "l2", "4.4134");
	set(&u, "beta", "70.1463");
	s = make(&u);
	advance(s, 0.5);
	st = status(s);
	print_message("rocking machine: %.6g rad/s at t = 0.5 s\n", st.rotor_speed);
	assert_true(isfinite(st.q[0]) && isfinite(st.q[1]) && isfinite(st.rotor_speed));
	/* bounded: the rocking whips the rotor between about +160 and -140
	 * rad/s within a period at t = 0.5 s, so its sign there is the steps' */
	assert_true(fabs(st.rotor_speed) < 2.0 * wss);
	sim_free(s);
}

/* The steady start (docs/MODEL.md "Parameters": the rotor at the speed
 * where M_el balances the mean load) puts the rotor alone (e = 0) at
 * kloss_against_drag_and_load's speed at t = 0, both senses: the
 * counter-clockwise motor, M_el,ccw(w) = -M_el(-w), on its stable branch
 * below the synchronous speed in magnitude, and where it starts it stays.
 * A heavy rotor (J_w = 10 kg m^2: its slip mode decays at 0.65 1/s) keeps
 * the settling before t = 0 from correcting a wrong start. */
static void steady_start_at_the_loaded_speed(void **state)
{
	(void)state;
	const double Mut = 50.0, wss = 157.08, sut = 15.5, b = 4e-4, ML = 2.0;
	const double w = loaded_speed(Mut, wss, sut, b, ML);
	for (int r = 0; r < 2; r++) {
		setup u = preset_defaults();
		set(&u, "feed", "false");
		set(&u, "e", "0");
		set(&u, "b_phi", "4e-4");
		set(&u, "M_load", "2");
		set(&u, "J_w", "10");
		set(&u, "rotation", r ? "ccw" : "cw");
		sim *s = make(&u);
		double sign = r ? -1.0 : 1.0;
		assert_close(status(s).rotor_speed, sign * w, 1e-6 * w);
		advance(s, 0.2);
		assert_close(status(s).rotor_speed, sign * w, 1e-6 * w);
		sim_free(s);
	}
}

/* The slip mode's rate that bounds a fixed step (model_slip_rate: the
 * torque's slope at the synchronous speed over the rotor's inertia) takes
 * the bearing drag's slope 2 b_phi w_ss with the motor's 2 M_ut / s_ut:
 * the largest step shrinks by their ratio when the drag is added. */
static void slip_bound_counts_the_drag(void **state)
{
	(void)state;
	setup a = preset(), b = preset();
	set(&a, "method", "rk4");
	set(&b, "method", "rk4");
	set(&b, "b_phi", "1e-3");
	double da = sim_max_dt(&a.p, &a.sc, &a.m), db = sim_max_dt(&b.p, &b.sc, &b.m);
	double motor = 2.0 * 50.0 / 15.5, drag = 2.0 * 1e-3 * 157.08;
	assert_true(isfinite(da) && da > 0.0);
	assert_close(da / db, (motor + drag) / motor, 1e-12);
}

/* The centre deck point's displacement shown (status deck) is the
 * kinematics of the point R(alpha) (0, h_d) from G: (x - h_d sin alpha,
 * y + h_d (cos alpha - 1)), from its rest position, whatever h_d; here on
 * the asymmetric machine running, alpha integrated, at a few times. */
static void deck_point_shown(void **state)
{
	(void)state;
	setup u = asymmetric("motor");
	set(&u, "h_d", "0.3");
	sim *s = make(&u);
	for (int i = 1; i <= 4; i++) {
		advance(s, 0.05 * i);
		sim_status st = status(s);
		double a = st.q[Q_ALPHA], hd = 0.3;
		assert_true(fabs(a) > 1e-6); /* the trough turns */
		assert_close(st.deck[0], st.q[Q_X] - hd * sin(a), 1e-12);
		assert_close(st.deck[1], st.q[Q_Y] + hd * (cos(a) - 1.0), 1e-12);
		assert_close(st.deck_vel[0], st.qd[Q_X] - hd * cos(a) * st.qd[Q_ALPHA], 1e-10);
		assert_close(st.deck_vel[1], st.qd[Q_Y] - hd * sin(a) * st.qd[Q_ALPHA], 1e-10);
	}
	sim_free(s);
}

/* What is shown of a state (dynamics_observe: the feed's force on the
 * deck from feed_deck_forces) is what the integration evaluates there
 * (dynamics_eval: from the feed's right-hand side): the same contact and
 * friction forces, so the same accelerations and, under the ideal drive,
 * the same torque, to the last bit. On random states of the full model
 * (every column, alpha integrated) with the layers pressed into each other
 * and sliding both ways, both drives. */
static void observation_is_the_evaluation(void **state)
{
	(void)state;
	const char *drives[] = {"motor", "ideal"};
	for (int d = 0; d < 2; d++) {
		setup u = preset();
		set(&u, "h", "0.1");
		set(&u, "drive", drives[d]);
		model md;
		model_ctl ctl;
		model_init(&md, &ctl, &u.p, &u.sc);
		assert_true(md.nf == 40 && !md.alpha_fixed);
		double *y = calloc((size_t)md.n, sizeof *y), *a = calloc((size_t)md.n, sizeof *a),
		       *b = calloc((size_t)md.n, sizeof *b);
		assert_non_null(y);
		assert_non_null(a);
		assert_non_null(b);
		srand(5);
		for (int trial = 0; trial < 50; trial++) {
			dynamics_equilibrium(&md, &ctl, y);
			for (int r = 0; r < md.nq; r++)
				y[md.npos + r] = 0.2 * (2.0 * rand() / RAND_MAX - 1.0);
			for (int e = 0; e < md.nf; e++) {
				y[md.nq + md.nf + e] += 2e-5 * (2.0 * rand() / RAND_MAX - 1.0);
				y[md.npos + md.nq + e] = 0.3 * (2.0 * rand() / RAND_MAX - 1.0);
				y[md.npos + md.nq + md.nf + e] = 0.1 * (2.0 * rand() / RAND_MAX - 1.0);
			}
			model_eval ea, eb;
			dynamics_eval(&md, &ctl, 0.01 * trial, y, a, &ea);
			dynamics_observe(&md, &ctl, 0.01 * trial, y, b, &eb);
			assert_memory_equal(ea.qdd, eb.qdd, sizeof ea.qdd);
			assert_true(ea.torque == eb.torque);
		}
		free(y);
		free(a);
		free(b);
	}
}

/* A deck point's velocity is the rate of its position and its
 * acceleration the rate of its velocity (central differences along q(t)
 * = q + t q' + t^2 q''/2), and deck_point_affine, which the split method
 * tracks the deck with, gives every column's position and velocity as
 * deck_point does: on random states with alpha, alpha' and alpha'' large,
 * at h_d = 0.25 m and body x from -1 to 1 m. */
static void deck_kinematics(void **state)
{
	(void)state;
	deck dk = {.K = 1, .h_d = 0.25};
	srand(9);
	for (int trial = 0; trial < 100; trial++) {
		double q[NQ_FULL] = {0}, qd[NQ_FULL] = {0}, qdd[NQ_FULL] = {0};
		for (int i = 0; i < 3; i++) {
			q[i] = 0.3 * (2.0 * rand() / RAND_MAX - 1.0);
			qd[i] = 2.0 * (2.0 * rand() / RAND_MAX - 1.0);
			qdd[i] = 50.0 * (2.0 * rand() / RAND_MAX - 1.0);
		}
		double x = 2.0 * rand() / RAND_MAX - 1.0, eps = 1e-5, pv[2][2][2];
		for (int side = 0; side < 2; side++) { /* t = -eps, +eps */
			double t = side ? eps : -eps, qs[NQ_FULL] = {0}, qds[NQ_FULL] = {0};
			for (int i = 0; i < 3; i++) {
				qs[i] = q[i] + t * qd[i] + 0.5 * t * t * qdd[i];
				qds[i] = qd[i] + t * qdd[i];
			}
			deck_rot R = deck_rotation(qs);
			deck_point(&dk, x, &R, qs, qds, pv[side][0], pv[side][1]);
		}
		deck_rot R = deck_rotation(q);
		double pos[2], vel[2], aff[3][2][2];
		deck_point(&dk, x, &R, q, qd, pos, vel);
		deck_point_affine(&dk, &R, q, qd, qdd, aff);
		for (int c = 0; c < 2; c++) {
			assert_close(vel[c], (pv[1][0][c] - pv[0][0][c]) / (2.0 * eps), 1e-8);
			assert_close(aff[0][0][c] + x * aff[0][1][c], pos[c], 1e-14);
			assert_close(aff[1][0][c] + x * aff[1][1][c], vel[c], 1e-13);
			assert_close(aff[2][0][c] + x * aff[2][1][c],
				     (pv[1][1][c] - pv[0][1][c]) / (2.0 * eps), 1e-6);
		}
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(power_balance_at_every_state),
		cmocka_unit_test(kloss_against_drag_and_load),
		cmocka_unit_test(load_holds_a_standing_rotor),
		cmocka_unit_test(orbit_beyond_the_motor_starts_at_rest),
		cmocka_unit_test(steady_start_at_the_loaded_speed),
		cmocka_unit_test(slip_bound_counts_the_drag),
		cmocka_unit_test(deck_point_shown),
		cmocka_unit_test(observation_is_the_evaluation),
		cmocka_unit_test(deck_kinematics),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
