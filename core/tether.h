/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * tether.h - end this process with the one named by CONVSIM_TETHER
 * (tether.c): what the test suite sets so that nothing it starts
 * outlives it.
 */
#ifndef CONVSIM_TETHER_H
#define CONVSIM_TETHER_H

/* Read CONVSIM_TETHER (a process id). When set, this process gets a
 * SIGKILL when that process ends (at once if it has ended). Call first
 * in main, before other threads start. Returns 1 tethered, 0 the variable
 * is not set, -1 it could not be done (a message on stderr for a bad
 * value). */
int sim_tether_from_env(void);

#endif
