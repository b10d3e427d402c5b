/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_cost.c - an identification's or a closed loop's measurements
 * in the request's thread before it answers: their cost estimated and
 * bounded, then run (srv_exp_ready; experiment_kind.c's srv_exp_prepare
 * runs them: an identification's slopes, two runs of the scene per
 * operating point; a closed loop's v(beta) curve, 73 runs, and those of
 * the scenes its disturbances of rotation or omega_ss lead to, each
 * spared where the cache has it; the identification behind "auto"
 * gains). Nothing interrupts them once begun (a 16 x 16 scene's curve is
 * about ten CPU seconds), so they are estimated first with the sessions'
 * cost model (budget_cost.c: each run's settling, then its window and
 * shadow) and refused beyond --max-cpu-seconds, the bound of a steady
 * start's settling in a creating request (docs/load.md "Creations
 * that settle"). One request, one bound: a fresh session settles after
 * them in the same thread, so its settling's estimate counts here too, and
 * it settles within what they left (session.c).
 */
#include <stdio.h>
#include <stdlib.h>

#include "budget.h"
#include "experiment_int.h"
#include "util.h"

/* One measurement of the curve or of a slope: to the transient and the
 * window. */
static double one_run(const api_spec *spec)
{
	return srv_budget_measure_cpu(spec, spec->scene.transient + SRV_EXP_CURVE_WINDOW);
}

/* The estimate for e on spec's scene: CPU s of the measurements, the
 * runs and the curves, and CPU s of the fresh session's settling after
 * them (0 on a running session). */
typedef struct measuring {
	double cpu;
	int runs, curves;
	double settle;
} measuring;

static measuring estimate(const srv_experiment *e, const api_spec *spec)
{
	const api_exp_ext *x = &e->ext;
	measuring m = {0, 0, 0, 0};
	if (x->kind != API_EXP_IDENTIFY && x->kind != API_EXP_CONTROL)
		return m;
	if (e->req.fresh)
		m.settle = srv_budget_settle_preview(spec);
	if (x->kind == API_EXP_IDENTIFY) {
		m.runs = 2 * x->npoints;
		m.cpu = m.runs * one_run(spec);
		return m;
	}
	if (!srv_exp_curve_cached(spec)) {
		m.curves++;
		m.cpu += API_FF_NODES * one_run(spec);
	}
	if (x->auto_gains) { /* one run of five segments */
		m.runs++;
		m.cpu += srv_budget_measure_cpu(spec, 5 * SRV_EXP_SCRATCH_HOLD);
	}
	/* each distinct curve the disturbances lead to, unless cached */
	api_spec *at = malloc(API_EXP_MAX_DIST * sizeof *at);
	int n = at ? srv_exp_dist_specs(x, spec, at) : 0;
	for (int k = 0; k < n; k++) {
		int seen = srv_exp_same_curve(&at[k], spec) || srv_exp_curve_cached(&at[k]);
		for (int j = 0; j < k && !seen; j++)
			seen = srv_exp_same_curve(&at[k], &at[j]);
		if (!seen) {
			m.curves++;
			m.cpu += API_FF_NODES * one_run(&at[k]);
		}
	}
	free(at);
	m.runs += m.curves * API_FF_NODES;
	return m;
}

/* The most columns, fewer than spec's, whose measurements for e fit
 * bound; 0 where none does. */
static int columns_that_fit(const srv_experiment *e, const api_spec *spec, double bound)
{
	api_spec *at = malloc(sizeof *at);
	int c = at ? spec->scene.columns - 1 : 0;
	if (at)
		*at = *spec;
	for (; c >= 1; c--) {
		at->scene.columns = c;
		measuring m = estimate(e, at);
		if (!(m.cpu + m.settle > bound))
			break;
	}
	free(at);
	return c;
}

api_err srv_exp_measuring_check(const srv_experiment *e, const api_spec *spec, double *cpu,
				api_problem *pb)
{
	measuring m = estimate(e, spec);
	double bound = srv_budget_run_limit();
	*cpu = m.cpu;
	if (!(m.cpu + m.settle > bound))
		return API_OK;
	const api_exp_ext *x = &e->ext;
	char what[160], fix[160];
	/* a problem's detail has room for the settling's name, not its figure */
	const char *then = m.settle > 0 ? " and its session's settling" : "";
	const char *when = m.settle > 0 ? "" : " before it answers and";
	const char *field = "session";
	double max = 0;
	if (x->kind == API_EXP_IDENTIFY) {
		snprintf(what, sizeof what, "identify's slopes (%d runs of the scene: two per operating "
			 "point)", m.runs);
		max = (double)(int)((bound - m.settle) / (2 * one_run(spec)));
	} else {
		snprintf(what, sizeof what, "control's v(beta) curve%s (%d runs of the scene%s)",
			 m.curves == 1 ? "" : "s", m.runs,
			 x->auto_gains ? ", one the identification behind \"auto\" gains" : "");
	}
	if (max >= 1) {
		field = "identify.beta";
		snprintf(fix, sizeof fix, "at most %g operating point%s, a larger integrator.dt or "
			 "a smaller scene", max, api_plural(max, "", "s"));
	} else if (e->req.fresh) {
		field = "session.scene.columns";
		max = columns_that_fit(e, spec, bound);
		if (max >= 1)
			snprintf(fix, sizeof fix, "a smaller scene (at most %g column%s of %d "
				 "layer%s) or a larger integrator.dt", max, api_plural(max, "", "s"),
				 spec->scene.layers, api_plural(spec->scene.layers, "", "s"));
		else
			snprintf(fix, sizeof fix, "fewer layers or a larger integrator.dt");
	} else {
		snprintf(fix, sizeof fix, "a session of a smaller scene or a larger integrator.dt");
	}
	api_fail(pb, API_RANGE, field,
		 "%s%s would take about %.3g CPU s in this request's thread,%s uninterrupted, more "
		 "than --max-cpu-seconds (%g); nothing was started: %s",
		 what, then, m.cpu + m.settle, when, bound, fix);
	if (max >= 1) {
		pb->has_range = 1;
		pb->min = 1;
		pb->max = max;
	}
	return api_budget(pb, "cpu", bound, 0);
}

api_err srv_exp_ready(srv_experiment *e, const api_spec *spec, api_problem *pb)
{
	if (e->ext.kind == API_EXP_SCHEDULE)
		return API_OK;
	/* its measurements settle and run instances in the request's thread
	 * (a closed loop's v(beta) curve: 73 of them), which nothing
	 * interrupts: refused beyond --max-cpu-seconds before any runs, then
	 * one of the --max-settling slots meanwhile, as a session's creation */
	double estimate;
	if (srv_exp_measuring_check(e, spec, &estimate, pb) != API_OK)
		return pb->code;
	int settling = 0;
	if (srv_budget_take_settling(&settling, pb) != API_OK)
		return pb->code;
	double cpu0 = srv_thread_cpu();
	/* stopped at the bound whatever the method (an adaptive one's steps
	 * are beyond the estimate): srv_exp_stopped */
	api_err err = srv_exp_prepare(e, spec, cpu0 + srv_budget_run_limit(), pb);
	srv_budget_give_settling(&settling);
	e->measured_cpu = srv_thread_cpu() - cpu0; /* a fresh session settles within the rest */
	srv_log(SRV_LOG_DEBUG, "experiment: measured for %.3g CPU s in the request's thread, "
		"estimated at %.3g", e->measured_cpu, estimate);
	return err;
}

double srv_exp_measured_cpu(const srv_experiment *e)
{
	return e->measured_cpu;
}
