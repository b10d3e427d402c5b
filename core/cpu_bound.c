/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cpu_bound.c - a bound on the calling thread's CPU for the calls that run
 * long in one piece: the steady start's settling in sim_new_bounded (an
 * adaptive method's steps follow the solution, so no estimate before it
 * knows them) and an advance over a long span (sim_advance_bounded; both
 * in sim_bounded.c, above sim.c, which reads the bound here). The
 * deadline is a time on the thread's CPU clock (CLOCK_THREAD_CPUTIME_ID,
 * POSIX in libc; no callback into the caller), read after every so many
 * steps: each read sets the next stride from what the steps since the last
 * one cost, to about CPU_READ_S of them (growing at most CPU_STRIDE_GROWTH
 * times a read, from one step), so that the reads (a system call each,
 * under a microsecond) cost nothing measurable beside the steps and a call
 * stops about CPU_READ_S, or one step where a step costs more, past its
 * deadline.
 */
#include <math.h>
#include <time.h>

#include "sim_int.h"

#define CPU_READ_S 1e-3
#define CPU_STRIDE_GROWTH 64.0
#define CPU_STRIDE_MAX 4096.0

double sim_thread_cpu(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cpu_bound_start(cpu_bound *b, double deadline)
{
	b->on = deadline < INFINITY;
	b->deadline = deadline;
	b->stride = b->left = 1;
	b->last = b->on ? sim_thread_cpu() : NAN;
	b->ran = 0.0;
}

int cpu_bound_read(cpu_bound *b)
{
	double now = sim_thread_cpu();
	if (now > b->deadline) {
		b->left = 1; /* read again at the next step, if asked */
		return 1;
	}
	double per_step = (now - b->last) / b->stride;
	double want = per_step > 0.0 ? CPU_READ_S / per_step : CPU_STRIDE_MAX;
	want = fmin(fmin(want, CPU_STRIDE_GROWTH * b->stride), CPU_STRIDE_MAX);
	b->stride = want > 1.0 ? (unsigned)want : 1u;
	b->last = now;
	b->left = b->stride;
	return 0;
}

void sim_bound_cpu(sim *s, double deadline)
{
	cpu_bound_start(&s->cpu, deadline);
	if (s->shadow) /* it steps beside the instance, on the same thread */
		cpu_bound_start(&s->shadow->cpu, deadline);
}
