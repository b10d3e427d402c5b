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
/* Wait for every driver (they see srv_stopping() and stop after their
 * running evaluations; call before the pool stops) and free every fit. */
void srv_fits_shutdown(void);

/* POST /api/v1/fits, GET /api/v1/fits[/{id}], DELETE /api/v1/fits/{id}. */
#endif
