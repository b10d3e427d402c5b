/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_control.c - a control (PATCH, session.h srv_session_control)
 * from its admission to its answer: checked against the session's state
 * and the budgets, queued to the worker (whose commands phase applies it,
 * worker_control.c), waited for, and answered once its control-log line
 * is durable; and an experiment attached to send its segments' controls.
 */
#include <errno.h>
#include <math.h>
#include <string.h>

#include "experiment.h"
#include "session_int.h"
#include "util.h"

static const srv_config *cfg;

void srv_session_control_init(const srv_config *config)
{
	cfg = config;
}

/* ---- the PATCH controls' admit column (api.h API_CONTROLS, by id) ---------- */

/* An admit: 0 (API_OK) if control c's member may go to s, else the error
 * with *pb filled (lock held). */
typedef api_err (*control_admit)(const srv_session *s, const api_control *c,
				 api_problem *pb);

static api_err admit_cpu_limit(const srv_session *s, const api_control *c,
			       api_problem *pb)
{
	(void)s;
	if (c->cpu_budget >= API_CPU_BUDGET_MIN && c->cpu_budget <= cfg->max_cpu_seconds)
		return API_OK;
	return api_fail_range(pb, "cpu_budget", API_CPU_BUDGET_MIN, cfg->max_cpu_seconds,
			      "cpu_budget must be CPU seconds in [%g, %g] "
			      "(--max-cpu-seconds); got %g", API_CPU_BUDGET_MIN,
			      cfg->max_cpu_seconds, c->cpu_budget);
}

int srv_until_cuts_experiment(const srv_session *s, double until)
{
	double end = s->exp ? srv_exp_end(s->exp) : NAN;
	return until > 0 && end > until;
}

static api_err admit_until(const srv_session *s, const api_control *c,
			   api_problem *pb)
{
	if (c->until > 0 && c->until <= s->st.t)
		return api_fail(pb, API_CONFLICT, "until",
				"until (%g s) lies in the past: the session is at "
				"t = %g s", c->until, s->st.t);
	/* an experiment runs its session to its schedule's end (worker.c
	 * extend_until); an until before that would end the session under
	 * it. One attached but not yet begun raises until when it begins,
	 * before the worker applies this control, which it then refuses
	 * (worker_control.c; srv_session_control answers it here again). */
	if (srv_until_cuts_experiment(s, c->until))
		return api_fail(pb, API_CONFLICT, "until",
				"experiment %s runs the session to t = %g s: until "
				"(%g s) must be at least that, or null, until it ends",
				srv_exp_id(s->exp), srv_exp_end(s->exp), c->until);
	return API_OK;
}

static api_err admit_running(const srv_session *s, const api_control *c,
			     api_problem *pb)
{
	if (c->running && s->state == SRV_FINISHED && !(c->set & API_C_UNTIL))
		return api_fail(pb, API_CONFLICT, "running",
				"the session finished at until = %g s; raise "
				"until to run on", s->until);
	return API_OK;
}

/* The column in two passes: `limit` checks a member against the daemon's
 * options, before the session's state (a cpu_budget past --max-cpu-seconds
 * is a 422 even for a session being deleted); `state` against the session,
 * after it. A member without an entry is admitted as parsed. */
static const struct {
	control_admit limit, state;
} control_admits[API_CTL_COUNT] = {
	[API_CTL_RUNNING] = {NULL, admit_running},
	[API_CTL_UNTIL] = {NULL, admit_until},
	[API_CTL_CPU] = {admit_cpu_limit, NULL},
};

#define CONTROL_BIT(id, member, bit, fn) [API_CTL_##id] = bit,
static const unsigned control_bits[API_CTL_COUNT] = {API_CONTROLS(CONTROL_BIT)};
#undef CONTROL_BIT

/* The session's state: one taking no more controls refuses any. */
static api_err admit_session(const srv_session *s, api_problem *pb)
{
	if (s->stop)
		return api_fail(pb, API_NOTFOUND, NULL,
				"the session is being deleted");
	if (s->state == SRV_FAILED)
		return api_fail(pb, API_CONFLICT, NULL,
				"the session has failed (%s); it takes no more "
				"controls", s->error);
	return API_OK;
}

/* A refusal of the paced cores for s at pace (e, *pb): a pace that alone
 * needs more than the whole budget is 422 stating pace's range, the
 * greatest pace that fits as max (or "max", pace's one choice, where none
 * does), so it names the pace, pace_field ("pace" in a PATCH,
 * "session.pace" in an experiment's body); who, which asked for that pace
 * without giving it (running, until, cpu_budget, "the experiment"), is
 * named in the detail. A 503 names who (lock held). */
static api_err pace_refused(srv_session *s, double pace, const char *pace_field,
			    const char *who, api_err e, api_problem *pb)
{
	if (e != API_RANGE)
		return e;
	if (pb->has_range)
		pb->max = srv_budget_greatest_pace(srv_paced_cost_of, s, srv_budget_paced_limit());
	else
		snprintf(pb->choices, sizeof pb->choices, "max");
	if (strcmp(pb->field, pace_field) != 0) {
		char detail[sizeof pb->detail];
		memcpy(detail, pb->detail, sizeof detail);
		snprintf(pb->detail, sizeof pb->detail, "%.16s would run it at its pace %g: %.260s",
			 who, pace, detail);
		snprintf(pb->field, sizeof pb->field, "%s", pace_field);
	}
	return e;
}

/* The paced cores s needs after c: raise its hold before c is queued, or
 * refuse (lock held). A 503 names the member that raises it; a pace beyond
 * the whole budget is pace_refused's 422. */
static api_err admit_paced(srv_session *s, const api_control *c,
			   api_problem *pb)
{
	double pace = (c->set & API_C_PACE) ? c->pace : s->pace;
	if (pace == API_PACE_MAX ||
	    srv_state_after(s->state, s->budget.cpu_paused, s->st.t, c) != SRV_RUNNING ||
	    srv_paced_cost(s, pace) * pace <= s->budget.paced_held)
		return API_OK;
	const char *field = (c->set & API_C_PACE)      ? "pace"
			    : (c->set & API_C_RUNNING) ? "running"
			    : (c->set & API_C_CPU)     ? "cpu_budget"
						       : "until";
	api_err e = srv_budget_take_paced(&s->budget.paced_held, srv_paced_cost(s, pace), pace,
					  field, "changed", pb);
	return pace_refused(s, pace, "pace", field, e, pb);
}

/* Admit c to s, the first refusal winning, in this fixed order: the
 * members' limits (table order), the session's state, the members against
 * the session (table order; until's and running's never both apply: running's
 * needs until absent), the paced cores (lock held). */
static api_err admit_control(srv_session *s, const api_control *c,
			     api_problem *pb)
{
	api_err e;
	for (size_t i = 0; i < API_CTL_COUNT; i++)
		if ((c->set & control_bits[i]) && control_admits[i].limit &&
		    (e = control_admits[i].limit(s, c, pb)) != API_OK)
			return e;
	if ((e = admit_session(s, pb)) != API_OK)
		return e;
	for (size_t i = 0; i < API_CTL_COUNT; i++)
		if ((c->set & control_bits[i]) && control_admits[i].state &&
		    (e = control_admits[i].state(s, c, pb)) != API_OK)
			return e;
	return admit_paced(s, c, pb);
}

api_err srv_session_control(srv_session *s, api_control *c,
			    double timeout_s, double *t_eff, api_problem *pb)
{
	srv_cmd cmd = {.c = *c, .cpu_grant = cfg->max_cpu_seconds, .waited = 1};
	pthread_mutex_lock(&s->lock);
	api_err e = admit_control(s, c, pb);
	if (e != API_OK) {
		pthread_mutex_unlock(&s->lock);
		return e;
	}
	srv_worker_queue(s, &cmd);
	struct timespec until = srv_deadline(timeout_s);
	while (!cmd.done && !s->stop)
		if (pthread_cond_timedwait(&s->data, &s->lock, &until) ==
		    ETIMEDOUT)
			break;
	if (!cmd.done) { /* take it back: nothing changes */
		srv_worker_unqueue(s, &cmd);
		srv_budget_set_paced(&s->budget.paced_held, srv_paced_need(s));
		pthread_mutex_unlock(&s->lock);
		return api_fail(pb, API_UNAVAILABLE, NULL,
				"the session's worker did not take the change "
				"within %g s; nothing was changed", timeout_s);
	}
	if (cmd.overtaken) { /* an experiment began under it: nothing applied */
		srv_budget_set_paced(&s->budget.paced_held, srv_paced_need(s));
		e = admit_until(s, c, pb);
		if (e == API_OK) /* that experiment is gone since: still nothing applied */
			e = api_fail(pb, API_CONFLICT, "until",
				     "an experiment that began after this control was admitted "
				     "ran the session past until (%g s); nothing was applied: "
				     "send it again", c->until);
		pthread_mutex_unlock(&s->lock);
		return e;
	}
	pthread_mutex_unlock(&s->lock);
	if (cmd.rc != SIM_OK)
		return api_fail(pb, api_from_sim(cmd.rc), NULL, "%s",
				sim_strerror(cmd.rc));
	/* the answer only once its line is on disk (control_log.c) */
	int err = cmd.logged ? srv_control_log_sync(s, cmd.logged, timeout_s) : 0;
	if (err) {
		api_fail(pb, API_UNAVAILABLE, NULL,
			 "the control was applied at t = %g s but its line could not be made "
			 "durable in the control log (%s): a crash may lose it",
			 cmd.t_eff, strerror(err));
		pb->retry_after = 5;
		return API_UNAVAILABLE;
	}
	*t_eff = cmd.t_eff;
	*c = cmd.c;
	return API_OK;
}

api_err srv_session_attach(srv_session *s, srv_experiment *e,
			   api_problem *pb)
{
	api_err rc = API_OK;
	pthread_mutex_lock(&s->lock);
	if (s->stop)
		rc = api_fail(pb, API_NOTFOUND, "session",
			      "the session is being deleted");
	else if (s->state == SRV_FAILED)
		rc = api_fail(pb, API_CONFLICT, "session",
			      "the session has failed (%s)", s->error);
	else if (s->exp)
		rc = api_fail(pb, API_CONFLICT, "session",
			      "the session already runs experiment %s",
			      srv_exp_id(s->exp));
	else if (s->state == SRV_FINISHED && s->pace != API_PACE_MAX &&
		 (rc = pace_refused(s, s->pace, "session.pace", "the experiment",
				    srv_budget_take_paced(&s->budget.paced_held,
							  srv_paced_cost(s, s->pace), s->pace,
							  "session", "attached", pb),
				    pb)) != API_OK)
		; /* the experiment would run it on (worker.c extend_until)
		     past the cores for paced sessions: nothing attached */
	else {
		s->exp = e;
		s->exp_started = 0;
		srv_exp_set_session(e, s->entry.id);
		pthread_cond_broadcast(&s->wake);
	}
	pthread_mutex_unlock(&s->lock);
	return rc;
}

int srv_session_detach(srv_session *s, srv_experiment *e, const char *why)
{
	pthread_mutex_lock(&s->lock);
	int ours = s->exp == e, owned = ours && s->owned;
	if (ours) {
		srv_worker_detach_exp(s, why);
		s->persist.ckpt_dirty = 1; /* its checkpoint no longer carries e */
		pthread_cond_broadcast(&s->data);
	}
	pthread_mutex_unlock(&s->lock);
	return owned;
}

/* Whether e, attached again to s as restored, begins where it began
 * before: created with s, which came back from its spec at t = 0; or s
 * stood still at its checkpoint (finished or paused) and nothing but e's
 * own commands came after it, so that e began right there. */
static int begins_as_before(const srv_session *s, const srv_experiment *e)
{
	if (srv_exp_request(e)->fresh && sim_effective_time(s->sim) == 0)
		return 1;
	if (s->state == SRV_RUNNING)
		return 0;
	for (size_t i = 0; i < s->restore.nreplay; i++)
		if (strcmp(s->restore.replay[i].exp, srv_exp_id(e)) != 0)
			return 0;
	return 1;
}

void srv_session_readopt(srv_session *s, const srv_exp_finder *ef)
{
	if (s->exp || !s->sim || s->state == SRV_FAILED || !ef || !ef->readopt)
		return;
	srv_experiment *e = ef->readopt(s->entry.id);
	if (!e)
		return;
	s->exp = e;
	s->exp_started = 0;
	/* it runs again exactly as it ran: its logged segment commands are
	 * left to it (sent again at the same times, not logged twice) */
	int same = begins_as_before(s, e);
	size_t own = 0;
	for (size_t i = 0; same && i < s->restore.nreplay; i++) {
		srv_replay *rp = &s->restore.replay[i];
		rp->exp_own = strcmp(rp->exp, srv_exp_id(e)) == 0;
		own += (size_t)rp->exp_own;
	}
	s->restore.exp_relogged = own;
	/* else where it began is not known: it begins again where the
	 * session is back (its logged commands replayed as controls) */
	s->restore.exp_after_catch_up = !same;
	srv_log(SRV_LOG_INFO, "session %s: experiment %s, which no checkpoint "
			      "carried, runs again from its first segment %s",
		s->entry.id, srv_exp_id(e), same ? "where it began" : "once the session is back");
}
