/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peer.h - the benchmark's peers: integrators from GSL (odeiv2) and
 * SUNDIALS (CVODE, ARKODE) wrapped as core integrator descriptors
 * (core/ode.h), so that they step the very right-hand side the core's
 * rk4, dopri5 and euler step (dynamics_eval through dyn_rhs) inside an
 * ordinary sim: the same start, settling, observers and transport
 * estimator. They live in tests/bench only; the core stays libc + libm.
 *
 * Every peer: adaptive, tolerances rtol and atol = 1e-3 rtol on the
 * positions and velocities (the core's dopri5 convention); the energy
 * accumulators ride along outside the error control; largest step 2e-3 s
 * (as dopri5); no smallest step beyond each library's own; steps clamped
 * to the caller's t_max (the settling's t = 0 and every sim_advance
 * target), so no interpolation is needed to observe. Implicit methods get
 * a dense Jacobian by forward differences (the right-hand side has no
 * analytic one: its contact and friction laws switch).
 */
#ifndef CONVSIM_PEER_H
#define CONVSIM_PEER_H

#include <stdint.h>

#include "sim_int.h"

/* What every peer's workspace starts with (peer_gsl.c, peer_sundials.c). */
typedef struct peer_ws {
	int n, nerr;          /* state length; components under error control */
	double rtol, atol;
	dyn *sys;             /* the dyn of the step in progress (borrowed) */
	int need_init;        /* (re)start from the caller's state at the next step */
	uint64_t steps, rejected; /* accepted steps; error-test (and convergence) failures */
	char msg[160];        /* why the last step failed */
} peer_ws;

/* The peers' names ("gsl-rk8pd", ..., "arkode-erk"), NULL-terminated. */
extern const char *const peer_names[];

/* One line on how the named peer is set up (for the report), or NULL. */
const char *peer_doc(const char *name);

/* A sim of (p, sc) stepped by the peer `name` at tolerance rtol, from the
 * scene's start (sim_start: a `steady` start's settling is the peer's
 * too). NULL with msg on an unknown name, a refused setting, or a failed
 * start. The caller frees it with sim_free. */
sim *peer_sim_new(const char *name, double rtol, const sim_params *p, const sim_scene *sc,
		  char *msg, size_t msglen);

/* The peer's counters and last failure of a sim from peer_sim_new. */
const peer_ws *peer_of(const sim *s);

/* A CPU-time budget for every peer step from now on (process CPU
 * seconds; <= 0: none). A step past it fails with "CPU budget ..." in
 * its msg. */
void peer_set_budget(double cpu_seconds);

/* Process CPU time, seconds. */
double peer_cpu_now(void);

/* Shared by the wrappers: the budget check (SIM_OK, or SIM_ESTEP with the
 * reason in w->msg at time t); the forward-difference Jacobian of the
 * right-hand side at (t, y) into J (row-major n x n, J[i n + j] =
 * d f_i / d y_j), f0 = f(t, y) given, work of length 2 n; the tolerance
 * weights' absolute part per component into atol (n). */
int peer_budget_check(peer_ws *w, double t);
void peer_fd_jacobian(peer_ws *w, double t, const double *y, const double *f0, double *J,
		      double *work);
void peer_atol_vector(const peer_ws *w, double *atol);

/* The interpolate of a peer without dense output: never called, since
 * every step is clamped to the target sim_advance passes; aborts with a
 * message if it is. */
void peer_no_interpolation(void *ws, double t, double *out);

/* Every peer's reset: restart from the caller's state at the next step. */
void peer_reset(void *ws);

/* The descriptors (peer_gsl.c, peer_sundials.c: CVODE and ARKODE): the
 * variant is chosen by the sim_method's name at alloc. */
extern const ode_method peer_gsl, peer_sundials;

#endif
