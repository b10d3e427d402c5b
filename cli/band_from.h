/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * band_from.h - `convsim sweep --band-from FIT.json` (band_from.c).
 */
#ifndef CONVSIM_BAND_FROM_H
#define CONVSIM_BAND_FROM_H

#include "cli.h"
#include "fit.h"
#include "study.h"

/* Read o->band_from into *src, mark in skip[j] the source's parameters
 * that the planned study st varies, set the others' fitted values on
 * o's model, and switch the mirror reduction off where a parameter's
 * step would break the symmetry the images rely on. 0, or 2 after a
 * message (the file unreadable or not a fit's result, no covariance). */
int cli_band_from(cli_opts *o, const sim_study *st, fit_band_source *src, int skip[FIT_MAX_FREE]);

#endif
