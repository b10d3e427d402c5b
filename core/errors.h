/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * errors.h - the core's return codes (errors.c has their messages). Part
 * of the public interface (sim.h includes it); the integrators include
 * this one instead of sim.h.
 */
#ifndef CONVSIM_ERRORS_H
#define CONVSIM_ERRORS_H

/* Return codes: one list, expanded into the enum and sim_strerror().
 * X(name, message); no transport meaning (api/errors.c maps them). */
#define SIM_ERRNO_MAP(X)                                                      \
	X(OK, "ok")                                                           \
	X(EPARAM, "parameter out of range")                                   \
	X(EUNKNOWN, "unknown name")                                           \
	X(ENOMEM, "out of memory")                                            \
	X(EDIVERGED, "simulation diverged")                                   \
	X(ESTEP, "step size underflow")                                       \
	X(ETIME, "requested time lies in the past")                           \
	X(ECHECKPOINT, "checkpoint damaged, cut off or of another version")   \
	X(ECPU, "stopped at the caller's CPU limit")

typedef enum {
#define SIM_ERR_ENUM(name, msg) SIM_##name,
	SIM_ERRNO_MAP(SIM_ERR_ENUM)
#undef SIM_ERR_ENUM
	SIM_NERR
} sim_err;

/* Static text for a return code; never NULL. */
const char *sim_strerror(int err);

#endif
