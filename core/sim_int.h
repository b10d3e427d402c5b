/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim_int.h - internal: the inside of a sim, shared by sim.c (the
 * instance, its controls and stepping) and sim_status.c (what it shows:
 * the status at the observed time, feed and deck observables). Not part of
 * the public interface (sim.h), as SQLite's btreeInt.h beside btree.h.
 */
#ifndef CONVSIM_SIM_INT_H
#define CONVSIM_SIM_INT_H

#include "estimator.h"
#include "ode.h"
#include "sim.h"

/* A bound on the calling thread's CPU while a bounded call runs
 * (cpu_bound.c): off, or a deadline on the thread's CPU clock (s) read
 * every `stride` steps (`left` to go), the stride adapted so that reads
 * come about CPU_READ_S of CPU apart (`last`: the last read; NaN none). */
typedef struct cpu_bound {
	int on;
	unsigned stride, left;
	double deadline, last;
	double ran; /* s: what the settling ran before a stop (sim.c) */
} cpu_bound;

struct sim {
	model md;            /* const after sim_new, but for the feed's m_n
				and mu, which sim_set_feed changes between
				steps (disturb.c) */
	model_ctl ctl;       /* changed by the sim_set_* controls */
	dyn sys;             /* what the integrator steps: &md, &ctl, rhs_evals */
	sim_method cfg;
	const ode_method *ode;
	void *ws;
	double t_int, t_obs, t_prev;
	uint64_t k_fixed;    /* fixed-step methods: t_int = k_fixed * dt, so
				that time carries no round-off of summed steps */
	double *y, *y_obs, *dy, *y_prev; /* y_prev: the state at t_prev, the
					    start of the last step */
	double e0, kin0, pot0, elastic0; /* energies at t = 0 */
	double e_disturb;    /* J: the stored energy's jumps at the feed's
				disturbances (disturb.c), booked as input */
	uint64_t steps;
	int failed;
	char error[160];
	estimator est;
	double X0;
	double *X0k;
	/* the measured step error (shadow.c): a second instance with
	 * fewer feed sub-steps, restored from this one's checkpoint where an estimate
	 * starts and stepped beside it until shadow_until; NULL when none
	 * runs */
	struct sim *shadow;
	double shadow_until;  /* s */
	double shadow_window; /* s: how long a shadow runs after the estimate's start */
	double step_error;    /* m/s: the last shadow's Richardson estimate of
				 the feed step's error in v; NaN before one */
	double shadow_v;      /* m/s: this instance's own estimate of v at
				 the last shadow's end, NaN where that shadow
				 measured nothing (too few periods, failed) */
	double step_se;       /* m/s: the standard error of the last shadow's
				 step_error from its paired batches (shadow.c),
				 NaN where they do not pair */
	int step_bounded;     /* a shadow's difference within SHADOW_SIGNIFICANT
				 of its standard errors is scatter: step_error
				 is bounded by step_se (measure.c's long run) */
	cpu_bound cpu;        /* off but within sim_new_bounded and
				 sim_advance_bounded */
	sim_status st;
};

/* Start (deadline finite) or switch off (INFINITY) b. cpu_bound.c */
void cpu_bound_start(cpu_bound *b, double deadline);
/* The same for s's bound and its shadow's: every later step of either
 * (sim_advance) is bounded until switched off. cpu_bound.c */
void sim_bound_cpu(sim *s, double deadline);
/* Read the clock, adapt the stride: 1 when past the deadline. */
int cpu_bound_read(cpu_bound *b);
/* After each step of a bounded call: 1 once the thread's CPU clock has
 * passed b's deadline (read every b->stride steps); 0 while off. */
static inline int cpu_bound_passed(cpu_bound *b)
{
	return b->on && --b->left == 0 && cpu_bound_read(b);
}

/* An instance for a validated set with its workspace allocated and the
 * controls initialised, but no state yet (all zero): sim_new fills it with
 * the start, sim_restore (checkpoint.c) with a checkpoint. Errors as
 * sim_new. sim.c */
sim *sim_alloc(const sim_params *p, const sim_scene *sc, const sim_method *m, int *err,
	       char *msg, size_t msglen);

/* Fill an instance fresh from sim_alloc with the scene's start (static
 * equilibrium; for `steady`, the forced response and the settling, run by
 * s->ode) and zero its observers: the rest of sim_new. Returns SIM_OK, or
 * the settling's failure with its cause in msg. Lets an integrator from
 * outside the core (the benchmark's peers, tests/bench/peer_*.c) replace
 * s->ode and s->ws between sim_alloc and sim_start. sim.c */
int sim_start(sim *s, char *msg, size_t msglen);

/* sim_new with the shadow's window (s; <= 0: the default, SHADOW_PERIODS
 * excitation periods), its settling bounded as sim_new_bounded's
 * (cpu_deadline INFINITY: unbounded). sim.c */
sim *sim_new_windowed(const sim_params *p, const sim_scene *sc, const sim_method *m,
		      double shadow_window, double cpu_deadline, double *settled, int *err,
		      char *msg, size_t msglen);

/* A shadow's difference within this many of its standard errors (step_se)
 * is not told from the feed's scatter (step_bounded; measure.c) */
#define SHADOW_SIGNIFICANT 2.0

/* The measured step error (shadow.c): shadow_begin starts a shadow from
 * the instance's present state (none where it cannot run), to run until
 * the estimate's start plus s->shadow_window; shadow_finish sets
 * s->step_error from the shadow's estimate against the instance's, both
 * at shadow_until, and frees it; shadow_stop frees it. */
#define SHADOW_PERIODS 40.0
void shadow_begin(sim *s);
void shadow_finish(sim *s);
void shadow_stop(sim *s);
/* shadow_peek: a running shadow's step error and its standard error as
 * shadow_finish would set them now (measure.c's long run checks its bar
 * with it); 0 where it has none yet. */
int shadow_peek(const sim *s, double *raw, double *se);
/* shadow_against: the step error from a coarser run instead of a shadow
 * (v_coarse, its feed step h_coarse: its shadow_v, from the same start),
 * at shadow_until; s has no shadow then. */
void shadow_against(sim *s, double v_coarse, double h_coarse);

/* Recompute s->st at the observed time after any change; reads the state
 * and evaluates the right-hand side for observation only (no counter
 * moves). sim_status.c */
void sim_update_status(sim *s);
/* The feed columns the steady start's settling integrates (sim.c): one
 * where it settles through the symmetric reduction (or has it), else every
 * integrated column; 0 without feed. */
int sim_settle_columns(const sim *s);
/* Whether the steady start settles s through the symmetric reduction
 * (sim.c settle_reduced; sim_status.c). */
int sim_reduced_settles(const sim *s);
/* What s integrates into st: its step and sub-steps, reductions,
 * coordinates, settle_columns and feed_mass_ratio (sim_status.c; what
 * sim_preview reports and every status carries). */
void sim_status_shape(const sim *s, sim_status *st);

#endif
