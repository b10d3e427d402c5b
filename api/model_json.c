/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model_json.c - the DEM check of a scene's column model (core's
 * sim_model_check) as the members every answer that reports a v carries:
 * model_error, model_error_uncertainty, model_checked, model_check_note.
 * Its own file, so that the session, control, sweep and experiment
 * writers all use it without using each other.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "json_int.h"

int api_model_check(const api_spec *spec, const sim_status *st, sim_model_error *me)
{
	sim_params p = spec->params;
	if (st) {
		p.beta = st->beta_target;
		p.rotation = st->rotation;
		p.omega_ss = st->omega_ss;
		p.m_n = st->m_n;
		p.mu = st->mu;
	}
	int rc = sim_model_check(&p, &spec->scene, me);
	/* a model_tol given (feed_model auto picked at creation, the pick
	 * kept): say where the scene as it stands now leaves it */
	double tol = spec->scene.model_tol;
	size_t n = strlen(me->note);
	if (rc >= 0 && tol > 0 && !(me->checked && me->error + me->error_uncertainty <= tol))
		snprintf(me->note + n, sizeof me->note - n, "; outside model_tol %g m/s", tol);
	return rc;
}

void api_add_model_error(cJSON *o, const sim_model_error *me)
{
	api_add_number(o, "model_error", me->checked ? me->error : NAN);
	api_add_number(o, "model_error_uncertainty", me->checked ? me->error_uncertainty : NAN);
	cJSON_AddBoolToObject(o, "model_checked", me->checked);
	cJSON_AddStringToObject(o, "model_check_note", me->note);
}

void api_buf_model_error(api_buf *b, const sim_model_error *me)
{
	if (!me) {
		api_buf_puts(b, ",,,");
		return;
	}
	api_buf_put(b, ",", 1);
	if (me->checked && isfinite(me->error))
		api_buf_double(b, me->error);
	api_buf_put(b, ",", 1);
	if (me->checked && isfinite(me->error_uncertainty))
		api_buf_double(b, me->error_uncertainty);
	api_buf_puts(b, me->checked ? ",true" : ",false");
}
