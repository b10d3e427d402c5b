/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget_cost.c - the CPU cost model of a session: CPU s per simulated s
 * estimated from its integrator's descriptor (cost, default steps) and
 * its feed before it runs (also before its instance is built and settled:
 * srv_budget_cpu_preview), and the cost of a published sample. The cores
 * of paced sessions (budget.c) are committed from it until the worker
 * has measured the session's own; and the greatest pace a session whose
 * cost a simulated s changes with the pace (its streams') fits in.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "budget.h"

/* Calibration of the CPU estimate (docs/budgets.md "Budgets and load"): CPU s of
 * one macro step of the machine (four right-hand sides: RK4, or dem's
 * macro step) and of one feed sub-step per integrated column and per
 * integrated element (`build/convsim run` on this machine, the cost of 5
 * simulated s less that of 0.01 s); and of one published sample in a
 * paced worker, with its share of the worker's wake-ups (status, ring
 * record, trajectory row, the lock, its session's state read back into
 * the cache). tests/bench/sample_cost.sh: fleets of 150 default sessions
 * at pace 1 and 250 samples a simulated second measured 1.7 to 2.4 ms of
 * CPU per simulated s in their workers in five runs of one hour (29
 * November), the same session flat out 1.0 to 1.3: 3 to 5.4 us a sample.
 * 5 us puts a default session's estimate (2.15 ms) in the middle of those
 * runs; it was 7 us (2.65 ms, above every run), taken before a sample's
 * record and a number's text became cheaper. */
#define STEP_CPU_S 0.41e-6
#define COLUMN_SUBSTEP_CPU_S 8.0e-8
#define ELEMENT_SUBSTEP_CPU_S 0.8e-8
#define SAMPLE_CPU_S 5e-6
/* What a published sample costs a worker besides the simulation, the
 * status and the feed's arrays read out (which the probe, cpu_probe.c,
 * runs itself): the ring record and trajectory row, sleeping and waking,
 * the loop's clocks and lock. tests/bench/results/profile.md (200 default
 * sessions, 22:24 UTC 28 November): 2.7 + 8.4 + 5.5 % of 2.63 ms of
 * daemon CPU per session-second at 250 samples a simulated second, 1.7 us */
#define SAMPLE_SERVER_CPU_S 2e-6
/* and of each double of a published sample's feed record (ring, history) */
#define RECORD_DOUBLE_CPU_S 2e-9
/* The chain solve of a feed heavier than about 1.6 times the machine
 * (feed.c's column_substep; dem holds its reaction a step there): its
 * rounds, each a pass over the column's layers, grow with the layers L and
 * the mass ratio r instead of staying near one, to about L^2 (CHAIN_BASE +
 * CHAIN_SLOPE r) layer visits a sub-step and integrated column. Counted in
 * the settling of czubak2016, columns x layers 1 to 64 x 2 to 64
 * (docs/load.md "What settling costs"): 2.0 to 3.1 L up to r = 1.54 (8 x
 * 64, 16 x 32, 64 x 8: the element term's), then 0.12 L^2 at 1.73 (9 x 64),
 * 0.42 at 1.93, 0.54 to 0.68 at 2.3, 0.69 to 0.95 at 3.1 (16 x 64, 32 x 32,
 * 64 x 16), 0.87 to 1.17 at 4.6, 1.25 to 1.46 at 6.2, 1.76 at 9.3, 2.0 at
 * 12.3 (64 x 64); at 1.93 a smaller eccentricity (e = 0.012 m) made it
 * 0.71, a smaller friction (mu = 0.2) 0.11. A visit: 4.7 ns on this machine
 * under load, where the default scene's step measured 2.1 times the
 * constants above; 2.2 ns beside them. */
#define CHAIN_ONSET 1.6
#define CHAIN_BASE 0.1
#define CHAIN_SLOPE 0.2
#define CHAIN_VISIT_CPU_S 2.2e-9
/* Doubles per record of a feed: column displacements, xi and eta. */
size_t srv_budget_record_doubles(int columns, int layers)
{
	return (size_t)columns + 2 * (size_t)columns * (size_t)layers;
}

/* CPU s of one integrator step of spec (the step into *dt_out) over
 * integrated feed columns of layers elements each. */
static double step_cpu(const api_spec *spec, const sim_status *st, int integrated, int layers,
		       double *dt_out)
{
	const sim_method *m = &spec->method;
	double dt = st->dt, evals = 1, chain = 0;
	int substeps = st->substeps;
	size_t n;
	const sim_method_info *const *all = sim_methods(&n);
	for (size_t i = 0; i < n; i++) {
		if (strcmp(all[i]->name, m->name) != 0)
			continue;
		evals = all[i]->cost;
		if (all[i]->substeps && st->feed_mass_ratio > CHAIN_ONSET)
			chain = (double)layers * (double)layers *
				(CHAIN_BASE + CHAIN_SLOPE * st->feed_mass_ratio);
		if (all[i]->adaptive) {
			/* its steps follow the solution: guess the default method's */
			sim_method guess = *m;
			snprintf(guess.name, sizeof guess.name, "%s", sim_default_method());
			dt = sim_default_dt(&spec->params, &spec->scene, &guess);
			substeps = sim_default_substeps(&spec->params, &spec->scene, &guess, dt);
		}
	}
	if (!(dt > 0))
		dt = 1e-3;
	if (substeps < 1)
		substeps = 1;
	if (integrated < 0 || layers <= 0)
		integrated = 0;
	*dt_out = dt;
	return evals * (STEP_CPU_S + (double)substeps * (double)integrated *
					     (COLUMN_SUBSTEP_CPU_S + (double)layers * ELEMENT_SUBSTEP_CPU_S +
					      chain * CHAIN_VISIT_CPU_S));
}

/* CPU s per simulated s of the integration alone, no samples. */
static double run_cpu(const api_spec *spec, const sim_status *st, int columns, int layers)
{
	/* the symmetric reduction integrates one representative column */
	int integrated = (st->reductions & SIM_RED_SYMMETRIC) ? 1 : columns;
	if (columns <= 0)
		integrated = 0;
	double dt, step = step_cpu(spec, st, integrated, layers, &dt);
	return step / dt;
}

double srv_budget_cpu_estimate(const api_spec *spec, const sim_status *st,
			       int columns, int layers)
{
	return run_cpu(spec, st, columns, layers) + SAMPLE_CPU_S * spec->sample_rate;
}

/* Simulated s a steady start settles before the run (in the creating
 * request's thread, stopped at --max-cpu-seconds: session.c; or the
 * job's, uninterrupted). */
static double settling(const api_spec *spec)
{
	return spec->scene.start == SIM_START_STEADY ? spec->scene.settle : 0.0;
}

double srv_budget_settle_cpu(const api_spec *spec, const sim_status *st, int layers)
{
	double span = settling(spec), dt;
	if (!(span > 0))
		return 0;
	double step = step_cpu(spec, st, st->settle_columns, layers, &dt);
	/* whole steps (sim.c rounds the fixed-step methods' span up) */
	return ceil(span / dt - 1e-9) * step;
}

static double run_limit = 1800.0; /* CPU s: --max-cpu-seconds */

void srv_budget_cost_init(double max_cpu_seconds)
{
	run_limit = max_cpu_seconds;
}

/* What sim_new would integrate (its step in st->dt), its estimate and
 * its settling's. */
static api_err preview(const api_spec *spec, sim_status *st, double *cpu_per_s,
		       double *settle_cpu, api_problem *pb)
{
	char msg[256] = "";
	int columns, layers;
	int err = sim_preview(&spec->params, &spec->scene, &spec->method, st, &columns, &layers,
			      msg, sizeof msg);
	if (err != SIM_OK)
		return api_fail(pb, api_from_sim(err), NULL, "%s", msg[0] ? msg : sim_strerror(err));
	*cpu_per_s = srv_budget_cpu_estimate(spec, st, columns, layers);
	*settle_cpu = srv_budget_settle_cpu(spec, st, layers);
	return API_OK;
}

double srv_budget_run_limit(void)
{
	return run_limit;
}

double srv_budget_measure_cpu(const api_spec *spec, double t_end)
{
	sim_status st;
	char msg[256];
	int columns, layers;
	if (sim_preview(&spec->params, &spec->scene, &spec->method, &st, &columns, &layers, msg,
			sizeof msg) != SIM_OK)
		return 0;
	return srv_budget_settle_cpu(spec, &st, layers) +
	       run_cpu(spec, &st, columns, layers) * sim_measure_span(&spec->scene, t_end);
}

/* The range a refusal names for integrator.dt: about the least step whose
 * work cpu_s (at step dt) comes within bound, up to the settings table's
 * largest step (SI). */
static void dt_range(api_problem *pb, double dt, double cpu_s, double bound)
{
	const sim_setting *t = sim_setting_find("dt");
	pb->min = dt * cpu_s / bound;
	pb->max = t->max * t->scale;
}

double srv_budget_settle_preview(const api_spec *spec)
{
	sim_status st;
	double cpu_per_s, settle_cpu;
	api_problem pb;
	return preview(spec, &st, &cpu_per_s, &settle_cpu, &pb) == API_OK ? settle_cpu : 0.0;
}

/* ", after the S CPU s this request's thread spent before it": what a
 * settling's bound (--max-cpu-seconds) is less of, in a detail; "" for
 * none. */
static const char *spent_before(double before, char *buf, size_t len)
{
	buf[0] = '\0';
	if (before > 0)
		snprintf(buf, len, " less the %.3g CPU s this request's thread spent before it "
			 "(an experiment's measurements)", before);
	return buf;
}

api_err srv_budget_cpu_preview(const api_spec *spec, double before, double *cpu_per_s,
			       api_problem *pb)
{
	sim_status st;
	double settle_cpu;
	if (preview(spec, &st, cpu_per_s, &settle_cpu, pb) != API_OK)
		return pb->code;
	double cpu = *cpu_per_s, sample = cpu / spec->sample_rate, settle = settling(spec);
	double left = before > 0 ? fmax(run_limit - before, 0) : run_limit;
	char less[120];
	if (sample > SRV_SAMPLE_CPU_MAX) {
		/* the least step whose interval fits (dt_range's min), and
		 * the longest that is stable: asked only of a session over */
		double need_dt = st.dt * sample / SRV_SAMPLE_CPU_MAX,
		       stable_dt = sim_max_dt(&spec->params, &spec->scene, &spec->method);
		if (need_dt > stable_dt) {
			/* no step both stable and short enough: more samples
			 * a simulated second make each interval shorter */
			api_fail(pb, API_RANGE, "sample_rate",
				 "a sample interval (%g s) would take about %.3g CPU s, more than "
				 "the %g s a worker may go without taking a control, and no stable "
				 "step is long enough (integrator.dt %.3g s needed, this machine's "
				 "bound %.3g s); nothing was created: a sample_rate of at least "
				 "%.4g 1/s or a smaller scene",
				 1.0 / spec->sample_rate, sample, SRV_SAMPLE_CPU_MAX, need_dt,
				 stable_dt, cpu / SRV_SAMPLE_CPU_MAX);
			pb->min = cpu / SRV_SAMPLE_CPU_MAX;
			pb->max = API_SAMPLE_RATE_MAX;
		} else {
			api_fail(pb, API_RANGE, "integrator.dt",
				 "a sample interval (%g s) of this session would take about %.3g "
				 "CPU s (%.3g CPU s per simulated s at integrator.dt = %g s), more "
				 "than the %g s a worker may go without taking a control or its "
				 "stop; nothing was created: a larger integrator.dt or a smaller "
				 "scene", 1.0 / spec->sample_rate, sample, cpu, st.dt,
				 SRV_SAMPLE_CPU_MAX);
			dt_range(pb, st.dt, sample, SRV_SAMPLE_CPU_MAX);
		}
	} else if (settle_cpu > left) {
		double per_s = settle_cpu / settle;
		api_fail(pb, API_RANGE, "scene.settle",
			 "the steady start would settle for about %.3g CPU s (%.3g CPU s per "
			 "simulated s over scene.settle = %g s), more than --max-cpu-seconds (%g)%s; "
			 "nothing was created: a larger integrator.dt, a smaller scene, a shorter "
			 "scene.settle or scene.start \"rest\"", settle_cpu, per_s, settle, run_limit,
			 spent_before(before, less, sizeof less));
		pb->min = 0;
		pb->max = left / per_s;
	} else {
		return API_OK;
	}
	pb->has_range = 1;
	return api_budget(pb, "cpu", run_limit, 0);
}

int srv_budget_adaptive(const api_spec *spec)
{
	size_t n;
	const sim_method_info *const *all = sim_methods(&n);
	for (size_t i = 0; i < n; i++)
		if (strcmp(all[i]->name, spec->method.name) == 0)
			return all[i]->adaptive;
	return 0;
}

int srv_budget_fixed_methods(const api_spec *spec, char *names, size_t names_len,
			     char *choices, size_t choices_len)
{
	size_t n;
	const sim_method_info *const *all = sim_methods(&n);
	unsigned fixed = 0;
	names[0] = '\0';
	for (size_t i = 0; i < n && i < 32; i++) {
		if (all[i]->adaptive)
			continue;
		fixed |= 1u << i;
		size_t at = strlen(names);
		snprintf(names + at, names_len - at, "%s%s", at ? ", " : "", all[i]->name);
	}
	api_choices_of("method", fixed, choices, choices_len);
	return srv_budget_adaptive(spec);
}

int srv_budget_settle_peeked(const api_spec *spec, double left, double spent, double settled,
			     api_problem *pb)
{
	double settle = settling(spec), whole = spent / settled * settle;
	if (!(whole >= 2 * left))
		return 0;
	char names[96], choices[96];
	srv_budget_fixed_methods(spec, names, sizeof names, choices, sizeof choices);
	api_fail_choices(pb, API_RANGE, "integrator.method", choices,
			 "the steady start's settling would take about %.3g CPU s, twice what "
			 "--max-cpu-seconds (%g) leaves or more (its first %.3g CPU s settled "
			 "%.3g of scene.settle's %g s; %s is adaptive); nothing was created: a "
			 "method of a fixed step (%s), a shorter scene.settle or scene.start "
			 "\"rest\"",
			 whole, run_limit, spent, settled, settle, spec->method.name, names);
	api_budget(pb, "cpu", run_limit, 0);
	return 1;
}

api_err srv_budget_settle_stopped(const api_spec *spec, double before, double spent,
				  double settled, api_problem *pb)
{
	double settle = settling(spec);
	char names[96], choices[96], less[120];
	spent_before(before, less, sizeof less);
	if (srv_budget_fixed_methods(spec, names, sizeof names, choices, sizeof choices)) {
		api_fail_choices(pb, API_RANGE, "integrator.method", choices,
				 "the steady start's settling stopped at %.3g CPU s, past "
				 "--max-cpu-seconds (%g)%s, %.3g of scene.settle's %g simulated s "
				 "settled: no estimate knows the steps of integrator.method %s "
				 "(adaptive); nothing was created: a method of a fixed step (%s), a "
				 "shorter scene.settle or scene.start \"rest\"",
				 spent, run_limit, less, settled, settle, spec->method.name, names);
	} else {
		/* the range: what settled within the limit */
		api_fail_range(pb, "scene.settle", 0, settled,
			       "the steady start's settling stopped at %.3g CPU s, past "
			       "--max-cpu-seconds (%g)%s, %.3g of scene.settle's %g simulated s "
			       "settled, estimated within it; nothing was created: a shorter "
			       "scene.settle, a larger integrator.dt, a smaller scene or "
			       "scene.start \"rest\"",
			       spent, run_limit, less, settled, settle);
	}
	return api_budget(pb, "cpu", run_limit, 0);
}

api_err srv_budget_run_check(const api_spec *spec, double t_end, api_problem *pb)
{
	sim_status st;
	double cpu, settle_cpu;
	if (preview(spec, &st, &cpu, &settle_cpu, pb) != API_OK)
		return API_OK; /* a set sim_new refuses: the run fails at once */
	double run = settle_cpu + cpu * t_end, longest = (run_limit - settle_cpu) / cpu;
	if (!(run > run_limit))
		return API_OK;
	int none = !(longest > spec->scene.transient);
	api_fail(pb, API_RANGE, none ? "integrator.dt" : "t_end",
		 "a run would take about %.3g CPU s (%.3g CPU s settling %g s, then %.3g CPU s "
		 "per simulated s at integrator.dt = %g s over t_end = %g s), more than "
		 "--max-cpu-seconds (%g), and nothing stops a run once begun; nothing was "
		 "started: %s",
		 run, settle_cpu, settling(spec), cpu, st.dt, t_end, run_limit,
		 none ? "a larger integrator.dt or a smaller scene" : "a shorter t_end, a larger "
								      "integrator.dt or a smaller scene");
	pb->has_range = 1;
	if (none) {
		dt_range(pb, st.dt, run, run_limit);
	} else {
		pb->min = spec->scene.transient;
		pb->max = longest;
	}
	return api_budget(pb, "cpu", run_limit, 0);
}

double srv_budget_sample_cpu(int columns, int layers)
{
	return SAMPLE_SERVER_CPU_S + RECORD_DOUBLE_CPU_S * (double)srv_budget_record_doubles(columns, layers);
}

double srv_budget_greatest_pace(srv_pace_cost cost, const void *session, double cores)
{
	double lo = 0, hi = 1;
	if (!(cores > 0))
		return 0;
	while (hi * cost(session, hi) <= cores && hi < 1e12)
		hi *= 2;
	for (int i = 0; i < 64; i++) {
		double mid = 0.5 * (lo + hi);
		if (mid * cost(session, mid) <= cores)
			lo = mid;
		else
			hi = mid;
	}
	return lo;
}
