/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_int.h - a sweep as sweep.c and sweep_plan.c see it (the rest of
 * the daemon knows a sweep only as a kind of job, job.h).
 */
#ifndef CONVSIM_SWEEP_INT_H
#define CONVSIM_SWEEP_INT_H

#include <pthread.h>
#include <stddef.h>

#include "api.h"
#include "registry.h"

typedef struct srv_sweep {
	srv_entry entry;       /* id and references: the registry */
	pthread_mutex_t lock;
	/* guarded by lock */
	api_sweep_req req;
	api_sweep_point *pt;
	long *image;           /* the point derived from point i, or -1 */
	size_t total, done;
	size_t jobs;           /* points that run (the others are images) */
	int running, cancelled;
	char store_error[256];  /* a write failed: state "error" */
	char damaged[256];      /* its record is unusable: why (state
				   "damaged", no points) */
	char *csv;              /* damaged: the result file as stored, or NULL */
	size_t csv_len;
} srv_sweep;

/* The mirror reduction's plan of the sweep's points (sweep_plan.c): which
 * are mirror images of which (sw->image, sw->jobs, each point's
 * `mirrored`). The plan depends only on the request, so a restart makes it
 * again. 0, or -1 when out of memory. */
int srv_sweep_plan(srv_sweep *sw);
/* A request and its points as a restart reads them back from
 * sweeps/ID.bin (sweep_load), before anything else reads them: the model
 * as api_check_model has it, 1 or 2 senses (total = nbeta per sense), each
 * cw or ccw, t_end within (0, API_SWEEP_T_END_MAX], at most
 * SIM_STUDY_MAX_AXES varied settings, each known, at most FIT_MAX_FREE band
 * parameters, every point a sense and a state (0-3); the strings cut at
 * their size. 0, or -1 with the reason in why. */
int srv_sweep_record_check(api_sweep_req *req, api_sweep_point *pt, size_t total, char *why,
			   size_t whylen);
/* Each point's run within --max-cpu-seconds (srv_budget_run_check, its
 * own settings applied): API_OK, or the first refusal in *pb. */
api_err srv_sweep_check_cost(const srv_sweep *sw, api_problem *pb);
/* Point i's settings on *spec (a copy of the request's): its beta
 * (SI, from api/), rotation and every other varied setting. SIM_OK, or
 * the setting's error with msg. */
int srv_sweep_apply(const srv_sweep *sw, size_t i, api_spec *spec, char *msg, size_t msglen);
/* Point i is over (done or failed): its mirror image, if it has one, is
 * too (lock held). */
void srv_sweep_fill_image(srv_sweep *sw, size_t i);
/* Once every point is over, a v(beta) curve's tol_met judged again with
 * its own peak (sim_tol_met_at_peak, core/study.h; lock held): a point
 * shows its run's until then. */
void srv_sweep_curve_tol(srv_sweep *sw);
/* band_from_fit (sweep_plan.c): the fit's result as the band source and
 * the request's model prepared for it (its fitted values, the varied ones
 * skipped); API_OK or the problem (srv_fit_band_source's, or a 422
 * naming band_from_fit). */
api_err srv_sweep_prepare_band(api_sweep_req *req, api_problem *pb);

#endif
