/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_stop.c - the refusal of an identification's or a closed
 * loop's measurements stopped at --max-cpu-seconds in the request's thread
 * (srv_exp_stopped, experiment_int.h): experiment_kind.c's measurements
 * stop there, experiment_cost.c bounds them before; apart from both, so
 * that neither calls the other back. And the stop a DELETE asks
 * (srv_exp_cancel).
 */
#include <stdio.h>

#include "budget.h"
#include "experiment_int.h"
#include "util.h"

api_err srv_exp_stopped(const srv_experiment *e, const api_spec *spec, double deadline,
			api_problem *pb)
{
	double bound = srv_budget_run_limit(), spent = srv_thread_cpu() - (deadline - bound);
	const char *what = e->ext.kind == API_EXP_IDENTIFY ? "identify's slopes"
							    : "control's measurements";
	char names[96], choices[96];
	if (srv_budget_fixed_methods(spec, names, sizeof names, choices, sizeof choices)) {
		const char *field = e->req.fresh ? "session.integrator.method" : "session";
		api_fail_choices(pb, API_RANGE, field, e->req.fresh ? choices : "",
				 "%s stopped at %.3g CPU s in this request's thread, past "
				 "--max-cpu-seconds (%g): no estimate knows the steps of "
				 "integrator.method %s (adaptive); nothing was started: a session whose "
				 "integrator.method has a fixed step (%s)", what, spent, bound,
				 spec->method.name, names);
	} else {
		const char *field = e->ext.kind == API_EXP_IDENTIFY ? "identify.beta"
				    : e->req.fresh			 ? "session.scene.columns"
									 : "session";
		api_fail(pb, API_RANGE, field,
			 "%s stopped at %.3g CPU s in this request's thread, past --max-cpu-seconds "
			 "(%g), estimated within it; nothing was started: %sa larger integrator.dt or "
			 "a smaller scene", what, spent, bound,
			 e->ext.kind == API_EXP_IDENTIFY ? "fewer operating points, " : "");
	}
	return api_budget(pb, "cpu", bound, 0);
}

int srv_exp_cancel(srv_experiment *e, int only_running, char *sid, size_t sidlen)
{
	pthread_mutex_lock(&e->lock);
	if (only_running && e->state >= EXP_DONE) {
		pthread_mutex_unlock(&e->lock);
		return -1;
	}
	e->deleted = 1;
	int on = e->attached && e->session_id[0];
	if (on)
		snprintf(sid, sidlen, "%s", e->session_id);
	pthread_mutex_unlock(&e->lock);
	return on;
}

int srv_exp_deleted(srv_experiment *e)
{
	pthread_mutex_lock(&e->lock);
	int gone = e->deleted;
	pthread_mutex_unlock(&e->lock);
	return gone;
}
