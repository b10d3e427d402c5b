/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * study.h - a design study: the measured points of v over any numeric
 * settings of the settings table, not only beta. A study is a few axes
 * (a setting by name with a range FROM:TO:STEP or a list of values, in
 * the setting's user unit), combined as a full grid or as a seeded
 * Latin-hypercube sample, times the rotation senses. The CLI's `convsim
 * sweep --vary` and the daemon's sweeps plan with it; the runs are the
 * caller's (sim_measure per point). Core only: libc and libm.
 */
#ifndef CONVSIM_STUDY_H
#define CONVSIM_STUDY_H

#include <stddef.h>
#include <stdint.h>

#include "sim.h"

#define SIM_STUDY_MAX_AXES 8
/* The most points a study has per rotation sense (grid or sample). */
#define SIM_STUDY_MAX_POINTS 10000

typedef struct sim_study_axis {
	const sim_setting *setting; /* borrowed from the settings table */
	double from, to, step;      /* user units; step 0: a list */
	size_t n;                   /* values of the grid */
	double *values;             /* user units, owned by the study */
} sim_study_axis;

typedef struct sim_study {
	size_t naxes;
	sim_study_axis axis[SIM_STUDY_MAX_AXES];
	size_t nrot;
	int rotation[2];  /* SIM_CW / SIM_CCW, the outer order of the tasks */
	size_t lhs;       /* 0: the full grid; else a sample of this many points */
	uint64_t seed;
	size_t npoints;   /* per sense */
	double *values;   /* npoints x naxes, user units (sim_study_plan) */
} sim_study;

/* Whether the setting `name` may be an axis of st: a number setting
 * (real or whole; not `rotation`) that is not one yet, with room for one
 * more. SIM_OK, or SIM_EUNKNOWN with a sentence in msg. The add functions
 * check it first; a caller may check it before it reads the values, so
 * that a setting no values could make an axis is refused as such. */
int sim_study_check_axis(const sim_study *st, const char *name, char *msg, size_t msglen);

/* Add an axis: the setting `name` from `from` to `to` (user units) by
 * `step` > 0, the values from + k step (k = 0, 1, ...) up to `to` (1e-9
 * of a step of slack), each rounded to 12 significant digits (0.6, not
 * 0.6000000000000001). Checks that the setting exists, is a number
 * (real or whole; `rotation` is the senses' list, enums and switches are
 * set with --set), is not already an axis, that both ends lie in its
 * range (on the model p, s, m: the same check as setting it) and FROM
 * <= TO. Returns SIM_OK, or SIM_EUNKNOWN / SIM_EPARAM / SIM_ENOMEM with
 * a sentence naming the setting and what it accepts in msg. */
int sim_study_add_range(sim_study *st, const sim_params *p, const sim_scene *s,
			const sim_method *m, const char *name, double from, double to,
			double step, char *msg, size_t msglen);
/* The count of values a range FROM:TO:STEP gives (as sim_study_add_range
 * makes them: 1e-9 of a step of slack at TO), NaN unless to >= from and
 * step > 0 is finite. A double: a tiny step's count may pass any integer
 * type. */
double sim_study_range_count(double from, double to, double step);
/* The same for a list of n values (each checked; copied), no value twice
 * (the same point would run twice): SIM_EPARAM naming the repeat. */
int sim_study_add_list(sim_study *st, const sim_params *p, const sim_scene *s,
		       const sim_method *m, const char *name, const double *values, size_t n,
		       char *msg, size_t msglen);
/* The index of the first of values[0..n) that repeats an earlier one (the
 * earlier's index into *first), or -1: the repeat sim_study_add_list
 * refuses. */
long sim_study_repeat(const double *values, size_t n, size_t *first);

/* Make the study's points: the full grid of its axes (the first axis
 * outermost, the last varying fastest), or, with st->lhs > 0, a Latin
 * hypercube of st->lhs points over the axes' [from, to] (each range cut
 * into lhs equal strata, one point in each, the strata shuffled per axis
 * from st->seed; whole-number settings rounded), which needs ranges, not
 * lists. At most SIM_STUDY_MAX_POINTS points. SIM_OK, or SIM_EPARAM /
 * SIM_ENOMEM with the reason in msg. */
int sim_study_plan(sim_study *st, char *msg, size_t msglen);
/* The points per sense sim_study_plan makes of st as it stands: st->lhs,
 * else the product of its axes' counts (1 without axes). A double, as
 * above. */
double sim_study_count(const sim_study *st);

/* The largest value (user units) the axis of setting `name` takes (over
 * the points once planned, else over its values), or `otherwise` when the
 * study does not vary it: the bound every point must respect, as t_end
 * past each point's scene.transient. */
double sim_study_largest(const sim_study *st, const char *name, double otherwise);

/* Point k's value of axis a (user units). */
static inline double sim_study_value(const sim_study *st, size_t k, size_t a)
{
	return st->values[k * st->naxes + a];
}

/* The tasks: nrot x npoints, sense-major (task t is point t % npoints in
 * sense rotation[t / npoints]). */
static inline size_t sim_study_tasks(const sim_study *st)
{
	return st->nrot * st->npoints;
}

/* Set task t's settings on the model p, s, m (the axes' values and its
 * rotation sense). SIM_OK, or the setting's error with msg. */
int sim_study_apply(const sim_study *st, size_t t, sim_params *p, sim_scene *s, sim_method *m,
		    char *msg, size_t msglen);

/* The mirror reduction over the study's tasks: source[t] = -1 for a task
 * to measure, else the earlier task whose mirror image task t is: the
 * other sense at 180 - beta and the same value of every other axis, on a
 * model (p, s, m with those values) where sim_mirror_applies holds.
 * source has sim_study_tasks() entries. Returns the tasks to measure, or
 * (size_t)-1 when out of memory. */
size_t sim_study_mirror_plan(const sim_study *st, const sim_params *p, const sim_scene *s,
			     const sim_method *m, long *source);

/* A curve's tol_met (docs/accuracy.md "A curve's own peak"): a point's run
 * judged tol by docs/MODEL.md's convention with the peak estimated from the
 * trough's vibration speed, which overestimates it where the feed barely
 * throws (below a throw number of about one: 2 to 8 times). Where beta
 * alone is varied over a curve that finds its peak (sim_curve_covers: beta
 * from 0 to 180 deg, no gap wider than SIM_CURVE_GAP_MAX), the largest |v|
 * measured (a lower bound of the peak) judges again: tol_met stays true
 * only where the bar is also within tol with that peak. Never from false
 * to true. beta_deg: the points' beta, deg. */
#define SIM_CURVE_GAP_MAX 30.0
int sim_curve_covers(const double *beta_deg, size_t n);
/* beta the study's only axis and its values sim_curve_covers. */
int sim_study_curve(const sim_study *st);
int sim_tol_met_at_peak(const sim_measurement *r, double tol, double peak);

/* Free what the study owns (NULL is fine); the struct itself is the
 * caller's. */
void sim_study_free(sim_study *st);

#endif
