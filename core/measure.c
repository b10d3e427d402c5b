/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * measure.c - sim_measure: one measurement of the transport velocity, a
 * fresh instance run to a time with its shadow (shadow.c) over the first
 * part of the window, repeated at finer steps where the measured step
 * error is beyond what the accuracy target tol allows.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>
#include <time.h>

#include "sim_int.h"

/* A measurement's shadow runs over this share of its window: long enough
 * for its estimate to settle (30 periods of the preset's 4-s
 * window), short enough to keep the shadow's cost near a fifth. */
#define SHADOW_MEASURE_SHARE 0.3

/* sim_measure's refinements at most: each shrinks the feed step, or the
 * machine step where its term is the larger, by the factor the
 * first-order error asks for, within [1/4, 3/5]. */
#define MEASURE_REFINEMENTS 3

/* One run of sim_measure: a fresh instance to t_end, its shadow over the
 * first SHADOW_MEASURE_SHARE of the window; *st its final status. */
static int measure_once(const sim_params *p, const sim_scene *sc, const sim_method *m,
			double t_end, sim_status *st, char *msg, size_t msglen)
{
	*st = (sim_status){.transport_velocity = NAN, .transport_velocity_uncertainty = NAN,
			   .rotor_speed_mean = NAN, .step_error = NAN, .tol_allowed = NAN};
	int err;
	double window = SHADOW_MEASURE_SHARE * (t_end - fmax(0.0, sc->transient));
	sim *s = sim_new_windowed(p, sc, m, window > 0.0 ? window : 0.0, &err, msg, msglen);
	if (!s)
		return err;
	err = sim_advance(s, t_end);
	if (err != SIM_OK && msg)
		snprintf(msg, msglen, "%s", s->error);
	*st = s->st;
	sim_free(s);
	return err;
}

int sim_measure(const sim_params *p, const sim_scene *sc, const sim_method *m, double t_end,
		sim_measurement *out, char *msg, size_t msglen)
{
	struct timespec c0, c1;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c0);
	*out = (sim_measurement){.transport_velocity = NAN, .uncertainty = NAN,
				 .rotor_speed_mean = NAN, .step_error = NAN};
	sim_method run = *m;
	sim_status st;
	int err;
	/* the steps are the engine's to choose only where the user left them */
	const ode_method *om = ode_find(m->name);
	int own_steps = m->dt == 0.0 && m->substeps == 0 && om && !(om->info.dt_feed > 0);
	double last = INFINITY;
	for (int attempt = 0;; attempt++) {
		err = measure_once(p, sc, &run, t_end, &st, msg, msglen);
		out->refinements = attempt;
		/* what the steps may take of tol: the bar less its scatter and
		 * drift, which finer steps cannot shrink */
		double room = st.tol_allowed - (st.transport_velocity_uncertainty - st.step_error);
		/* done: within tol, the user's own steps, no room the steps could
		 * fit in, or a refinement that did not shrink the step error as a
		 * first-order one shrinks (by 0.6 at least): what remains is not
		 * the steps' */
		if (err != SIM_OK || !own_steps || st.tol_met || attempt == MEASURE_REFINEMENTS ||
		    !(room > 0.0) || !(st.step_error > room) || !(st.step_error < 0.8 * last) ||
		    st.substeps < 1)
			break;
		last = st.step_error;
		/* first order in both steps: the step whose term is the larger
		 * shrinks by the factor asked (the machine step with the feed
		 * step, which the sub-steps keep in proportion) */
		double f = fmin(0.6, fmax(0.25, 0.7 * room / st.step_error));
		if (st.machine_error > st.step_error - st.machine_error) {
			run.dt = st.dt * f;
			run.substeps = st.substeps;
		} else {
			run.dt = st.dt;
			run.substeps = (int)ceil(st.substeps / f);
		}
		if (run.substeps > 1000)
			break;
	}
	out->transport_velocity = st.transport_velocity;
	out->uncertainty = st.transport_velocity_uncertainty;
	out->steady = st.steady;
	out->periods = st.transport_periods;
	out->rotor_speed_mean = st.rotor_speed_mean;
	out->step_error = st.step_error;
	out->tol_met = st.tol_met;
	out->dt = st.dt;
	out->substeps = st.substeps;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &c1);
	out->cpu_seconds = (double)(c1.tv_sec - c0.tv_sec) + 1e-9 * (double)(c1.tv_nsec - c0.tv_nsec);
	return err;
}
