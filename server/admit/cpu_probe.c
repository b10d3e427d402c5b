/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cpu_probe.c - the measured cost of a session before it runs (see
 * cpu_probe.h). The copy goes through sim_checkpoint and sim_restore,
 * which continue bit for bit from the live instance's state without its
 * equilibrium and settling (seconds for a large feed), so the probe costs
 * what it measures and little more. Its time is the calling thread's CPU
 * clock, as the worker's own measurement (worker.c measure_cost) is. It
 * measures the copy without its shadow (shadow.c): a session's steady
 * cost, what it holds once its start is over.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "cpu_probe.h"
#include "util.h"

double srv_cpu_probe(const sim *live, const api_spec *spec, int columns, int layers,
		     double cpu_s, double deadline, const char *id)
{
	size_t len = sim_checkpoint_size(live), n = (size_t)columns * (size_t)layers;
	void *buf = malloc(len);
	double *feed = malloc(((size_t)columns + 2 * n + 1) * sizeof *feed);
	sim *copy = NULL;
	double cost = -1;
	char msg[160];
	int err = 0;
	if (!buf || !feed || sim_checkpoint(live, buf, len) != SIM_OK)
		goto out;
	copy = sim_restore(&spec->params, &spec->scene, &spec->method, buf, len,
			   &err, msg, sizeof msg);
	if (!copy)
		goto out;
	/* the cost it is admitted for is its steady one: the shadow that
	 * measures the step error runs only over a session's start (40
	 * periods) and after a control, and doubled a default session's probe
	 * (4.3-5.2 ms of CPU per simulated s with it, 2.5-2.7 without; the
	 * worker then measures 2.4-2.6) */
	sim_drop_shadow(copy);
	sim_status st;
	sim_get_status(copy, &st);
	/* sample by sample, each sample in pieces of at most
	 * SRV_PROBE_PIECE_S: a sample of a slow rate (1 s at 1 per s) of a
	 * dear scene would otherwise be one piece of seconds of CPU */
	double t0 = st.t, t = t0, dt = 1.0 / spec->sample_rate, sample = t0 + dt;
	double cpu0 = srv_thread_cpu(), cpu = cpu0;
	while (cpu - cpu0 < cpu_s && t - t0 < SRV_PROBE_T_S) {
		t = fmin(sample, t + SRV_PROBE_PIECE_S);
		int e = sim_advance_bounded(copy, t, deadline);
		if (e == SIM_ECPU) { /* the creation's bound: what it ran */
			sim_get_status(copy, &st);
			t = st.t;
			cpu = srv_thread_cpu();
			break;
		}
		if (e != SIM_OK)
			break;
		if (t >= sample) {
			sim_get_status(copy, &st);
			if (columns > 0) {
				sim_column_displacement(copy, feed);
				sim_feed_state(copy, feed + columns, feed + columns + n);
			}
			sample = t + dt;
		}
		cpu = srv_thread_cpu();
	}
	if (t > t0) {
		cost = (cpu - cpu0) / (t - t0) +
		       srv_budget_sample_cpu(columns, layers) * spec->sample_rate;
		srv_log(SRV_LOG_DEBUG, "session %s: probe %.3g ms of CPU per simulated s over "
			"%.3g simulated s", id, 1e3 * cost, t - t0);
	}
out:
	sim_free(copy);
	free(feed);
	free(buf);
	return cost;
}

int srv_cpu_settle_peek(const api_spec *spec, double cpu0, double deadline, sim **out,
			api_problem *pb)
{
	*out = NULL;
	if (!srv_budget_adaptive(spec) || cpu0 + SRV_SETTLE_PEEK_CPU >= deadline)
		return 0;
	double settled = 0, held = 0;
	int err = SIM_OK;
	char msg[64];
	*out = sim_new_bounded(&spec->params, &spec->scene, &spec->method,
			       cpu0 + SRV_SETTLE_PEEK_CPU, &settled, &err, msg, sizeof msg);
	if (*out || err != SIM_ECPU || !(settled > 0))
		return 0; /* settled, or failed: the whole settling says why */
	double spent = srv_thread_cpu() - cpu0, per_s = spent / settled;
	if (spec->pace == API_PACE_MAX || per_s * spec->pace < 2 * srv_budget_paced_limit())
		return srv_budget_settle_peeked(spec, deadline - cpu0, spent, settled, pb);
	srv_budget_take_paced(&held, per_s, spec->pace, "pace", "created", pb);
	size_t at = strlen(pb->detail);
	snprintf(pb->detail + at, sizeof pb->detail - at, " (measured over the first %g CPU s of "
		 "its settling: integrator.method %s is adaptive)", SRV_SETTLE_PEEK_CPU,
		 spec->method.name);
	return 1;
}
