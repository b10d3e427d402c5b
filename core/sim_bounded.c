/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim_bounded.c - sim_new and sim_advance with a deadline on the calling
 * thread's CPU clock (sim.h): the bound is set on the instance
 * (cpu_bound.c) and read by its steps (sim.c), so these callers of sim.c
 * sit above it and cpu_bound.c below.
 */
#include <math.h>

#include "sim_int.h"

sim *sim_new_bounded(const sim_params *p, const sim_scene *sc, const sim_method *m,
		     double cpu_deadline, double *settled, int *err, char *msg, size_t msglen)
{
	return sim_new_windowed(p, sc, m, 0.0, cpu_deadline, settled, err, msg, msglen);
}

int sim_advance_bounded(sim *s, double t_end, double cpu_deadline)
{
	sim_bound_cpu(s, cpu_deadline);
	int e = sim_advance(s, t_end);
	sim_bound_cpu(s, INFINITY);
	return e;
}
