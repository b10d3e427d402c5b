/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fitjob.h - calibration fits as jobs: a driver thread per fit, its model
 * evaluations on the worker pool, progress, results, cancel.
 */
#ifndef CONVSIM_FITJOB_H
#define CONVSIM_FITJOB_H

#include "api.h"
#include "config.h"
#include "reply.h"

/* Start with an empty registry of at most cfg->max_fits fits. */
/* Wait for every driver (they see srv_stopping() and stop after their
 * running evaluations; call before the pool stops) and free every fit. */
void srv_fits_shutdown(void);

/* POST /api/v1/fits, GET /api/v1/fits[/{id}], DELETE /api/v1/fits/{id}. */

/* The band source of fit id (a sweep's band_from_fit): its result read
 * back (fit_band_source_parse) with the fit's own step. API_OK, or a 422
 * naming band_from_fit: no such fit, not finished, failed, or no
 * covariance. */
api_err srv_fit_band_source(const char *id, fit_band_source *src, api_problem *pb);
#endif
