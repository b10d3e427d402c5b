/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode_registry.c - the table of integrators the API can name, built from
 * the methods' own descriptors (name, order, adaptive, doc live in each
 * ode_*.c file only).
 */
#include <string.h>

#include "ode.h"

/* Each entry is the first member of an ode_method (ode.h). */
static const sim_method_info *const registry[] = {&ode_rk4.info, &ode_dopri5.info,
						  &ode_euler.info, &ode_split.info};
#define N_METHODS (sizeof registry / sizeof registry[0])

const ode_method *ode_find(const char *name)
{
	for (size_t i = 0; i < N_METHODS; i++)
		if (strcmp(registry[i]->name, name) == 0)
			return (const ode_method *)registry[i];
	return NULL;
}

const sim_method_info *const *sim_methods(size_t *n)
{
	*n = N_METHODS;
	return registry;
}
