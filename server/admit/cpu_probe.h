/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cpu_probe.h - what a simulated second of a session costs, measured
 * before it is admitted to the cores for paced sessions: the estimate from
 * the integrator alone (budget.c) misses what grows with the scene (a
 * 64 x 64 feed was estimated at 0.04 cores and used 1.3).
 */
#ifndef CONVSIM_CPU_PROBE_H
#define CONVSIM_CPU_PROBE_H

#include "api.h"
#include "sim.h"

/* Longest a probe runs in simulated s (its CPU s: --cpu-probe). */
#define SRV_PROBE_T_S 0.2
/* Longest piece of simulated time it advances between two reads of its
 * CPU clock (a quarter of the preset's 25-Hz period): the probe ends
 * within one such piece of --cpu-probe whatever the sample rate. */
#define SRV_PROBE_PIECE_S 0.01

/* CPU s per simulated s of running live (borrowed, read only) as its
 * worker would: a copy made from a checkpoint of it (no settling) is
 * advanced sample by sample at spec's sample rate, with the status and
 * the feed's state read at each sample as the worker reads them, for
 * cpu_s of this thread's CPU (--cpu-probe) or SRV_PROBE_T_S simulated s,
 * whichever comes first, in pieces of at most SRV_PROBE_PIECE_S; plus
 * the server's cost per published sample; stopped within a piece where
 * this thread's CPU clock passes deadline (srv_thread_cpu; the creation's
 * --max-cpu-seconds), measured over what it ran. columns x layers: the
 * feed recorded (0 without). Logs its figure and the simulated s it ran
 * at debug level, for session id. Returns a negative value if the copy
 * cannot be made (out of memory) or ran nothing: then estimate. */
double srv_cpu_probe(const sim *live, const api_spec *spec, int columns, int layers,
		     double cpu_s, double deadline, const char *id);

/* An adaptive method's steps are known only once it runs, so the
 * estimate before a creation's settling cannot refuse a paced session that
 * needs far more than the cores for paced sessions: it would settle (up to
 * --max-cpu-seconds, holding a settling slot) and its probe refuse it
 * after; nor one whose settling would run to --max-cpu-seconds. Such a
 * session first settles SRV_SETTLE_PEEK_CPU s of this thread's CPU from
 * cpu0; where that settling's CPU per simulated s at its pace (not max)
 * is at least twice the whole budget, it is refused there: 1 and *pb (422
 * naming pace, as after the probe, its detail saying where the figure
 * comes from); where its whole settling would take twice what is left to
 * deadline or more, 1 and srv_budget_settle_peeked's 422. Else 0: *out is
 * the instance where the peek settled it all, NULL where the settling is
 * to start again within deadline (or spec's method is not adaptive). */
#define SRV_SETTLE_PEEK_CPU 0.2
int srv_cpu_settle_peek(const api_spec *spec, double cpu0, double deadline, sim **out,
			api_problem *pb);

#endif
