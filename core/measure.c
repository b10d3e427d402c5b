/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * measure.c - sim_measure: one measurement of the transport velocity, a fresh instance run
 * to a time with its shadow (shadow.c) over the first part of the window, repeated at finer
 * steps where the measured step error is beyond what the accuracy target tol allows;
 * sim_measure_point, a sweep's point: the same, stopped early once its bar is met with little
 * scatter; a point whose bar misses tol where the difference between the run and its shadow
 * is scatter (a chaotic feed) measured again over a longer window instead of refined (at
 * twice the sub-steps), its step error bounded statistically.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim_int.h"

/* A measurement's shadow runs over this share of its window: long enough for its estimate to
 * settle (30 periods of the preset's 4-s window), short enough to keep its cost near a fifth. */
#define SHADOW_MEASURE_SHARE 0.3

/* sim_measure's refinements at most: each shrinks the feed step, or the machine step where
 * its term is the larger, by the factor the first-order error asks for, within [1/4, 3/5]. */
#define MEASURE_REFINEMENTS 3

/* How often a measurement with a shadow checks its bar once the shadow has finished (the
 * first check at its end): a fortieth of the preset's 4-s window, 2.5 of its periods. */
#define MEASURE_CHECK 0.1

/* A scatter-dominated point's long run (measure_long): its first check at the window that the
 * first run's statistical bar and its shadow's standard error (both shrinking as one over the
 * root of the window) say brings the bar to MEASURE_LONG_AIM of scatter_scale, within [1,
 * MEASURE_LONG_FIRST] times the measurement's; where the bar then misses what tol allows, on
 * to the window its shrinking part asks for (MEASURE_LONG_MARGIN over it), at most
 * MEASURE_LONG_MAX windows: a point that would need more stops at its check (on the R = 0.5
 * machine: tests/bench/results/chaos.md). */
#define MEASURE_LONG_AIM 0.8
#define MEASURE_LONG_FIRST 6.0
#define MEASURE_LONG_MAX 25.0
#define MEASURE_LONG_MARGIN 1.1

/* scatter_only: the first run's shadow's standard error at least this share of
 * scatter_scale (the preset's steps at most 0.95 of it, the chaotic feed's at least 2.0) */
#define MEASURE_SCATTER_SE 1.5

/* The scale the scatter and room rules below were read on: tol max(|v|, 0.3 peak), which is
 * what tol allows where |v| >= 0.3 peak and 0.3 of it nearer v = 0 (sim_status.c: the
 * convention allows tol peak there). A short window's scatter near v = 0 is no better read
 * than elsewhere: on the chaotic feed (R = 0.5, mu = 0.6) at 75 and 80 deg cw a stop at the
 * first check by what tol allows there left v_ref outside the bar. */
static double scatter_scale(const sim_status *st)
{
	return fmax(st->tol * fabs(st->transport_velocity), 0.3 * st->tol_allowed);
}

/* What scatter_scale leaves the steps: it less the bar's scatter and drift, which finer steps
 * cannot shrink. Near v = 0 a refinement is asked as before the convention's allowance (a
 * chaotic feed's point at 100 deg cw went from 5 to 80 sub-steps for a room its scatter
 * fills); a bar within what tol allows there needs none (tol_met ends it). */
static double room_of(const sim_status *st)
{
	return scatter_scale(st) - (st->transport_velocity_uncertainty - st->step_error);
}

/* Whether sim_measure would refine after a run whose status is st: its step error beyond
 * room_of, and shrunk as a first-order one shrinks (by 0.8 at least) since the last run's,
 * last. */
static int refine_asks(const sim_status *st, double last)
{
	double room = room_of(st);
	return room > 0.0 && st->step_error > room && st->step_error < 0.8 * last &&
	       st->substeps >= 1;
}

/* A bar met early enough to stop on: within tol, steady, and its scatter and drift at most
 * MEASURE_EARLY_SCATTER of scatter_scale. A short window's scatter is read from few batches,
 * and where the feed's motion is correlated over many periods it is read low (a 1.2-s window
 * of the zoo's `stiffer` machine said 0.31 % at 140 deg cw where its v was 0.97 % off): a
 * scatter that small a share of tol holds even read low. And a window of MEASURE_EARLY_PERIODS
 * whole periods at least: the preset's shadow spans 29 of them (30 % of 4 s at its loaded 24.5
 * Hz); a shorter --duration shortens the shadow, and a measurement stopped with it (0.6 s at
 * --duration 2) put 2 of the 74 points outside their bars. */
#define MEASURE_EARLY_SCATTER 0.25
#define MEASURE_EARLY_PERIODS 28
static int early_met(const sim_status *st)
{
	double scatter = st->transport_velocity_uncertainty - st->step_error;
	return st->tol_met && st->steady && scatter <= MEASURE_EARLY_SCATTER * scatter_scale(st) &&
	       st->transport_periods >= MEASURE_EARLY_PERIODS;
}

/* A refinement's bar that neither a longer window nor a further refinement brings within tol
 * (its step error alone beyond it and not shrunk to 0.8 of the run before's, last), measured
 * on no longer where its scatter and drift are already as small as early_met asks: where they
 * are larger (a chaotic feed) the rest of the window still makes v better, if not its bar. */
static int beyond_tol(const sim_status *st, double last)
{
	double scatter = st->transport_velocity_uncertainty - st->step_error;
	return st->step_error >= 0.8 * last && scatter <= MEASURE_EARLY_SCATTER * scatter_scale(st);
}

/* The first run's instance as it starts (settled, at t = 0, its shadow begun), kept for the
 * refinements: a checkpoint of it restored with finer steps starts them where the first run
 * started, without settling again (the settling at the first run's steps: the state at t = 0
 * is a start like any other, and the estimate and its bar come from the finer steps alone).
 * buf NULL: none kept (yet). */
typedef struct settled_start {
	void *buf;
	size_t len;
} settled_start;

/* A run's instance: the first one fresh (its start kept in *start where start is not NULL), a
 * refinement's restored from *start with its own steps (its shadow too; *restored then 1), or
 * fresh where no start could be kept. */
static sim *start_instance(const sim_params *p, const sim_scene *sc, const sim_method *m,
			   double t_end, double deadline, settled_start *start, int *restored,
			   int *err, char *msg, size_t msglen)
{
	*restored = 0;
	if (start && start->buf) {
		sim *s = sim_restore(p, sc, m, start->buf, start->len, err, NULL, 0);
		if (s) {
			*restored = 1;
			sim_bound_cpu(s, deadline);
			return s;
		}
	}
	double window = SHADOW_MEASURE_SHARE * (t_end - fmax(0.0, sc->transient));
	sim *s = sim_new_windowed(p, sc, m, window > 0.0 ? window : 0.0, deadline, NULL, err,
				  msg, msglen);
	if (s)
		sim_bound_cpu(s, deadline); /* its steps to come, its shadow's too */
	if (s && start && !start->buf) {
		size_t len = sim_checkpoint_size(s);
		start->buf = malloc(len);
		start->len = len;
		if (start->buf && sim_checkpoint(s, start->buf, len) != SIM_OK) {
			free(start->buf);
			start->buf = NULL;
		}
	}
	return s;
}

/* A feed thrown hard: the trough's acceleration (its largest speed times omega_ss) beyond
 * MEASURE_LATE_THROW g (the zoo's at most 5.0). Such a machine may leave the steady start's
 * orbit seconds later, steady and within tol before, and either step may pick its motion
 * (docs/random-machines.md): a sweep's point is measured again from MEASURE_LATE_START s at
 * MEASURE_LATE_FINE times the feed sub-steps (its shadow at half), then refined once at half
 * the machine step, that run its shadow, whatever its bar; then as any point. */
#define MEASURE_LATE_THROW 5.5
#define MEASURE_LATE_START 8.0
#define MEASURE_LATE_FINE 4
/* Beyond MEASURE_CHECK_THROW g the feed's shadow at about half its sub-steps may stall with it
 * (the two agree, twice the sub-steps move v by more than tol): a sweep's point whose first run
 * met tol is run again at twice its sub-steps, the first run its shadow, then as any point. */
#define MEASURE_CHECK_THROW 4.2
static int thrown(const sim_params *p, double speed_max, double throw)
{
	return speed_max * p->omega_ss > throw * p->g;
}
static int thrown_hard(const sim_params *p, double speed_max)
{
	return thrown(p, speed_max, MEASURE_LATE_THROW);
}

/* The run before a refinement: its own estimate of v at its shadow's end and its feed step. A
 * refinement restored from the same settled start takes it as its shadow (shadow_against): the
 * two estimates span the same periods from the same state, as a shadow's do, and the coarser
 * run is already paid for, where the refinement's own shadow would cost it about 0.8 of itself
 * again. v NaN: none (the refinement runs its own). */
typedef struct coarser_run {
	double v, h, dt;
	int substeps;
	/* its own shadow's raw difference over (r - 1), that estimate's
	 * standard error (shadow.c: step_se; NaN: none) and how far past the
	 * window's start the run went (s) */
	double raw, se, ran;
	double speed_max; /* m/s: the trough's largest in its window */
	int late_check;   /* stop at the first check once thrown_hard */
} coarser_run;

/* Whether s's own shadow would be the coarser run itself (the same machine step, ceil(n / 2)
 * of s's n sub-steps the coarser run's). */
static int shadow_is(const sim *s, const coarser_run *c)
{
	return s->cfg.dt == c->dt && (s->cfg.substeps + 1) / 2 == c->substeps;
}

/* Where the coarser run as a refinement's shadow leaves its bar beyond tol (the coarser run,
 * pre-asymptotic, is why the point was refined), the refinement's own shadow, run now from the
 * settled start to s's shadow_until (s stands there): the step error as the shadow beside it
 * would have measured it, bit for bit. */
static void own_shadow(sim *s, const sim_params *p, const sim_scene *sc, const sim_method *m,
		       const settled_start *start)
{
	sim *r = sim_restore(p, sc, m, start->buf, start->len, NULL, NULL, 0);
	if (!r)
		return;
	sim *sh = r->shadow;
	r->shadow = NULL;
	sim_free(r);
	if (!sh)
		return;
	sh->cpu = s->cpu;
	if (sim_advance(sh, s->shadow_until) == SIM_ECPU) {
		sim_free(sh); /* measure_once's next advance stops too */
		return;
	}
	s->shadow = sh;
	shadow_finish(s);
	sim_update_status(s);
}

/* One run of sim_measure: a fresh instance to t_end at most, its shadow over the first
 * SHADOW_MEASURE_SHARE of the window (a refinement from the settled start: the run before as
 * its shadow, coarser_run); *st its final status, *coarser this run for the next. If early
 * (sim_measure_point) and with a shadow, the run stops early at the first check after the
 * shadow has finished where the bar is within tol and the estimate steady (the rest of the
 * window would only shrink a bar already met), or, if may_refine, where the step error alone
 * is beyond tol and either a refinement is asked (refine_asks with last) or none can follow
 * (the step error not shrunk to 0.8 of last): the step error does not change after the shadow
 * and no longer window makes room for it, so the refinement the whole window would ask for is
 * asked now, and a bar that no window or refinement brings within tol is not measured on where
 * its scatter is small already (beyond_tol). A step error within tol whose room a longer
 * window's smaller scatter may yet make is left to the window's end, as before. */
static int measure_once(const sim_params *p, const sim_scene *sc, const sim_method *m,
			double t_end, double deadline, int early, int may_refine, double last,
			settled_start *start, coarser_run *coarser, sim_status *st, char *msg,
			size_t msglen)
{
	*st = (sim_status){.transport_velocity = NAN, .transport_velocity_uncertainty = NAN,
			   .rotor_speed_mean = NAN, .step_error = NAN, .tol_allowed = NAN};
	int err, restored;
	sim *s = start_instance(p, sc, m, t_end, deadline, start, &restored, &err, msg, msglen);
	if (!s)
		return err;
	/* a refinement from the settled start: the run before is its shadow */
	int against = restored && s->shadow && isfinite(coarser->v);
	if (against)
		shadow_stop(s);
	double until = s->shadow_until;
	/* the first check at the shadow's end (just past it: the shadow
	 * finishes once the instance is asked beyond it) */
	double t = early && (s->shadow || against) ? fmin(t_end, nextafter(until, INFINITY)) : t_end;
	for (;;) {
		if (against && t > until) {
			err = sim_advance(s, until);
			if (err != SIM_OK)
				break;
			shadow_against(s, coarser->v, coarser->h);
			if (!s->st.tol_met && !shadow_is(s, coarser))
				own_shadow(s, p, sc, m, start);
			against = 0;
		}
		err = sim_advance(s, t);
		if (err != SIM_OK || t >= t_end)
			break;
		if (!s->shadow && coarser->late_check && thrown_hard(p, s->est.speed_max))
			break;
		if (!s->shadow && (early_met(&s->st) ||
				   (may_refine && s->st.step_error > s->st.tol_allowed &&
				    (refine_asks(&s->st, last) || beyond_tol(&s->st, last)))))
			break;
		t = fmin(t_end, t + MEASURE_CHECK);
	}
	if (err != SIM_OK && msg)
		snprintf(msg, msglen, "%s", s->error);
	*st = s->st;
	coarser->v = s->shadow_v;
	coarser->h = s->cfg.dt / s->cfg.substeps;
	coarser->dt = s->cfg.dt;
	coarser->substeps = s->cfg.substeps;
	coarser->raw = restored ? NAN : s->step_error;
	coarser->se = restored ? NAN : s->step_se;
	coarser->ran = s->st.t - fmax(0.0, sc->transient);
	coarser->speed_max = s->est.speed_max;
	sim_free(s);
	return err;
}

/* A first run whose bar is beyond scatter_scale (what tol allows, but near v = 0 0.3 of it:
 * the scale the shares were read on) where its shadow's difference is within
 * SHADOW_SIGNIFICANT of its standard error (a chaotic feed: the run and its shadow drift
 * apart, and their difference is scatter, which finer steps do not shrink): measured again
 * over a longer window with its shadow beside it throughout (measure_long), not refined. */
static int scatter_only(const sim_status *st, const coarser_run *c)
{
	return st->transport_velocity_uncertainty > scatter_scale(st) && isfinite(c->se) &&
	       c->raw <= SHADOW_SIGNIFICANT * c->se &&
	       c->se >= MEASURE_SCATTER_SE * scatter_scale(st) && c->ran > 0.0;
}

/* The long run's scatter: the estimate's bar, its standard error from the batches merged 2 and
 * 4 at a time where larger (estimator_blocked_bar, at least LONG_BLOCKS of them). On the
 * chaotic feed the motion is correlated beyond a batch at some angles (the reference's 16-s
 * windows scatter up to 2.5 times as much as its 4-s windows say,
 * tests/bench/zoo/chaos_ref.tsv at 105 deg), which the batches alone read low. */
#define LONG_BLOCKS 8

/* The long run's bar at its present time with the running shadow's raw step error and standard
 * error (shadow_peek): the scatter (as above), the step error as shadow_finish bounds it, the
 * machine step's term; *shrink the part that shrinks as one over the root of the window. */
static double long_bar(const sim *s, double raw, double se, double *shrink)
{
	double stat = estimator_blocked_bar(&s->est, LONG_BLOCKS);
	int scatter = raw <= SHADOW_SIGNIFICANT * se;
	*shrink = stat + (scatter ? se : 0.0);
	return stat + (scatter ? se : raw) + s->st.machine_error;
}

/* The long run of a scatter-dominated point: from the settled start, at the first run's
 * machine step and twice its sub-steps, its shadow beside it throughout, to the first check
 * (MEASURE_LONG_FIRST) and on where the bar misses tol and more window can bring it within
 * (MEASURE_LONG_MAX). The step error is the shadow's difference where significant, else its
 * standard error (s->step_bounded). */
static int measure_long(const sim_params *p, const sim_scene *sc, const sim_method *m,
			double t_end, double deadline, const settled_start *start, coarser_run *c,
			sim_status *st, char *msg, size_t msglen)
{
	double t0 = fmax(0.0, sc->transient), w = t_end - t0;
	double stat = st->transport_velocity_uncertainty - st->step_error;
	double root = (stat * sqrt(c->ran) + c->se * sqrt(SHADOW_MEASURE_SHARE * w)) /
		      (MEASURE_LONG_AIM * scatter_scale(st));
	double len = fmin(MEASURE_LONG_FIRST * w, fmax(w, root * root));
	int err;
	/* twice the first run's sub-steps made even, the shadow half of them
	 * (r = 2): 3 sub-steps are not yet first order at some angles (at 80
	 * deg cw over 48 s, 3 and 6 sub-steps gave v 0.33 mm/s apart and 6
	 * sub-steps 0.65 mm/s from v_ref), and the finer run's own error is
	 * the smaller */
	sim_method even = *m;
	even.dt = st->dt;
	even.substeps = 2 * (st->substeps + st->substeps % 2);
	sim *s = sim_restore(p, sc, &even, start->buf, start->len, &err, msg, msglen);
	if (!s)
		return err;
	sim_bound_cpu(s, deadline);
	s->step_bounded = 1;
	s->shadow_until = t0 + MEASURE_LONG_MAX * w;
	for (;;) {
		err = sim_advance(s, t0 + len);
		double raw, se, shrink;
		if (err != SIM_OK || len >= MEASURE_LONG_MAX * w || !shadow_peek(s, &raw, &se))
			break;
		double bar = long_bar(s, raw, se, &shrink), room = s->st.tol_allowed - (bar - shrink);
		if (bar <= s->st.tol_allowed || !(room > 0.0))
			break;
		double need = MEASURE_LONG_MARGIN * len * (shrink / room) * (shrink / room);
		if (need > MEASURE_LONG_MAX * w)
			break;
		len = fmin(MEASURE_LONG_MAX * w, fmax(need, 1.25 * len));
	}
	if (err == SIM_OK && s->shadow) {
		s->shadow_until = t0 + len;
		err = sim_advance(s, nextafter(t0 + len, INFINITY));
	}
	if (err != SIM_OK && msg)
		snprintf(msg, msglen, "%s", s->error);
	*st = s->st;
	st->transport_velocity_uncertainty =
		estimator_blocked_bar(&s->est, LONG_BLOCKS) + st->step_error;
	st->tol_met = st->transport_velocity_uncertainty <= st->tol_allowed;
	sim_free(s);
	return err;
}

/* sim_measure, and sim_measure_point if early: its runs stop once their bar is met, and its
 * refinements start from the first run's settled start; *moved where its first run is thrown
 * hard and its window starts before MEASURE_LATE_START (the caller measures it over the later
 * one, fine: at MEASURE_LATE_FINE times the scene's feed sub-steps, then at half the machine
 * step, where the steps are the engine's); a point thrown beyond MEASURE_CHECK_THROW whose
 * first run met tol is run again at twice its sub-steps (that check one of the refinements). */
static int measure_window(const sim_params *p, const sim_scene *sc, const sim_method *m,
			  double t_end, int early, int fine, double deadline, sim_measurement *out,
			  int *moved, char *msg, size_t msglen)
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
	if (fine && own_steps) {
		run.dt = sim_default_dt(p, sc, m);
		run.substeps = MEASURE_LATE_FINE * sim_default_substeps(p, sc, m, run.dt);
	}
	double last = INFINITY;
	settled_start start = {NULL, 0};
	coarser_run coarser = {NAN, NAN, NAN, 0, NAN, NAN, NAN, NAN, 0};
	int late = early && fmax(0.0, sc->transient) < MEASURE_LATE_START;
	for (int attempt = 0;; attempt++) {
		int may_refine = own_steps && attempt < MEASURE_REFINEMENTS;
		coarser.late_check = late && attempt == 0;
		err = measure_once(p, sc, &run, t_end, deadline, early, may_refine, last,
				   early && own_steps ? &start : NULL, &coarser, &st, msg, msglen);
		out->refinements = attempt;
		*moved = attempt == 0 && late && err == SIM_OK && thrown_hard(p, coarser.speed_max);
		if (*moved)
			break;
		if (err == SIM_OK && attempt == 0 && early && own_steps && start.buf &&
		    scatter_only(&st, &coarser)) {
			err = measure_long(p, sc, &run, t_end, deadline, &start, &coarser, &st, msg,
					   msglen);
			break;
		}
		/* a hard-thrown point's later window: once at half the machine step, whatever its bar */
		if (fine && own_steps && attempt == 0 && err == SIM_OK) {
			last = st.step_error;
			run.dt = st.dt * 0.5;
			continue;
		}
		if (!fine && early && own_steps && attempt == 0 && err == SIM_OK && st.tol_met &&
		    start.buf && thrown(p, coarser.speed_max, MEASURE_CHECK_THROW)) {
			run.substeps = 2 * st.substeps;
			continue;
		}
		/* done: within tol, the user's own steps, no room the steps could fit in, or a refinement
		 * that did not shrink the step error as first order does: what remains is not the steps' */
		if (err != SIM_OK || !may_refine || st.tol_met || !refine_asks(&st, last))
			break;
		double room = room_of(&st);
		last = st.step_error;
		/* first order in both steps: the step whose term is the larger shrinks by the
		 * factor asked (the machine step with the feed step, the sub-steps kept) */
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
	free(start.buf);
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

static int measure(const sim_params *p, const sim_scene *sc, const sim_method *m, double t_end,
		   int early, double deadline, sim_measurement *out, char *msg, size_t msglen)
{
	int moved, err = measure_window(p, sc, m, t_end, early, 0, deadline, out, &moved, msg,
					msglen);
	if (err != SIM_OK || !moved)
		return err;
	sim_scene late = *sc;
	late.transient = MEASURE_LATE_START;
	double cpu = out->cpu_seconds, shift = MEASURE_LATE_START - fmax(0.0, sc->transient);
	err = measure_window(p, &late, m, t_end + shift, early, 1, deadline, out, &moved, msg,
			     msglen);
	out->cpu_seconds += cpu;
	return err;
}

double sim_measure_span(const sim_scene *sc, double t_end)
{
	double window = t_end - fmax(0.0, sc->transient);
	return t_end + (window > 0.0 ? SHADOW_MEASURE_SHARE * window : 0.0);
}

int sim_measure(const sim_params *p, const sim_scene *sc, const sim_method *m, double t_end,
		sim_measurement *out, char *msg, size_t msglen)
{
	return measure(p, sc, m, t_end, 0, INFINITY, out, msg, msglen);
}

int sim_measure_bounded(const sim_params *p, const sim_scene *sc, const sim_method *m,
			double t_end, double cpu_deadline, sim_measurement *out, char *msg,
			size_t msglen)
{
	return measure(p, sc, m, t_end, 0, cpu_deadline, out, msg, msglen);
}

int sim_measure_point(const sim_params *p, const sim_scene *sc, const sim_method *m,
		      double t_end, sim_measurement *out, char *msg, size_t msglen)
{
	return measure(p, sc, m, t_end, 1, INFINITY, out, msg, msglen);
}
