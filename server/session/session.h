/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session.h - simulation sessions: one sim instance each, stepped by its
 * own worker thread (worker.c), kept in a registry by id.
 *
 * Handlers never call the core: they create, look up and delete sessions,
 * send controls through the worker's command queue and read what the
 * worker publishes under the session lock (views, the record ring, the
 * trajectory history). The session lock stays inside session.c and
 * worker.c: streams read through the snapshot readers below. Lock order:
 * see registry.h.
 */
#ifndef CONVSIM_SESSION_H
#define CONVSIM_SESSION_H

#include <stddef.h>
#include <stdint.h>

#include "api.h"
#include "budget.h"
#include "config.h"

typedef struct srv_session srv_session;
typedef struct srv_experiment srv_experiment;

enum { SRV_RUNNING, SRV_PAUSED, SRV_FINISHED, SRV_FAILED };

/* Start with an empty registry; cfg (borrowed for the daemon's life) gives
 * --max-sessions, --ring and --history. */
void srv_sessions_init(const srv_config *cfg);
/* Stop every worker, end every stream, free all sessions. */
void srv_sessions_shutdown(void);

/* Create a session from spec (copied) and start its worker, with exp
 * (may be NULL; borrowed, must outlive the attachment) attached before
 * the first step. Its instance is built, settled and probed in the
 * calling thread, holding a --max-settling slot (not a LIGGGHTS
 * session's: --max-dem-sessions bounds those), within --max-cpu-seconds
 * of that thread's CPU less before, the CPU s it spent on the request
 * before (an experiment's measurements; 0: none). client_fd: -1, or the
 * creating client's socket (borrowed): a LIGGGHTS bed's settling is
 * cancelled when the client leaves before it ends, and any creation whose
 * client has left once settled and probed (srv_peer_gone) is discarded
 * before its spec is written (503, nothing kept, counted in
 * convsim_sessions_abandoned_total). Returns a new reference or NULL with
 * *pb set (429 at --max-sessions, 422 when the core refuses the spec, 503:
 * budget "memory", "cpu" or "settling"). */
srv_session *srv_session_create(const api_spec *spec, srv_experiment *exp, int client_fd,
				double before, api_problem *pb);
/* Look up by id; returns a new reference or NULL. */
srv_session *srv_session_get(const char *id);
/* Drop a reference; the last one stops the worker and frees the session.
 * NULL is accepted. */
void srv_session_put(srv_session *s);
/* Remove from the registry, stop the worker, end the streams, remove its
 * files. The caller holds a reference (and still puts it). 1, or 0 when
 * another call removed it first (a concurrent DELETE: nothing done). */
int srv_session_delete(srv_session *s);
/* API_OK if its files could be removed now (store.c
 * srv_store_check_removable); else 503 in *pb. */
api_err srv_session_check_removable(const srv_session *s, api_problem *pb);
/* Delete the sessions whose experiment ended (created by it, not kept)
 * and, with idle_timeout > 0 (s), those with no stream client, no
 * experiment and no request for that long. Returns how many. */
size_t srv_sessions_reap(double idle_timeout);
/* The experiments' registry as the restore sees it (passed in, so that
 * sessions do not depend on it): find, a new reference by id, or NULL,
 * and put to give it back; readopt, the experiment whose record says it
 * ran on session_id and that no checkpoint resumed, attached again
 * (srv_exp_readopt), or NULL. */
typedef struct srv_exp_finder {
	srv_experiment *(*find)(const char *id);
	void (*put)(srv_experiment *e);
	srv_experiment *(*readopt)(const char *session_id);
} srv_exp_finder;
/* Rebuild the sessions of the data directory (session_load.c); the
 * experiments must be restored first: ef gives the running ones back to
 * their sessions. Returns how many. */
size_t srv_sessions_restore(const srv_exp_finder *ef);
const char *srv_session_id(const srv_session *s);
/* Its spec (immutable; borrowed while the reference is held). */
const api_spec *srv_session_spec(const srv_session *s);
/* Fill a view (spec borrowed from s: keep the reference while using it). */
void srv_session_view(srv_session *s, api_view *v);
/* API_OK, or 503 in *pb with Retry-After while s, restored at a start,
 * runs flat out through the controls of its log to where it was: until
 * then its status would show a past the clients had already left
 * (docs/durability.md). GET, PATCH, its trajectory and streams and an
 * experiment's attach answer this; the listing shows its status null. */
api_err srv_session_replaying(srv_session *s, api_problem *pb);
/* Live sessions. */
size_t srv_session_count(void);
/* Every live session, newest first, as new references in *out (malloc'd;
 * give it back with srv_sessions_release). Returns the count. */
size_t srv_sessions_all(srv_session ***out);
void srv_sessions_release(srv_session **all, size_t n);
/* Sum of achieved steps/s of running sessions. */
double srv_sessions_steps_per_s(void);

/* Apply a control through the worker; waits up to timeout_s for the
 * acknowledgement. Returns API_OK (acked, *t_eff set, *c as applied: with
 * the end the worker gave a session of pace "max" that has none, as its
 * until), API_NOTFOUND (being
 * deleted), API_CONFLICT (the session cannot take it), the core's refusal,
 * or API_UNAVAILABLE (not acknowledged; nothing changed), with *pb set. */
api_err srv_session_control(srv_session *s, api_control *c,
			    double timeout_s, double *t_eff, api_problem *pb);
/* Let go of experiment e if s runs it (DELETE of e): e aborted with why,
 * its queued command taken back, s's controls the client's again and s
 * running on to the until e gave it. 1 when s was created by e and not
 * kept (the caller deletes it, as the reaper would at e's end), else 0. */
int srv_session_detach(srv_session *s, srv_experiment *e, const char *why);
/* Attach an experiment (borrowed until it detaches) to a running
 * session's worker. API_CONFLICT if it already runs one or has failed;
 * a finished paced session, which the experiment runs on, first takes its
 * hold of the cores for paced sessions: API_UNAVAILABLE (budget "cpu")
 * when they are taken, and nothing is attached. */
api_err srv_session_attach(srv_session *s, srv_experiment *e,
			   api_problem *pb);

/* ---- snapshot readers (streams, trajectory) ---------------------------- */

/* What a reader sees of the record ring at one moment. */
typedef struct srv_ring_read {
	uint64_t head;        /* next index to be written */
	uint64_t oldest;      /* oldest index still held */
	int state;            /* SRV_RUNNING ... */
	int removed;          /* the session is being deleted */
	double t;             /* s: the latest simulated time */
	uint64_t next;        /* srv_session_read: the record copied, or
				 head when none was */
} srv_ring_read;

/* The ring's bounds and state now. */
srv_ring_read srv_session_ring(srv_session *s);
/* One consistent look: the bounds and state in *rd and the first record
 * from max(cursor, oldest) on that is an event or a sample at or after
 * from_t (s; -INFINITY: every sample), copied into dst (arrays sized by
 * srv_sample_alloc for this session's feed) with its index in rd->next;
 * rd->next = head when there is none (the samples passed over are not
 * copied). */
void srv_session_read(srv_session *s, uint64_t cursor, double from_t,
		      api_sample *dst, srv_ring_read *rd);
/* Wait up to seconds for a record newer than *rd that a reader wanting
 * samples from from_t on would take (an event, such a sample), a state
 * change or the deletion. The worker wakes waiting readers once per batch
 * of steps, and only when such a record exists. */
void srv_session_wait(srv_session *s, const srv_ring_read *rd, double from_t,
		      double seconds);
/* Count a stream client in, its charge (srv_budget_stream_charge; linked
 * into the session's, so it lives until the close) held with the
 * session's own in the cores for paced sessions while it runs paced (and
 * from when it runs paced again): API_OK, or 503 (budget "cpu") with
 * nothing counted nor held. */
api_err srv_session_stream_open(srv_session *s, srv_stream_charge *c, api_problem *pb);
/* Count it out and give its charge back. */
void srv_session_stream_close(srv_session *s, srv_stream_charge *c);
/* The feed size of this session's records (0 without feed). */
void srv_session_feed_size(const srv_session *s, int *columns, int *layers);
/* Allocate / free the arrays of a record for a feed size. 0 or -1. */
int srv_sample_alloc(api_sample *rec, int columns, int layers);
void srv_sample_free(api_sample *rec);
/* Trajectory rows in [from, to] (s): malloc'd copy into *rows (caller
 * frees; NULL when out of memory), count returned, stride in *stride. */
size_t srv_session_history(srv_session *s, double from, double to,
			   double **rows, double *stride);

#endif
