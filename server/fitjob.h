/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fitjob.h - calibration fits as jobs: a driver thread per fit, its model
 * evaluations on the worker pool, progress, results, cancel.
 */
#ifndef CONVSIM_FITJOB_H
#define CONVSIM_FITJOB_H

#include "config.h"
#include "reply.h"

/* Start with an empty registry of at most cfg->max_fits fits. */
void srv_fits_init(const srv_config *cfg);
/* Wait for every driver (they see srv_stopping() and stop after their
 * running evaluations; call before the pool stops) and free every fit. */
void srv_fits_shutdown(void);

/* POST /api/v1/fits, GET /api/v1/fits[/{id}], DELETE /api/v1/fits/{id}. */
enum MHD_Result srv_h_fits_create(srv_req *r);
enum MHD_Result srv_h_fits_list(srv_req *r);
enum MHD_Result srv_h_fit_get(srv_req *r);
enum MHD_Result srv_h_fit_delete(srv_req *r);

#endif
