/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode.h - internal: integrators as data. Each method is one file of static
 * functions exporting one const descriptor; ode_registry.c lists them so
 * that the API finds a method by name. The caller (sim.c) decides when to
 * step; there are no callbacks into the caller. A step reads the const
 * model and the controls through its dyn and changes only the state, its
 * workspace and the dyn's evaluation counter.
 */
#ifndef CONVSIM_ODE_H
#define CONVSIM_ODE_H

#include "dynamics.h"
#include "errors.h"

/* Classical RK4's stability region along the negative real axis: the
 * real root of 1 + z/2 + z^2/6 + z^3/24 (where |R(z)| returns to 1). */
#define RK4_REAL_LIMIT 2.785293563405282
/* ... and the radius of the largest half-disc of the left half-plane
 * inside it (|R(z)| = 1 nearest the origin at arg z = 122.5 deg: 2.616),
 * rounded down: h |lambda| within it keeps any decaying or oscillating
 * mode bounded, however damped. */
#define RK4_RADIUS_LIMIT 2.6

typedef struct ode_method {
	/* name, order, adaptive, doc: the public description. First member,
	 * so that the registry lists descriptors through it. */
	sim_method_info info;
	int dense;     /* steps past the target and interpolates */
	/* Workspace for model md (its size n fixed) and settings cfg; NULL on
	 * allocation failure. Everything the steps need is allocated here. */
	void *(*alloc)(const model *md, const sim_method *cfg);
	/* One step from (*t, y), in place. Fixed-step methods do not pass
	 * t_max (the last step is shortened; sim.c passes INFINITY except to
	 * land the steady start's settling on t = 0); dense methods may. Returns
	 * SIM_OK or SIM_ESTEP. */
	int (*step)(void *ws, dyn *sys, double *t, double *y, double t_max);
	/* Dense methods: the state at t within the last step into out. */
	void (*interpolate)(void *ws, double t, double *out);
	/* Forget cached derivatives (after a control change). */
	void (*reset)(void *ws);
	void (*free)(void *ws);
	/* What the workspace carries from one step to the next (cached
	 * derivatives, step size, contact modes, dense output), for a
	 * checkpoint (checkpoint.c): its size in bytes, then saved into /
	 * loaded from a buffer of that size. NULL when the workspace caches
	 * nothing (size 0). load trusts its buffer: the caller checked it. */
	size_t (*state_size)(const void *ws);
	void (*save)(const void *ws, void *buf);
	void (*load)(void *ws, const void *buf);
} ode_method;

extern const ode_method ode_rk4, ode_dopri5, ode_euler, ode_split;

/* The registry: every integrator, in the order sim_methods lists them and
 * the setting "method" numbers them, as X(descriptor, name); each name is
 * its descriptor's own (ode_registry.c and params.c read this list alone;
 * test_params checks the names). */
#define ODE_REGISTRY(X) X(ode_rk4, "rk4") X(ode_dopri5, "dopri5") X(ode_euler, "euler") \
	X(ode_split, "dem")
/* The default integrator (the presets'). */
#define ODE_DEFAULT ode_split

/* Method by name, NULL if unknown. */
const ode_method *ode_find(const char *name);

/* Length of the fixed step that lands on t_max without a sliver. */
static inline double ode_fixed_step(double t, double dt, double t_max)
{
	double rest = t_max - t;
	return rest <= dt * (1.0 + 1e-9) ? rest : dt;
}

/* Cubic Hermite interpolant on a step of length H at u in [0, 1] from the
 * values p0, p1 and rates v0, v1 at its ends. */
static inline double ode_hermite(double p0, double v0, double p1, double v1, double H, double u)
{
	double u2 = u * u, u3 = u2 * u;
	return (2 * u3 - 3 * u2 + 1) * p0 + (u3 - 2 * u2 + u) * H * v0 + (-2 * u3 + 3 * u2) * p1 +
	       (u3 - u2) * H * v1;
}

#endif
