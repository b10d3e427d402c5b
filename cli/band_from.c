/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * band_from.c - `convsim sweep --band-from FIT.json`: a fit's result (the
 * JSON of `convsim fit`) read back as a band source (fit/fit.h) and
 * the study's model prepared for it (fit_band_source_prepare). The
 * points' bands themselves are fit_band_point's, per task in
 * sweep_cmd.c.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "band_from.h"

int cli_band_from(cli_opts *o, const sim_study *st, fit_band_source *src, int skip[FIT_MAX_FREE])
{
	char msg[300];
	char *text = cli_slurp("sweep", "band-from", o->band_from);
	if (!text)
		return 2;
	int rc = fit_band_source_parse(text, src, msg, sizeof msg);
	free(text);
	if (rc != SIM_OK) {
		fprintf(stderr, "convsim sweep: --band-from %s: %s\n", o->band_from, msg);
		return 2;
	}
	const char *varied[SIM_STUDY_MAX_AXES];
	for (size_t a = 0; a < st->naxes; a++)
		varied[a] = st->axis[a].setting->name;
	if (fit_band_source_prepare(src, varied, st->naxes, skip, &o->p, &o->sc, &o->m, msg,
				    sizeof msg) != SIM_OK) {
		fprintf(stderr, "convsim sweep: --band-from %s: %s\n", o->band_from, msg);
		return 2;
	}
	return 0;
}
