/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode_registry.c - the table of integrators the API can name, built from
 * the methods' own descriptors (name, order, adaptive, doc and what each
 * can do live in each ode_*.c file only), in ode.h's ODE_REGISTRY order.
 */
#include <string.h>

#include "ode.h"

/* Each entry is the first member of an ode_method (ode.h). */
#define ENTRY(descriptor, name) &descriptor.info,
static const sim_method_info *const registry[] = {ODE_REGISTRY(ENTRY)};
#undef ENTRY
#define N_METHODS (sizeof registry / sizeof registry[0])

const ode_method *ode_find(const char *name)
{
	for (size_t i = 0; i < N_METHODS; i++)
		if (strcmp(registry[i]->name, name) == 0)
			return (const ode_method *)registry[i];
	return NULL;
}

const char *sim_default_method(void)
{
	return ODE_DEFAULT.info.name;
}

const sim_method_info *const *sim_methods(size_t *n)
{
	*n = N_METHODS;
	return registry;
}
