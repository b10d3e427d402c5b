/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_disturb.c - the feed's disturbances on a running instance
 * (sim_set_feed, docs/MODEL.md "Disturbances"): a settled column under a
 * new m_n is settled again, with each contact's compression the new
 * load's (W_above / k)^(1/p); mid-run every element keeps its horizontal
 * position and velocities, the compressions scale by (m_new / m_old)^(1/p)
 * and the energy books close across the change (the residual does not
 * move, and the terms close within 0.1 % of the input a second later); a
 * change of mu moves nothing; the checkpoint carries the new values (and
 * a version 3 checkpoint still restores, with the values of its start);
 * and the refusals change nothing.
 */
#include "sim_int.h" /* the state vector, to compare the feed's velocities */
#include "testutil.h"

/* The feed's block b (0 xi, 1 eta, 2 xi', 3 eta') of y, nf values. */
static const double *feed_block(const sim *s, const double *y, int b)
{
	const model *md = &s->md;
	int off[4] = {md->nq, md->nq + md->nf, md->npos + md->nq, md->npos + md->nq + md->nf};
	return y + off[b];
}

/* The machine at rest (motor off, rest start): the feed settled on the
 * deck. Doubling m_n with p = 1.5 leaves each contact at the new load's
 * compression, to round-off. */
static void settled_column_settles_anew(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "start", "rest");
	set(&u, "motor_on", "false");
	set(&u, "p", "1.5");
	sim *s = make(&u);
	const model *md = &s->md;
	double xi0[SIM_MAX_COLUMNS * 64];
	memcpy(xi0, feed_block(s, s->y, 0), sizeof(double) * (size_t)md->nf);
	assert_int_equal(sim_set_feed(s, 0.8, NAN), SIM_OK);
	double q[NQ_FULL], qd[NQ_FULL];
	deck_motion dm;
	model_full_coords(md, &s->ctl, s->t_int, s->y, q, qd);
	deck_motion_eval(&md->dk, q, qd, &dm);
	const double *eta = feed_block(s, s->y, 1), *xi = feed_block(s, s->y, 0);
	const double k_c = u.p.k_c, g = u.p.g;
	const int L = md->L;
	for (int k = 0; k < md->dk.K; k++) {
		double below = dm.pos[k][1];
		for (int j = 0; j < L; j++) {
			double load = (double)(L - j) * 0.8 * g;
			assert_close(below - eta[k * L + j], pow(load / k_c, 1.0 / 1.5), 1e-12);
			assert_true(xi[k * L + j] == xi0[k * L + j]);
			below = eta[k * L + j];
		}
	}
	sim_status st = status(s);
	assert_true(st.m_n == 0.8 && st.mu == u.p.mu);
	assert_close(st.e_residual, 0.0, 1e-9);
	sim_free(s);
}

/* Mid-run on the defaults (dem, steady start, beta 30 deg): +50 % load. */
static void load_step_keeps_the_state_and_the_books(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "beta", "30");
	sim *s = make(&u);
	advance(s, 0.5);
	const model *md = &s->md;
	const int nf = md->nf;
	double *before = malloc(sizeof(double) * (size_t)md->n);
	assert_non_null(before);
	memcpy(before, s->y, sizeof(double) * (size_t)md->n);
	sim_status a = status(s);
	assert_int_equal(sim_set_feed(s, 0.75, NAN), SIM_OK);
	sim_status b = status(s);
	/* horizontal positions and both velocities kept, bit for bit */
	for (int blk = 0; blk < 4; blk += blk == 0 ? 2 : 1)
		for (int e = 0; e < nf; e++)
			assert_true(feed_block(s, s->y, blk)[e] == feed_block(s, before, blk)[e]);
	/* the compressions scaled by 1.5 (p = 1), gaps kept: the bottom
	 * layer's first, from the deck point where y puts it */
	double q[NQ_FULL], qd[NQ_FULL];
	deck_motion dm;
	model_full_coords(md, &s->ctl, s->t_int, s->y, q, qd);
	deck_motion_eval(&md->dk, q, qd, &dm);
	int closed = 0;
	for (int k = 0; k < md->dk.K; k++) {
		double below0 = dm.pos[k][1], below1 = dm.pos[k][1];
		for (int j = 0; j < md->L; j++) {
			int e = k * md->L + j;
			double d0 = below0 - feed_block(s, before, 1)[e];
			double d1 = below1 - feed_block(s, s->y, 1)[e];
			assert_close(d1, d0 > 0 ? 1.5 * d0 : d0, 1e-15);
			closed += d0 > 0;
			below0 = feed_block(s, before, 1)[e];
			below1 = feed_block(s, s->y, 1)[e];
		}
	}
	assert_true(closed > 0);
	free(before);
	/* the books: the jump is input, the residual does not move */
	assert_true(b.m_n == 0.75);
	assert_true(b.e_disturb != 0.0);
	assert_close(b.e_input - a.e_input, b.e_disturb, 1e-9 * a.e_input);
	assert_close(b.e_residual, a.e_residual, 1e-9 * a.e_input);
	/* and they close a second later as they did before the change */
	advance(s, 1.5);
	sim_status c = status(s);
	double gap = c.e_kinetic + c.e_potential + c.e_dissipated - c.e_input;
	assert_close(gap, c.e_residual, 1e-9 * c.e_input);
	assert_true(fabs(c.e_residual) <= 1e-3 * c.e_input);
	print_message("+50 %% load at 0.5 s: residual %.3g J of %.4g J input at 1.5 s, "
		      "the change brought %.4g J\n", c.e_residual, c.e_input, c.e_disturb);
	assert_true(isfinite(c.transport_velocity));
	sim_free(s);
}

/* mu alone moves nothing and brings no energy; a lighter load during the
 * run-up from rest closes the books too. */
static void friction_step_moves_nothing(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "start", "rest");
	sim *s = make(&u);
	advance(s, 0.3);
	const model *md = &s->md;
	double *before = malloc(sizeof(double) * (size_t)md->n);
	assert_non_null(before);
	memcpy(before, s->y, sizeof(double) * (size_t)md->n);
	sim_status a = status(s);
	assert_int_equal(sim_set_feed(s, NAN, 0.8), SIM_OK);
	assert_memory_equal(before, s->y, sizeof(double) * (size_t)md->n);
	sim_status b = status(s);
	assert_true(b.mu == 0.8 && b.m_n == 0.5 && b.e_input == a.e_input && b.e_disturb == 0.0);
	assert_int_equal(sim_set_feed(s, 0.3, NAN), SIM_OK);
	b = status(s);
	assert_close(b.e_residual, a.e_residual, 1e-9 * a.e_input);
	advance(s, 0.6);
	sim_status c = status(s);
	assert_true(fabs(c.e_residual) <= 1e-3 * c.e_input);
	free(before);
	sim_free(s);
}

/* Refusals: out of the table's range, past the corrector's edge, no
 * column feed; nothing changes. */
static void refusals_change_nothing(void **state)
{
	(void)state;
	setup u = preset_defaults();
	double lo, hi;
	sim_feed_mass_range(&u.p, &u.sc, &u.m, &lo, &hi);
	/* 0.2 of the machine's 166 kg over 5 x 8 elements */
	assert_close(hi, 0.2 * 166.0 / 40.0, 1e-12);
	assert_true(lo == 1e-4);
	sim *s = make(&u);
	sim_status a = status(s);
	assert_int_equal(sim_set_feed(s, 200.0, NAN), SIM_EPARAM);
	assert_int_equal(sim_set_feed(s, 0.9, NAN), SIM_EPARAM);
	assert_int_equal(sim_set_feed(s, NAN, 2.5), SIM_EPARAM);
	assert_int_equal(sim_set_feed(s, NAN, -0.1), SIM_EPARAM);
	assert_int_equal(sim_set_feed(s, INFINITY, NAN), SIM_EPARAM);
	sim_status b = status(s);
	assert_true(b.m_n == a.m_n && b.mu == a.mu && b.e_input == a.e_input);
	sim_free(s);
	/* rk4 has no corrector: the table's range */
	set(&u, "method", "rk4");
	sim_feed_mass_range(&u.p, &u.sc, &u.m, &lo, &hi);
	assert_true(lo == 1e-4 && hi == 100.0);
	setup v = preset_defaults();
	set(&v, "feed", "false");
	s = make(&v);
	assert_int_equal(sim_set_feed(s, 0.6, NAN), SIM_EPARAM);
	sim_free(s);
	/* heavier than the contacts hold: on k_c = 2e4 N/m the column of 8
	 * rests 36 m_n g / k_c deep, 5 cm at m_n = 0.05 x 2e4 / (36 g) =
	 * 2.83 kg (u runs rk4 now: no corrector's bound below it) */
	set(&u, "k_c", "2e4");
	double most = 0.05 * 2e4 / (36.0 * u.p.g);
	assert_close(sim_m_n_most(&u.p, &u.sc), most, 1e-12);
	s = make(&u);
	assert_int_equal(sim_set_feed(s, 1.01 * most, NAN), SIM_EPARAM);
	assert_int_equal(sim_set_feed(s, 0.99 * most, NAN), SIM_OK);
	sim_free(s);
}

/* A checkpoint after a change restores the changed feed and continues bit
 * for bit; one of version 3 (without the disturbances' part) restores
 * with the values of the start. */
static void checkpoint_carries_the_change(void **state)
{
	(void)state;
	setup u = preset_defaults();
	set(&u, "method", "rk4");
	set(&u, "dt", "1e-4");
	sim *s = make(&u);
	advance(s, 0.05);
	assert_int_equal(sim_set_feed(s, 0.6, 0.3), SIM_OK);
	size_t len = sim_checkpoint_size(s);
	unsigned char *buf = malloc(len);
	assert_non_null(buf);
	assert_int_equal(sim_checkpoint(s, buf, len), SIM_OK);
	int err;
	char msg[200] = "";
	sim *r = sim_restore(&u.p, &u.sc, &u.m, buf, len, &err, msg, sizeof msg);
	assert_non_null(r);
	advance(s, 0.1);
	advance(r, 0.1);
	sim_status a = status(s), b = status(r);
	assert_true(b.m_n == 0.6 && b.mu == 0.3);
	assert_memory_equal(s->y, r->y, sizeof(double) * (size_t)s->md.n);
	assert_true(a.e_residual == b.e_residual && a.e_disturb == b.e_disturb);
	sim_free(r);
	/* version 3: the part cut out (no shadow runs with rk4: the step
	 * error's part, 32 bytes, closes the payload) */
	const size_t head = 48, part = 3 * sizeof(double), tail = 32;
	memmove(buf + len - tail - part, buf + len - tail, tail);
	len -= part;
	uint32_t v3 = 3;
	uint64_t payload = len - head;
	memcpy(buf + 8, &v3, sizeof v3);
	memcpy(buf + 32, &payload, sizeof payload);
	uint64_t sum = sim_checksum(buf + head, payload);
	memcpy(buf + 40, &sum, sizeof sum);
	r = sim_restore(&u.p, &u.sc, &u.m, buf, len, &err, msg, sizeof msg);
	if (!r)
		fail_msg("version 3: %s", msg);
	b = status(r);
	assert_true(b.m_n == 0.5 && b.mu == u.p.mu && b.e_disturb == 0.0);
	sim_free(r);
	free(buf);
	sim_free(s);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(settled_column_settles_anew),
		cmocka_unit_test(load_step_keeps_the_state_and_the_books),
		cmocka_unit_test(friction_step_moves_nothing),
		cmocka_unit_test(refusals_change_nothing),
		cmocka_unit_test(checkpoint_carries_the_change),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
