/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_beyond_preset.c - known answers at parameters other than the
 * czubak2016 preset's, where the terms that vanish on the preset (p = 1,
 * k_x = k_y, h = 0, c = 0, l1 = l2, the axle at G) are alive: a settled
 * stack's compressions under p != 1, the suspension's free vibration with
 * k_x != k_y, the statics of an asymmetric trough with h != 0 and c != 0
 * against a hand derivation, the rocking a horizontal displacement starts
 * through the lever arm h, a two-layer stack sliding under the regularised
 * law, and the mean rotor speed against a count of whole periods. Every
 * expected value is derived here from docs/MODEL.md, not read from the
 * code; tests/mutate.sh plants the faults each one catches.
 */
#include "sim_int.h" /* the machine's state, for a free vibration's start */
#include "testutil.h"

/* ---- helpers ----------------------------------------------------------- */

/* Move full machine coordinate `coord` (Q_X, Q_Y, Q_ALPHA, ...) of a fresh
 * instance by `by` (m or rad) at t = 0: the start of a free vibration.
 * sim_place_feed with every array NULL then gives the instance a fresh
 * integrator workspace and restarts its observers from the new state. */
static void displace(sim *s, int coord, double by)
{
	const model *md = &s->md;
	for (int r = 0; r < md->nq; r++)
		if (md->ncol[r] == 1 && md->col[r][0] == coord) {
			s->y[r] += by;
			assert_int_equal(sim_place_feed(s, NULL, NULL, NULL, NULL), SIM_OK);
			return;
		}
	fail_msg("coordinate %d is not integrated on its own", coord);
}

/* Each NAME=VALUE of a table of n (user units) in turn, or fail the test. */
static void set_all(setup *u, const char *const (*sets)[2], size_t n)
{
	for (size_t i = 0; i < n; i++)
		set(u, sets[i][0], sets[i][1]);
}
#define SET_ALL(u, sets) set_all(u, sets, sizeof sets / sizeof sets[0])

/* A machine without feed, on the ideal drive switched off: the rotor is
 * held at its angle relative to the trough, so the unbalanced mass rides
 * with the trough as a fixed point mass; no damping anywhere but the
 * eliminators' (which nothing here moves). */
static setup free_machine(void)
{
	setup u = preset();
	static const char *const sets[][2] = {{"feed", "false"},  {"drive", "ideal"},
					      {"motor_on", "false"}, {"b_x", "0"},
					      {"b_y", "0"},         {"trough_rotation", "false"},
					      {"method", "rk4"},    {"dt", "1e-4"}};
	SET_ALL(&u, sets);
	return u;
}

/* ---- a settled stack under p != 1 -------------------------------------- */

/* A column of L layers settled on a deck held still (one-way coupling,
 * motor off): contact j (between layer j-1, or the deck, and layer j,
 * bottom first) carries the weight above it, W_j = (L - j) m_n g, so its
 * compression is (W_j / k)^(1/p) (docs/accuracy.md "Checks with known
 * answers"). The start places the stack so; the integrators must then
 * hold it there: the contact law's force at those compressions is the
 * weight above only if it is k delta^p. R = 1 (no unloading branch), so a
 * round-off's sign of delta' cannot switch the force, and under the split
 * method (dem) every contact is the law's force itself (with R < 1 its
 * set-valued contact would hold any compression whose loading and
 * unloading forces bracket the weight). Tolerance: 1e-12 of each
 * compression: the start computes them to a few ulps (measured: 1e-15),
 * a held stack moves by round-off only; at the bottom contact under
 * p = 1.5, k delta would be 26 times the weight it carries. */
static void settled_stack_compressions(void **state)
{
	(void)state;
	const char *ps[] = {"1.5", "2"};
	const char *methods[][2] = {{"rk4", "5e-5"}, {"dem", "5e-5"}};
	enum { L = 6 };
	for (int pi = 0; pi < 2; pi++)
		for (int mi = 0; mi < 2; mi++) {
			setup u = one_element();
			const char *const sets[][2] = {{"layers", "6"}, {"p", ps[pi]},
						       {"k_c", "3e5"},  {"m_n", "0.3"},
						       {"R", "1"},      {"method", methods[mi][0]},
						       {"dt", methods[mi][1]}, {"substeps", "1"}};
			SET_ALL(&u, sets);
			double p = atof(ps[pi]), k = 3e5, w = 0.3 * 9.81;
			sim *s = make(&u);
			for (int pass = 0; pass < 2; pass++) {
				if (pass == 1)
					advance(s, 0.3);
				double eta[L];
				sim_feed_state(s, NULL, eta);
				double below = status(s).q[Q_Y] + u.p.h_d; /* the deck */
				for (int j = 0; j < L; j++) {
					double expect = pow((L - j) * w / k, 1.0 / p);
					double delta = below - eta[j];
					if (!(fabs(delta - expect) <= 1e-12 * expect))
						fail_msg("p=%s %s t=%g: contact %d compressed %.12g m, "
							 "(W/k)^(1/p) = %.12g m",
							 ps[pi], methods[mi][0], pass ? 0.3 : 0.0, j, delta,
							 expect);
					below = eta[j];
				}
			}
			sim_free(s);
		}
}

/* ---- free vibration of the suspension with k_x != k_y ------------------ */

/* Without feed, with no suspension damping and the rotor held (ideal drive
 * off), a displacement of G along x or y starts a pure harmonic motion
 * when nothing couples that direction to another: the machine symmetric
 * (h = 0, l1 = l2: alpha = 0 exactly) and the eliminators' guides across
 * it (beta = 0: guides vertical for x; beta = 90 deg: horizontal for y),
 * so each eliminator mass moves with the trough in that direction. Two
 * spring sets of stiffness k_x (k_y) then carry everything that moves:
 * trough, unbalanced mass and both eliminator masses,
 *   omega_x = sqrt(2 k_x / M),  omega_y = sqrt(2 k_y / M),
 *   M = M_r + m + m1 + m2,
 * and the motion is x0 cos(omega t) about the static equilibrium. The run
 * is compared with it every 5 ms over 1 s. Tolerance 1e-7 of x0: rk4 at
 * omega h < 0.006 has a phase error below 1e-9 rad over the second and the
 * observation's interpolant one below 1e-11 of x0; 0.1 % off in omega is
 * already 3e-2 (y) to 6e-2 (x) of x0 at t = 1 s. */
static void suspension_frequencies(void **state)
{
	(void)state;
	const double M_r = 90.0, m = 6.0, m1 = 12.0, k_x = 2.0e5, k_y = 6.0e4, x0 = 2e-3;
	const double M = M_r + m + 2.0 * m1;
	for (int dir = 0; dir < 2; dir++) {
		setup u = free_machine();
		const char *const sets[][2] = {{"M_r", "90"},  {"m", "6"},     {"m1", "12"},
					       {"m2", "12"},   {"k_x", "2e5"}, {"k_y", "6e4"},
					       {"beta", dir == 0 ? "0" : "90"}};
		SET_ALL(&u, sets);
		sim *s = make(&u);
		assert_int_equal(status(s).reductions & SIM_RED_SYMMETRIC, SIM_RED_SYMMETRIC);
		int coord = dir == 0 ? Q_X : Q_Y;
		double rest = status(s).q[coord];
		displace(s, coord, x0);
		double omega = sqrt(2.0 * (dir == 0 ? k_x : k_y) / M), worst = 0.0;
		for (int i = 1; i <= 200; i++) {
			double t = 5e-3 * i;
			advance(s, t);
			sim_status st = status(s);
			worst = fmax(worst, fabs(st.q[coord] - rest - x0 * cos(omega * t)));
			/* the other direction stays at rest */
			assert_close(st.q[1 - coord], 0.0, 1e-12);
		}
		if (worst > 1e-7 * x0)
			fail_msg("%s: free vibration off sqrt(2 k / M) = %.6g rad/s by %.3g m "
				 "(amplitude %.3g m)",
				 dir == 0 ? "x" : "y", omega, worst, x0);
		sim_free(s);
	}
}

/* ---- statics of an asymmetric trough ----------------------------------- */

/* (R(a) v)_x and (R(a) v)_y. */
static void rotate(double a, double vx, double vy, double out[2])
{
	out[0] = cos(a) * vx - sin(a) * vy;
	out[1] = sin(a) * vx + cos(a) * vy;
}

/* The static equilibrium of the machine with its feed's weight, by hand
 * from docs/MODEL.md, for a given trough angle alpha: the whole machine
 * (trough, unbalanced mass hanging straight down, eliminator masses on
 * their guides) under gravity, the two spring sets at body points
 * (l1, -h), (-l2, -h) with the preload, and the columns' weights at the
 * deck points (d_k, h_d). Fills q = (x, y, alpha, -, s1, s2) from the
 * force balances and returns the moment about G, which vanishes at the
 * equilibrium's alpha.
 *  - Eliminator i along its guide R(alpha) u(beta): k_si s_i = -m_i g
 *    cos(beta + alpha).
 *  - Horizontal: only the springs, k_x (u_x1 + u_x2) = 0 with u_x the
 *    spring point's displacement x + (R P - P)_x:
 *    x = -h sin(alpha) + (l1 - l2)(1 - cos alpha) / 2.
 *  - Vertical: the preload F0_1 + F0_2 carries the empty machine, the
 *    springs the feed: k_y (u_y1 + u_y2) = -W_feed.
 *  - The preload: the empty machine at x = y = alpha = 0 balances, so
 *    l1 F0_1 - l2 F0_2 = g sum m_k r_k,x there. */
static double hand_statics(const sim_params *p, int K, int L, double alpha, double q[NQ_FULL])
{
	const double g = p->g, sb = sin(p->beta), cb = cos(p->beta);
	const double W = (p->M_r + p->m + p->m1 + p->m2) * g, Wcol = L * p->m_n * g;
	const double mi[2] = {p->m1, p->m2}, ks[2] = {p->k_s1, p->k_s2};
	const double px[2] = {p->p1_x, p->p2_x}, py[2] = {p->p1_y, p->p2_y};
	const double lx[2] = {p->l1, -p->l2};
	/* the preload, from the empty machine's moment at alpha = 0 */
	double gm0 = p->m * p->w_x;
	for (int i = 0; i < 2; i++)
		gm0 += mi[i] * (px[i] - (p->c - mi[i] * g * cb / ks[i]) * sb);
	double F0[2];
	F0[0] = (g * gm0 + p->l2 * W) / (p->l1 + p->l2);
	F0[1] = W - F0[0];
	/* the force balances at alpha */
	memset(q, 0, sizeof(double) * NQ_FULL);
	q[Q_X] = -p->h * sin(alpha) + (p->l1 - p->l2) * (1.0 - cos(alpha)) / 2.0;
	q[Q_Y] = -K * Wcol / (2.0 * p->k_y) - (p->l1 - p->l2) * sin(alpha) / 2.0 -
		 p->h * (1.0 - cos(alpha));
	q[Q_ALPHA] = alpha;
	q[Q_PHI] = -M_PI / 2.0;
	double moment = 0.0, r[2];
	for (int i = 0; i < 2; i++) {
		/* spring set i */
		rotate(alpha, lx[i], -p->h, r);
		double Fx = -p->k_x * (q[Q_X] + r[0] - lx[i]);
		double Fy = -p->k_y * (q[Q_Y] + r[1] + p->h) + F0[i];
		moment += r[0] * Fy - r[1] * Fx;
		/* eliminator mass i at p_i + (c + s_i) u(beta) in the body */
		double s = -mi[i] * g * cos(p->beta + alpha) / ks[i];
		q[Q_S1 + i] = s;
		rotate(alpha, px[i] - (p->c + s) * sb, py[i] + (p->c + s) * cb, r);
		moment -= mi[i] * g * r[0];
	}
	/* the unbalanced mass: axle at w, the mass straight below it */
	rotate(alpha, p->w_x, p->w_y, r);
	moment -= p->m * g * r[0];
	/* the columns' weights at the deck points */
	for (int k = 0; k < K; k++) {
		double d = K == 1 ? 0.0 : p->column_span * (-1.0 + 2.0 * k / (K - 1.0));
		rotate(alpha, d, p->h_d, r);
		moment -= Wcol * r[0];
	}
	return moment;
}

/* An asymmetric machine (l1 != l2, h != 0, c != 0, the axle off G,
 * k_x != k_y) at rest with its feed: the start's static equilibrium is the
 * hand derivation's (hand_statics, its moment solved for alpha by the
 * secant method), and the machine stays there. The feed's weight on the
 * unequal lever arms tilts the trough (alpha = 5.9e-4 rad), the springs
 * below G then shift it sideways by -h sin(alpha), and c moves the
 * eliminator masses along their guides (their moment enters the preload
 * and the tilt). Tolerance 1e-11 m and rad: the start's Newton iteration
 * leaves residual accelerations near 1e-15 m/s^2 and the derivation is
 * exact (measured: within 1e-16); the faults of tests/mutate.sh (c
 * ignored in the geometry or the preload, h with the other sign, k_x as
 * the vertical stiffness) move x alone by 1.3e-4 to 3.5e-4 m. */
static void statics_with_h_and_c(void **state)
{
	(void)state;
	setup u = preset();
	const char *const sets[][2] = {
		{"l1", "1.1"},   {"l2", "0.7"},     {"h", "0.3"},           {"c", "0.15"},
		{"k_x", "2e5"},  {"k_y", "5e4"},    {"beta", "50"},         {"w_x", "0.1"},
		{"w_y", "0.05"}, {"columns", "3"},  {"layers", "4"},        {"m_n", "2"},
		{"h_d", "0.12"}, {"column_span", "0.6"}, {"motor_on", "false"}, {"method", "dem"},
		{"dt", "1e-4"}};
	SET_ALL(&u, sets);
	/* the secant method on the moment about G */
	double q[NQ_FULL], a0 = 0.0, a1 = 1e-4;
	double mom0 = hand_statics(&u.p, 3, 4, a0, q), mom1 = hand_statics(&u.p, 3, 4, a1, q);
	for (int it = 0; it < 50 && mom1 != mom0 && a1 != a0; it++) {
		double a2 = a1 - mom1 * (a1 - a0) / (mom1 - mom0);
		a0 = a1;
		mom0 = mom1;
		a1 = a2;
		mom1 = hand_statics(&u.p, 3, 4, a1, q);
	}
	assert_true(fabs(mom1) < 1e-9); /* N m, of moments near 1e2 */
	/* the scene is what the derivation says it is */
	assert_true(fabs(q[Q_ALPHA]) > 1e-4 && fabs(q[Q_X]) > 1e-4);
	sim *s = make(&u);
	sim_status a, b;
	assert_rests(s, 0.3, 1e-13, &a, &b);
	const char *names[NQ_FULL] = {"x", "y", "alpha", "phi", "s1", "s2"};
	for (int i = 0; i < NQ_FULL; i++) {
		if (i == Q_PHI)
			continue;
		if (!(fabs(a.q[i] - q[i]) <= 1e-11))
			fail_msg("static %s = %.12g, by hand %.12g", names[i], a.q[i], q[i]);
	}
	sim_free(s);
}

/* ---- the lever arm h: a horizontal displacement rocks the trough ------- */

/* With the spring sets h below G, a horizontal displacement x0 of G pulls
 * them back at their points (l, -h), (-l, -h): a force -2 k_x x0 below G,
 * a moment -2 k_x h x0 about it (MODEL.md's axes: X right, Y up, angles
 * counter-clockwise). The point masses made negligible (1 g each, e = 0,
 * the eliminators' springs soft), the trough alone moves, linearised:
 *   M_r x''   = -2 k_x (x + h alpha)
 *   J_r alpha'' = -2 k_x h (x + h alpha) - (2 k_y l^2 - h W) alpha
 * (h W: the preload W, the machine's weight, acts at the spring points,
 * which a tilt moves sideways by h alpha; y decouples for l1 = l2). From
 * x = x0, alpha = 0 at rest, the run is compared with the modal solution
 * of these two equations every 2 ms over 0.3 s. Tolerance 2e-4 of each
 * amplitude: the neglected masses are 1e-5 of the trough's (a phase error
 * of about 1e-4 over the 0.3 s), the geometric nonlinearity alpha^2 ~
 * 1e-7; h with the other sign rocks the trough the other way. */
static void lever_arm_rocks_the_trough(void **state)
{
	(void)state;
	const double M_r = 100.0, J_r = 20.0, k_x = 1.0e5, k_y = 4.0e4, h = 0.25, l = 0.8;
	const double x0 = 1e-3, W = (M_r + 3e-3) * 9.81;
	setup u = free_machine();
	const char *const sets[][2] = {
		{"M_r", "100"}, {"J_r", "20"},    {"k_x", "1e5"},   {"k_y", "4e4"}, {"h", "0.25"},
		{"l1", "0.8"},  {"l2", "0.8"},    {"m", "0.001"},   {"e", "0"},     {"m1", "0.001"},
		{"m2", "0.001"}, {"k_s1", "1"},   {"k_s2", "1"},    {"b_s1", "0"},  {"b_s2", "0"}};
	SET_ALL(&u, sets);
	/* the 2 x 2 problem K v = w^2 M v, M = diag(M_r, J_r) */
	const double Kxx = 2 * k_x, Kxa = 2 * k_x * h, Kaa = 2 * k_y * l * l + 2 * k_x * h * h - h * W;
	const double A = Kxx / M_r, B = Kxa / M_r, C = Kxa / J_r, D = Kaa / J_r;
	const double tr = A + D, disc = sqrt((A - D) * (A - D) + 4 * B * C);
	double w2[2] = {0.5 * (tr - disc), 0.5 * (tr + disc)}, v[2][2], coef[2];
	for (int i = 0; i < 2; i++) {
		v[i][0] = B; /* (A - w2) vx + B va = 0 */
		v[i][1] = w2[i] - A;
		/* M-orthogonal projection of (x0, 0) */
		coef[i] = M_r * v[i][0] * x0 / (M_r * v[i][0] * v[i][0] + J_r * v[i][1] * v[i][1]);
	}
	sim *s = make(&u);
	assert_int_equal(status(s).reductions & SIM_RED_SYMMETRIC, 0);
	displace(s, Q_X, x0);
	double ex = 0.0, ea = 0.0, amp_a = 0.0, first_a = 0.0;
	for (int k = 1; k <= 150; k++) {
		double t = 2e-3 * k, x = 0.0, a = 0.0;
		for (int i = 0; i < 2; i++) {
			double c = coef[i] * cos(sqrt(w2[i]) * t);
			x += c * v[i][0];
			a += c * v[i][1];
		}
		advance(s, t);
		sim_status st = status(s);
		if (k == 1)
			first_a = st.q[Q_ALPHA];
		ex = fmax(ex, fabs(st.q[Q_X] - x));
		ea = fmax(ea, fabs(st.q[Q_ALPHA] - a));
		amp_a = fmax(amp_a, fabs(a));
	}
	/* the sign on its own: a push to the right below G turns the trough
	 * clockwise (alpha < 0) at first */
	if (!(first_a < 0.0))
		fail_msg("alpha after 2 ms = %.3g rad: h = %g below G must turn it clockwise", first_a,
			 h);
	if (ex > 2e-4 * x0 || ea > 2e-4 * amp_a)
		fail_msg("x off by %.3g m (amplitude %.3g), alpha off by %.3g rad (amplitude %.3g)", ex,
			 x0, ea, amp_a);
	sim_free(s);
}

/* ---- two layers sliding under the regularised law ---------------------- */

/* Two layers on a deck held still, both sliding to the right, the bottom
 * one faster (xi'_1 = 2, xi'_2 = 1 m/s; the same as a deck moving at
 * constant speed under a stack, seen from the deck). Each contact's
 * friction opposes its own relative velocity: the deck's on layer 1
 * (normal force 2 m_n g) and layer 1's on layer 2 (m_n g), measured
 * against layer 1, not the deck. With every slip far beyond the
 * regularisation's width (tanh = 1 to the last bit) that is Coulomb's:
 *   layer 2: +mu g (dragged forward by the faster layer below),
 *   layer 1: (-2 mu m g - mu m g) / m = -3 mu g,
 * until the two meet at t = 1 / (4 mu g) = 0.036 s; at 0.02 s each has
 * moved v t + a t^2 / 2. (Friction against the deck would give -mu g to
 * both: 1.4 mm and 2.7 mm off.) Tolerance: rk4 integrates a constant
 * acceleration exactly (1e-9 m for round-off), the split method's
 * symplectic Euler is |a| h t / 2 off (2e-6 m with h = 1e-5 s), so 1e-5 m. */
static void two_layers_slide_on_each_other(void **state)
{
	(void)state;
	const char *methods[][2] = {{"rk4", "1e-5"}, {"dem", "1e-5"}};
	const double mu = 0.7, g = 9.81, t = 0.02;
	const double v0[2] = {2.0, 1.0}, acc[2] = {-3.0 * mu * g, mu * g};
	for (int mi = 0; mi < 2; mi++) {
		setup u = one_element();
		const char *const sets[][2] = {{"layers", "2"}, {"mu", "0.7"}, {"R", "1"}, {"p", "1.5"},
					       {"friction", "regularised"}, {"friction_eps", "1e-3"},
					       {"method", methods[mi][0]}, {"dt", methods[mi][1]},
					       {"substeps", "1"}};
		SET_ALL(&u, sets);
		sim *s = make(&u);
		double xi0[2];
		sim_feed_state(s, xi0, NULL);
		assert_int_equal(sim_place_feed(s, NULL, NULL, v0, NULL), SIM_OK);
		advance(s, t);
		double xi[2];
		sim_feed_state(s, xi, NULL);
		for (int j = 0; j < 2; j++) {
			double expect = v0[j] * t + 0.5 * acc[j] * t * t;
			if (!(fabs(xi[j] - xi0[j] - expect) <= 1e-5))
				fail_msg("%s: layer %d moved %.9g m, Coulomb with mu against the layer "
					 "below: %.9g m",
					 methods[mi][0], j + 1, xi[j] - xi0[j], expect);
		}
		sim_free(s);
	}
}

/* ---- the mean rotor speed against a count of whole periods ------------- */

/* Cubic Hermite on [0, H] through (p0, v0), (p1, v1) at u in [0, 1]. */
static double hermite(double p0, double v0, double p1, double v1, double H, double u)
{
	double u2 = u * u, u3 = u2 * u;
	return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * H * v0 + (-2 * u3 + 3 * u2) * p1 +
	       (u3 - u2) * H * v1;
}

/* The Kloss motor running up an asymmetric machine (alpha integrated and
 * rocking) at a speed of its own (omega_ss = 100 rad/s, a load torque):
 * the status' rotor_speed_mean is 2 pi n / (t_n - t_0), n whole periods of
 * the rotor relative to the trough, psi = phi - alpha, between its first
 * 2 pi crossing after the transient and its last. Counted here from psi
 * and psi' sampled at every step's end (t = k dt) and each crossing
 * placed by bisection on the cubic Hermite of the two samples around it.
 * Tolerance 1e-9 relative: the crossings agree to about 1e-13 s over a
 * window of 1.5 s; one period miscounted is 1/140 off. Both senses. */
static void rotor_speed_mean_counts_periods(void **state)
{
	(void)state;
	for (int r = 0; r < 2; r++) {
		setup u = preset();
		const char *const sets[][2] = {
			{"feed", "false"}, {"l2", "0.8"}, {"h", "0.2"},  {"omega_ss", "100"},
			{"e", "0.03"},     {"M_load", "3"}, {"method", "rk4"}, {"dt", "1e-4"},
			{"transient", "1"}, {"rotation", r ? "ccw" : "cw"}};
		SET_ALL(&u, sets);
		const double dt = 1e-4, transient = 1.0;
		const int steps = 50000;
		sim *s = make(&u);
		assert_int_equal(status(s).reductions & SIM_RED_SYMMETRIC, 0);
		sim_status st = status(s);
		double psi0 = st.q[Q_PHI] - st.q[Q_ALPHA], psid0 = st.qd[Q_PHI] - st.qd[Q_ALPHA];
		double t_first = NAN, t_last = NAN, rocking = 0.0;
		int n = -1;
		for (int k = 1; k <= steps; k++) {
			advance(s, k * dt);
			st = status(s);
			double psi = st.q[Q_PHI] - st.q[Q_ALPHA], psid = st.qd[Q_PHI] - st.qd[Q_ALPHA];
			rocking = fmax(rocking, fabs(st.q[Q_ALPHA]));
			double c0 = floor(psi0 / (2 * M_PI)), c1 = floor(psi / (2 * M_PI));
			if (c0 != c1) {
				/* one crossing a step at most at these speeds */
				double target = 2 * M_PI * (c1 > c0 ? c1 : c0), lo = 0.0, hi = 1.0;
				int up = c1 > c0;
				for (int it = 0; it < 60; it++) {
					double mid = 0.5 * (lo + hi);
					double f = hermite(psi0, psid0, psi, psid, dt, mid) - target;
					if ((f < 0.0) == up)
						lo = mid;
					else
						hi = mid;
				}
				double tb = (k - 1 + 0.5 * (lo + hi)) * dt;
				if (tb >= transient) {
					if (n < 0)
						t_first = tb;
					t_last = tb;
					n++;
				}
			}
			psi0 = psi;
			psid0 = psid;
		}
		double sense = r ? -1.0 : 1.0, counted = sense * 2 * M_PI * n / (t_last - t_first);
		assert_true(rocking > 1e-6); /* psi is not phi alone here */
		assert_true(n > 50);
		assert_int_equal((int)st.transport_periods, n);
		if (!(fabs(st.rotor_speed_mean - counted) <= 1e-9 * fabs(counted)))
			fail_msg("%s: rotor_speed_mean %.12g rad/s, 2 pi %d / %.9g s = %.12g rad/s",
				 r ? "ccw" : "cw", st.rotor_speed_mean, n, t_last - t_first, counted);
		/* the loaded motor runs below its synchronous speed */
		assert_true(sense * counted > 90.0 && sense * counted < 100.0);
		sim_free(s);
	}
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(settled_stack_compressions),
		cmocka_unit_test(suspension_frequencies),
		cmocka_unit_test(statics_with_h_and_c),
		cmocka_unit_test(lever_arm_rocks_the_trough),
		cmocka_unit_test(two_layers_slide_on_each_other),
		cmocka_unit_test(rotor_speed_mean_counts_periods),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
