/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * band_from.c - `convsim sweep --band-from FIT.json`: a fit's result (the
 * JSON of `convsim fit`) read back as a band source (core/fit/fit.h), its
 * fitted values set on the study's model for the parameters the study
 * does not vary, and the varied ones marked to leave the band. The
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
	for (int j = 0; j < src->nfree; j++) {
		skip[j] = 0;
		for (size_t a = 0; a < st->naxes; a++)
			skip[j] |= strcmp(st->axis[a].setting->name, src->free[j].name) == 0;
	}
	if (fit_band_source_apply(src, skip, &o->p, &o->sc, &o->m, msg, sizeof msg) != SIM_OK) {
		fprintf(stderr, "convsim sweep: --band-from %s: %s\n", o->band_from, msg);
		return 2;
	}
	/* the images of the mirror reduction take their sources' bands only
	 * where every perturbed model is mirror-symmetric as well */
	for (int j = 0; j < src->nfree; j++) {
		sim_params p = o->p;
		sim_scene sc = o->sc;
		sim_method m = o->m;
		if (skip[j] || !sim_mirror_applies(&p, &sc))
			continue;
		double x = src->x[j] + fit_step(&src->free[j], src->fd_rel, src->x[j]);
		if (sim_set(&p, &sc, &m, src->free[j].name, x, NULL, 0) != SIM_OK ||
		    !sim_mirror_applies(&p, &sc))
			sim_set(&o->p, &o->sc, &o->m, "mirror", 0, NULL, 0);
	}
	return 0;
}
