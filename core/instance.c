/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * instance.c - an instance's workspace: allocated once for a validated
 * set (the model, the controls, the state vectors, the integrator's
 * workspace), released with everything it owns. Shared by sim.c (a new
 * instance), checkpoint.c (a restored one) and shadow.c (the measured
 * step error's second instance). Also the feed masses a running instance
 * takes (sim_feed_mass_range), which depend on the method as sim_alloc
 * resolves it, and what an instance would integrate, looked at without
 * its start (sim_preview).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim_int.h"
#include "units.h"

sim *sim_alloc(const sim_params *p, const sim_scene *sc, const sim_method *m, int *err,
	       char *msg, size_t msglen)
{
	int e = sim_validate(p, sc, m, msg, msglen);
	sim *s = NULL;
	if (e != SIM_OK)
		goto fail;
	if (sc->feed_model == SIM_FEED_AUTO) { /* the caller's to resolve */
		e = SIM_EPARAM;
		if (msg)
			snprintf(msg, msglen, "feed_model auto picks the model of one run "
					      "(convsim run, a session): give column here");
		goto fail;
	}
	e = SIM_ENOMEM;
	s = calloc(1, sizeof *s);
	if (!s)
		goto fail;
	model_init(&s->md, &s->ctl, p, sc);
	s->sys = (dyn){.md = &s->md, .ctl = &s->ctl, .rhs_evals = 0};
	s->cfg = *m;
	if (s->cfg.dt == 0.0)
		s->cfg.dt = sim_default_dt(p, sc, m);
	if (s->cfg.substeps == 0)
		s->cfg.substeps = s->md.nf > 0 ? sim_default_substeps(p, sc, &s->cfg, s->cfg.dt) : 1;
	s->ode = ode_find(m->name);
	s->step_error = NAN;
	s->shadow_v = NAN;
	s->step_se = NAN;
	s->shadow_window = SHADOW_PERIODS * 2.0 * M_PI / p->omega_ss;
	size_t n = (size_t)s->md.n;
	s->y = calloc(4 * n, sizeof(double));
	s->X0k = calloc((size_t)(s->md.dk.K > 0 ? s->md.dk.K : 1), sizeof(double));
	if (!s->y || !s->X0k)
		goto fail;
	s->y_obs = s->y + n;
	s->dy = s->y_obs + n;
	s->y_prev = s->dy + n;
	s->ws = s->ode->alloc(&s->md, &s->cfg);
	if (!s->ws)
		goto fail;
	if (err)
		*err = SIM_OK;
	return s;
fail:
	if (e == SIM_ENOMEM && msg)
		snprintf(msg, msglen, "out of memory for the simulation workspace");
	if (err)
		*err = e;
	sim_free(s);
	return NULL;
}

int sim_preview(const sim_params *p, const sim_scene *sc, const sim_method *m,
		sim_status *st, int *columns, int *layers, char *msg, size_t msglen)
{
	int err = SIM_OK;
	memset(st, 0, sizeof *st);
	*columns = *layers = 0;
	sim *s = sim_alloc(p, sc, m, &err, msg, msglen);
	if (!s)
		return err ? err : SIM_ENOMEM;
	sim_status_shape(s, st);
	*columns = sim_columns(s);
	*layers = sim_layers(s);
	sim_free(s);
	return SIM_OK;
}

void sim_free(sim *s)
{
	if (!s)
		return;
	sim_free(s->shadow);
	if (s->ode && s->ws)
		s->ode->free(s->ws);
	free(s->y);
	free(s->X0k);
	free(s);
}

/* The machine's mass that the corrector's ratio divides by (setup.c's
 * model_feed_mass_ratio). */
static double machine_mass(const sim_params *p)
{
	return p->M_r + p->m + p->m1 + p->m2;
}

void sim_feed_mass_range(const sim_params *p, const sim_scene *sc, const sim_method *m,
			 double *lo, double *hi)
{
	const sim_setting *set = sim_setting_find("m_n");
	*lo = set->min;
	*hi = set->max;
	const ode_method *ode = ode_find(m->name);
	if (!ode || !ode->info.substeps || !sc->feed || !sc->feed_coupling ||
	    sc->feed_model != SIM_FEED_COLUMN || sc->columns < 1 || sc->layers < 1)
		return;
	/* the sub-steps as sim_alloc resolves them */
	sim_method r = *m;
	if (r.dt == 0.0)
		r.dt = sim_default_dt(p, sc, m);
	if (r.substeps == 0)
		r.substeps = sim_default_substeps(p, sc, &r, r.dt);
	if (r.substeps <= 1)
		return;
	double edge = MODEL_CORRECTOR_MAX_RATIO * machine_mass(p) /
		      ((double)sc->columns * (double)sc->layers);
	if (model_feed_mass_ratio(p, sc) <= MODEL_CORRECTOR_MAX_RATIO)
		*hi = fmin(*hi, edge);
	else
		*lo = fmax(*lo, nextafter(edge, INFINITY));
}
