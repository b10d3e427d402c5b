/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * testutil.h - shared set-up for the core's unit tests (cmocka): the
 * czubak2016 preset with changes, running an instance to a time, and
 * assertions on doubles with a message that shows both values.
 */
#ifndef CONVSIM_TESTUTIL_H
#define CONVSIM_TESTUTIL_H

#include <math.h>
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <cmocka.h>

#include "sim.h"
#include "units.h"

typedef struct setup {
	sim_params p;
	sim_scene sc;
	sim_method m;
} setup;

/* The czubak2016 preset as the paper's scene, which most known-answer
 * tests are written for: the run-up from rest (start = rest), the full
 * model (trough_rotation = true) and v measured after 2 s. Tests of the
 * defaults themselves use preset_defaults(). */
static inline setup preset_defaults(void)
{
	setup u;
	sim_preset_czubak2016(&u.p, &u.sc, &u.m);
	return u;
}

static inline setup preset(void)
{
	setup u = preset_defaults();
	u.sc.start = SIM_START_REST;
	u.sc.trough_rotation = 1;
	u.sc.transient = 2.0;
	return u;
}

/* Set NAME=VALUE (user units) or fail the test. */
static inline void set(setup *u, const char *name, const char *value)
{
	char msg[200];
	int e = sim_set_user_str(&u->p, &u->sc, &u->m, name, value, msg, sizeof msg);
	if (e != SIM_OK)
		fail_msg("set %s=%s: %s", name, value, msg);
}

/* One element (one column, one layer) on a deck held still: motor off and
 * one-way coupling, so the machine stays at rest whatever the feed does. */
static inline setup one_element(void)
{
	setup u = preset();
	set(&u, "trough_rotation", "false");
	set(&u, "columns", "1");
	set(&u, "layers", "1");
	set(&u, "motor_on", "false");
	set(&u, "feed_coupling", "false");
	return u;
}

/* The reduced scene (alpha dropped, one column) with the ideal drive. */
static inline setup reduced_ideal(void)
{
	setup u = preset();
	set(&u, "trough_rotation", "false");
	set(&u, "drive", "ideal");
	set(&u, "transient", "0.5");
	return u;
}

/* sim_measure's transport velocity (m/s) into *v; its return code. */
static inline int measure_v(const setup *u, double t_end, double *v, char *msg, size_t msglen)
{
	sim_measurement r;
	int e = sim_measure(&u->p, &u->sc, &u->m, t_end, &r, msg, msglen);
	*v = r.transport_velocity;
	return e;
}

static inline sim *make(const setup *u)
{
	char msg[200];
	int err;
	sim *s = sim_new(&u->p, &u->sc, &u->m, &err, msg, sizeof msg);
	if (!s)
		fail_msg("sim_new: %s", msg);
	return s;
}

static inline void advance(sim *s, double t)
{
	int e = sim_advance(s, t);
	if (e != SIM_OK)
		fail_msg("sim_advance(%g): %s", t, sim_last_error(s));
}

static inline sim_status status(const sim *s)
{
	sim_status st;
	sim_get_status(s, &st);
	return st;
}

/* The status of a fresh instance of u after t_end simulated seconds. */
static inline sim_status run_status(const setup *u, double t_end)
{
	sim *s = make(u);
	advance(s, t_end);
	sim_status st = status(s);
	sim_free(s);
	return st;
}

/* The running transport velocity (m/s) of a fresh instance of u after
 * t_end simulated seconds. */
static inline double run_velocity(const setup *u, double t_end)
{
	return run_status(u, t_end).transport_velocity;
}

#define assert_close(a, b, tol)                                                           \
	do {                                                                              \
		double a_ = (a), b_ = (b), t_ = (tol);                                    \
		if (!(fabs(a_ - b_) <= t_))                                               \
			fail_msg("%s = %.12g, %s = %.12g, |diff| %.3g > %.3g", #a, a_, #b, b_, \
				 fabs(a_ - b_), t_);                                      \
	} while (0)

#define assert_rel(a, b, rel) assert_close(a, b, (rel) * fabs(b))

/* Advance s to t_end and check that no machine coordinate moved by more
 * than tol (m, rad); returns the status before and after. */
static inline void assert_rests(sim *s, double t_end, double tol, sim_status *before,
				sim_status *after)
{
	*before = status(s);
	advance(s, t_end);
	*after = status(s);
	for (int i = 0; i < 6; i++)
		assert_close(after->q[i], before->q[i], tol);
}

#endif
