/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment.h - the beta-schedule experiment as the worker runs it.
 *
 * An experiment rides on one session's worker, which calls the hooks below
 * with the session lock held; they take the experiment's own lock inside
 * it, as the lock order (registry.h) allows. The experiment never touches the
 * simulation: each segment's beta is a command (srv_cmd, cmd.h) it hands
 * back to the worker, which queues and applies it like a PATCH and reports
 * the outcome with srv_exp_commanded. The handlers and the registry of
 * experiments are in experiment_http.c.
 */
#ifndef CONVSIM_EXPERIMENT_H
#define CONVSIM_EXPERIMENT_H

#include "api.h"
#include "registry.h"
#include "cmd.h"

typedef struct srv_experiment srv_experiment;

/* A new experiment for the parsed request and its kind (both copied; ext
 * NULL: a plain schedule), saving its results under data_dir (borrowed;
 * NULL: not saved). NULL with *pb (503) when out of memory. Free with
 * srv_exp_free (NULL accepted). */
srv_experiment *srv_exp_new(const api_experiment_req *req, const api_exp_ext *ext,
			    const char *data_dir, api_problem *pb);
/* An identification or a closed loop measures what it needs on spec (its
 * session's scene) before it starts (experiment_cost.c, experiment_kind.c),
 * holding a --max-settling slot meanwhile: API_OK, or the problem (those
 * measurements, and a fresh session's settling after them, estimated
 * beyond --max-cpu-seconds: 422 budget "cpu", nothing measured; a setpoint out of the machine's reach: 422; 503
 * budget "settling" when every slot is taken, nothing measured). A plain
 * schedule: API_OK at once. */
api_err srv_exp_ready(srv_experiment *e, const api_spec *spec, api_problem *pb);
void srv_exp_free(srv_experiment *e);
/* Its registry entry (the id), and back. */
srv_entry *srv_exp_entry(srv_experiment *e);
srv_experiment *srv_exp_from_entry(srv_entry *en);
const char *srv_exp_id(const srv_experiment *e);
/* Its request as parsed (borrowed; its schedule's results change while it
 * runs: read it before it starts). */
const api_experiment_req *srv_exp_request(const srv_experiment *e);
/* CPU s its request's thread spent on its measurements (srv_exp_ready; 0
 * without any): what a fresh session's settling has less of
 * --max-cpu-seconds in the same request. */
double srv_exp_measured_cpu(const srv_experiment *e);
/* 1 when its session stays after the end (it was not created by the
 * experiment, or keep_session was asked). */
int srv_exp_keeps_session(const srv_experiment *e);
/* Note the session it runs on. */
void srv_exp_set_session(srv_experiment *e, const char *session_id);
/* Note the scene of an existing session it is attached to (copied): each
 * segment's model error is the scene's at the segment's beta. */
void srv_exp_set_spec(srv_experiment *e, const api_spec *spec);
/* 1 when it is over and no worker refers to it (it may be evicted). */
int srv_exp_finished(srv_experiment *e);
/* Room for a view's copies. */
typedef struct srv_exp_scratch {
	api_segment seg[API_EXP_MAX_SEGMENTS];
	api_exp_ext ext;
} srv_exp_scratch;
/* A consistent copy of its state: *v, with v->seg and v->ext pointing into
 * sc (filled here). */
void srv_exp_view(srv_experiment *e, api_experiment_view *v, srv_exp_scratch *sc);

/* ---- worker hooks (session lock held) ---------------------------------- */

/* Begin at status st: the first segment starts. *t_end (s) is the
 * simulated time the session must run to. Returns the segment's command
 * (owned by e) for the worker to queue. */
srv_cmd *srv_exp_begin(srv_experiment *e, const sim_status *st,
		       double *t_end);
/* The simulated time (s) a running experiment ends at, its last segment's
 * end; NAN before it begins and once it is over. */
double srv_exp_end(const srv_experiment *e);
/* The next segment boundary (s), where an advance must stop, or INFINITY. */
double srv_exp_boundary(const srv_experiment *e);
/* After each advance: record, close a segment that ended and start the
 * next. Returns the new segment's command (owned by e) or NULL; *over is
 * set to 1 when the experiment is done (the worker detaches it). */
srv_cmd *srv_exp_step(srv_experiment *e, const sim_status *st, int *over);
/* The worker applied (or refused) e's command. Returns 1 when a refusal
 * aborted the experiment (the worker detaches it). */
int srv_exp_commanded(srv_experiment *e, const srv_cmd *cmd);
/* DELETE of e: 1 with the id of the session it runs on in sid (the
 * caller lets it go there, srv_session_detach), else 0 (over, or not yet
 * on a session: then srv_exp_deleted says so to its start); -1, nothing
 * done, when only_running and e has ended (done, aborted, interrupted). */
int srv_exp_cancel(srv_experiment *e, int only_running, char *sid, size_t sidlen);
/* 1 once a DELETE of e came. */
int srv_exp_deleted(srv_experiment *e);
/* The session ended before the experiment (deleted, failed, shutdown). */
void srv_exp_abort(srv_experiment *e, const char *why);

/* ---- persistence (store.h) ---------------------------------------------- */

/* Write experiments/ID.bin now, on this thread (at creation, before the
 * answer; the end queues it by itself). */
void srv_exp_persist(srv_experiment *e);
/* The running state (record and feed-velocity record) for the session's
 * checkpoint: malloc'd, its length in *len; NULL when out of memory.
 * Session lock held (the experiment's is taken inside). */
void *srv_exp_save(srv_experiment *e, size_t *len);
/* Continue from a running state srv_exp_save wrote: attached again. 0, or
 * -1 when buf does not pass its checks (nothing changed). */
int srv_exp_resume(srv_experiment *e, const void *buf, size_t len);
/* An experiment from the payload of experiments/ID.bin (taken) as it was
 * last written, not attached; NULL with the reason in why when it does not
 * pass its checks. */
srv_experiment *srv_exp_load(void *payload, size_t len, char *why, size_t whylen);
/* An experiment whose record (experiments/ID.bin) cannot be read back:
 * listed in state "damaged" with why and no segments, as a damaged
 * session is; a session checkpoint that carries its progress still
 * resumes it (srv_exp_resume). NULL when out of memory. */
srv_experiment *srv_exp_damaged(const char *id, const char *why);
/* Still running but no session resumed it nor took it again
 * (srv_exp_readopt): "interrupted", its finished segments kept. Returns
 * 1 if it was. */
int srv_exp_interrupt(srv_experiment *e);
/* Running or waiting when the daemon died, on session session_id, but no
 * checkpoint of it carried the experiment (it began after the last one,
 * or the session had none yet): attached again from its first segment,
 * every result cleared, to begin when its session's worker next starts a
 * job (srv_session's restore decides when). 1 if it was; 0 (nothing
 * changed) when e is not such an experiment or out of memory. */
int srv_exp_readopt(srv_experiment *e, const char *session_id);
/* A result or record could not be written: state "error" with what. */
void srv_exp_write_failed(srv_experiment *e, const char *what);

#endif
