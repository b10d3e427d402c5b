/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep.h - v(beta) sweeps on the worker pool and their resources.
 */
#ifndef CONVSIM_SWEEP_H
#define CONVSIM_SWEEP_H

#include "config.h"
#include "reply.h"

/* Start with an empty registry; cfg (borrowed for the daemon's life) gives
 * --max-sweeps and --data-dir. */
void srv_sweeps_init(const srv_config *cfg);
/* Rebuild the sweeps of the data directory (after the pool started):
 * finished ones are served again, pending points are queued. How many. */
size_t srv_sweeps_restore(void);
/* Free every sweep (after the pool has stopped). */
void srv_sweeps_shutdown(void);

/* POST /api/v1/sweeps, GET /api/v1/sweeps[/{id}], DELETE
 * /api/v1/sweeps/{id}. */
enum MHD_Result srv_h_sweeps_create(srv_req *r);
enum MHD_Result srv_h_sweeps_list(srv_req *r);
enum MHD_Result srv_h_sweep_get(srv_req *r);
enum MHD_Result srv_h_sweep_delete(srv_req *r);

#endif
