/*
 * ode_registry.c - the table of integrators the API can name.
 */
#include <string.h>

#include "ode.h"

static const ode_method *const methods[] = {&ode_rk4, &ode_dopri5, &ode_euler, &ode_dem};
#define N_METHODS (sizeof methods / sizeof methods[0])

/* The public view of the same table (tests check that they agree). */
static const sim_method_info infos[] = {
	{"rk4", 4, 0, "classical Runge-Kutta, fixed step dt, whole state"},
	{"dopri5", 5, 1, "Dormand-Prince 5(4), PI step control, dense output; dt is the first step"},
	{"euler", 1, 0, "semi-implicit (symplectic) Euler, fixed step dt"},
	{"dem", 1, 0, "machine RK4 macro step dt, feed sub-stepped with implicit Coulomb friction"},
};
_Static_assert(sizeof infos / sizeof infos[0] == N_METHODS, "one info per method");

const ode_method *ode_find(const char *name)
{
	for (size_t i = 0; i < N_METHODS; i++)
		if (strcmp(methods[i]->name, name) == 0)
			return methods[i];
	return NULL;
}

const sim_method_info *sim_methods(size_t *n)
{
	*n = N_METHODS;
	return infos;
}
