/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_plan.c - the mirror reduction of a sweep's points
 * (sim_study_mirror_plan): a point that is the mirror image of another is
 * no job of its own, and is filled, velocity negated, when the other is
 * over; a point's varied settings applied to its model; and the band
 * source of a sweep with band_from_fit; the check of a stored record.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "budget.h"
#include "fitjob.h"
#include "sim_mirror.h"
#include "study.h"
#include "sweep_int.h"
#include "units.h"

/* The mirror reduction's plan of the sweep's points: which are mirror
 * images of which (sw->image, sw->jobs, each point's `mirrored`), over
 * points that differ in sense and beta alone (sim_study_mirror_plan on
 * the sweep's varied settings, their values borrowed from the points).
 * The plan depends only on the request, so a restart makes it again. 0,
 * or -1 when out of memory. */
int srv_sweep_plan(srv_sweep *sw)
{
	size_t n = sw->total, np = (size_t)sw->req.nbeta, na = (size_t)sw->req.nvary;
	sim_study st = {.naxes = na, .nrot = (size_t)sw->req.nrot, .npoints = np};
	st.values = malloc(sizeof *st.values * (np * na > 0 ? np * na : 1));
	long *source = malloc(sizeof *source * (n ? n : 1));
	sw->image = malloc(sizeof *sw->image * (n ? n : 1));
	int rc = st.values && source && sw->image && n == np * st.nrot ? 0 : -1;
	for (size_t a = 0; rc == 0 && a < na; a++)
		if (!(st.axis[a].setting = sim_setting_find(sw->req.vary[a])))
			rc = -1;
	for (size_t r = 0; rc == 0 && r < st.nrot; r++)
		st.rotation[r] = sw->req.rotations[r];
	for (size_t k = 0; rc == 0 && k < np; k++)
		for (size_t a = 0; a < na; a++)
			st.values[k * na + a] = sw->pt[k].vary[a];
	if (rc == 0) {
		size_t run = sim_study_mirror_plan(&st, &sw->req.spec.params, &sw->req.spec.scene,
						   &sw->req.spec.method, source);
		rc = run == (size_t)-1 ? -1 : 0;
		sw->jobs = run;
	}
	for (size_t i = 0; rc == 0 && i < n; i++)
		sw->image[i] = -1;
	for (size_t i = 0; rc == 0 && i < n; i++) {
		sw->pt[i].mirrored = source[i] >= 0;
		if (source[i] >= 0)
			sw->image[source[i]] = (long)i;
	}
	free(st.values);
	free(source);
	return rc;
}

#define CUT(s) ((s)[sizeof(s) - 1] = '\0')

int srv_sweep_record_check(api_sweep_req *req, api_sweep_point *pt, size_t total, char *why,
			   size_t whylen)
{
	CUT(req->band_fit);
	for (int a = 0; a < SIM_STUDY_MAX_AXES; a++)
		CUT(req->vary[a]);
	for (int j = 0; j < FIT_MAX_FREE; j++)
		CUT(req->band_src.free[j].name);
	for (size_t k = 0; k < total; k++)
		CUT(pt[k].error);
	api_problem pb;
	if (api_check_model(&req->spec, &pb) != API_OK) {
		snprintf(why, whylen, "its spec: %.*s", whylen > 12 ? (int)(whylen - 12) : 0,
			 pb.detail);
		return -1;
	}
	const char *bad = NULL;
	if (req->nrot < 1 || req->nrot > 2 || total != (size_t)req->nbeta * (size_t)req->nrot)
		bad = "senses";
	for (int r = 0; !bad && r < req->nrot; r++)
		if (req->rotations[r] != SIM_CW && req->rotations[r] != SIM_CCW)
			bad = "a sense";
	if (!bad && !(req->t_end > 0.0 && req->t_end <= API_SWEEP_T_END_MAX))
		bad = "t_end";
	if (!bad && (req->nvary < 0 || req->nvary > SIM_STUDY_MAX_AXES))
		bad = "its varied settings";
	for (int a = 0; !bad && a < req->nvary; a++)
		if (!sim_setting_find(req->vary[a]))
			bad = "a varied setting";
	if (!bad && (req->band_src.nfree < 0 || req->band_src.nfree > FIT_MAX_FREE ||
		     req->band < 0 || req->band > 1 || req->lhs < 0))
		bad = "its band or sample";
	for (size_t k = 0; !bad && k < total; k++)
		if ((pt[k].rotation != SIM_CW && pt[k].rotation != SIM_CCW) || pt[k].state < 0 ||
		    pt[k].state > 3)
			bad = "a point";
	if (bad)
		snprintf(why, whylen, "inconsistent: %s", bad);
	return bad ? -1 : 0;
}

int srv_sweep_apply(const srv_sweep *sw, size_t i, api_spec *spec, char *msg, size_t msglen)
{
	const api_sweep_point *p = &sw->pt[i];
	spec->params.beta = p->beta.si;
	spec->params.rotation = p->rotation;
	for (int a = 0; a < sw->req.nvary; a++) {
		if (strcmp(sw->req.vary[a], "beta") == 0)
			continue;
		int rc = sim_set_user(&spec->params, &spec->scene, &spec->method, sw->req.vary[a],
				      p->vary[a], msg, msglen);
		if (rc != SIM_OK)
			return rc;
	}
	return SIM_OK;
}

api_err srv_sweep_check_cost(const srv_sweep *sw, api_problem *pb)
{
	/* beta and the sense leave a run's cost as it is: the first point
	 * stands for all unless other settings vary */
	int others = 0;
	for (int a = 0; a < sw->req.nvary; a++)
		others |= strcmp(sw->req.vary[a], "beta") != 0;
	for (size_t i = 0; i < (others ? sw->total : sw->total > 0); i++) {
		api_spec spec = sw->req.spec;
		char msg[160];
		if (srv_sweep_apply(sw, i, &spec, msg, sizeof msg) == SIM_OK &&
		    srv_budget_run_check(&spec, sw->req.t_end, pb) != API_OK)
			return pb->code;
	}
	return API_OK;
}

/* Point i is over (done or failed): its mirror image, if it has one, is
 * too (lock held). */
void srv_sweep_fill_image(srv_sweep *sw, size_t i)
{
	long j = sw->image[i];
	if (j < 0 || sw->pt[j].state >= 2)
		return;
	const api_sweep_point *src = &sw->pt[i];
	api_sweep_point *p = &sw->pt[j];
	p->state = src->state;
	sim_mirror_measurement(&src->m, &p->m);
	p->band[0] = -src->band[1]; /* the band's image: v -> -v */
	p->band[1] = -src->band[0];
	if (src->state == 3)
		sim_mirror_failure(p->error, sizeof p->error, src->beta.user, src->rotation,
				   src->error);
	sw->done++;
}

void srv_sweep_curve_tol(srv_sweep *sw)
{
	if (sw->done != sw->total || sw->req.nvary != 1 || strcmp(sw->req.vary[0], "beta") != 0)
		return;
	double *b = malloc(sw->total * sizeof *b), peak = 0.0;
	for (size_t k = 0; b && k < sw->total; k++)
		b[k] = sw->pt[k].beta.user;
	int curve = b && sim_curve_covers(b, sw->total);
	free(b);
	for (size_t k = 0; curve && k < sw->total; k++)
		if (sw->pt[k].state == 2)
			peak = fmax(peak, fabs(sw->pt[k].m.transport_velocity));
	for (size_t k = 0; curve && k < sw->total; k++)
		if (sw->pt[k].state == 2)
			sw->pt[k].m.tol_met = sim_tol_met_at_peak(&sw->pt[k].m,
								  sw->req.spec.method.tol, peak);
}

/* band_from_fit: the fit's result as the band source and the sweep's
 * model prepared for it (its fitted values, the varied ones skipped). */
api_err srv_sweep_prepare_band(api_sweep_req *req, api_problem *pb)
{
	api_err e = srv_fit_band_source(req->band_fit, &req->band_src, pb);
	if (e != API_OK)
		return e;
	const char *varied[SIM_STUDY_MAX_AXES];
	for (int a = 0; a < req->nvary; a++)
		varied[a] = req->vary[a];
	char msg[240];
	if (fit_band_source_prepare(&req->band_src, varied, (size_t)req->nvary, req->band_skip,
				    &req->spec.params, &req->spec.scene, &req->spec.method, msg,
				    sizeof msg) != SIM_OK)
		return api_fail(pb, API_INVALID, "band_from_fit", "band_from_fit: %s", msg);
	req->band = 1;
	return API_OK;
}
