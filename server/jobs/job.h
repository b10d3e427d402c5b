/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * job.h - a kind of background job as data: sweeps, fits and experiments
 * are each one const descriptor (sweep.c, fitjob.c, experiment_http.c)
 * plus their own logic, the way each integrator is one descriptor. One
 * set of handlers serves them all (job.c): GET and POST /api/v1/{kind},
 * GET and DELETE /api/v1/{kind}/{id}, one list writer with the peers'
 * merge, one restore from the data directory ({kind}/ID.bin) and one
 * clean-up of a deleted job's files. docs/jobs.md has a new kind's
 * checklist.
 *
 * A job embeds a srv_entry (registry.h) and lives in its kind's registry;
 * the hooks below receive that entry. text, view and cancel run under the
 * job's own lock (the lock hook's) when it has one; no hook is called with
 * a registry lock held, except evictable (registry.h's lock order).
 */
#ifndef CONVSIM_JOB_H
#define CONVSIM_JOB_H

#include <pthread.h>
#include <stddef.h>
#include <stdint.h>

#include "registry.h"
#include "reply.h"

typedef struct srv_job_kind {
	const char *name;      /* "sweep": the word in its problems and logs */
	const char *plural;    /* "sweeps": /api/v1/{plural}, the listing's
				  member, the data directory's sub-directory,
				  the 429's budget */
	srv_registry *reg;     /* where its jobs live (capped) */
	int created_status;    /* POST's status: 202 (queued) or 201 */
	const char *limit;     /* the 429's detail after "N sweeps are" (the
				  registry's cap, name or plural, is or are) */
	uint32_t store_kind;   /* framed files {plural}/ID.bin (store.h) */
	const char *result_file; /* "sweep-%s.csv": a result beside them, or NULL */
	int restore_evicts;    /* a restore may evict (evictable) to make room */

	/* A new job for a request body: parsed, with what it reserves (a
	 * sweep's points); NULL with *pb. */
	srv_entry *(*create)(const char *body, size_t len, api_problem *pb);
	/* A created job that was never published: what create reserved goes
	 * back and it is freed. */
	void (*discard)(srv_entry *e);
	/* Start a published job (the caller holds a reference): API_OK with
	 * its first answer in *answer (JSON, malloc'd; NULL when out of
	 * memory), or the error in *pb, and the job is removed. client_fd:
	 * the requesting client's socket (borrowed; -1: unknown), for a start
	 * that settles a session to see whether its client left. */
	api_err (*start)(srv_entry *e, int client_fd, char **answer, api_problem *pb);
	/* 1 when the registry may push it out (over); registry lock held. */
	int (*evictable)(srv_entry *e);
	/* The job's own lock, which job.c holds around text, view and
	 * cancel; NULL: those hooks take what they need themselves. */
	pthread_mutex_t *(*lock)(srv_entry *e);
	/* One job as JSON or CSV (malloc'd), from a consistent state. */
	char *(*text)(srv_entry *e, int csv);
	/* A listing: view copies one job into view (view_size bytes, zeroed)
	 * with room in scratch (scratch_size bytes) for what the view points
	 * to; list_text writes n views as JSON or CSV (malloc'd). */
	size_t view_size, scratch_size;
	void (*view)(srv_entry *e, void *view, void *scratch);
	char *(*list_text)(const void *views, size_t n, int csv);
	/* DELETE: stop a job before it is unlinked, and 1; 0, nothing done,
	 * when only_running and it has ended (?only=running); NULL: no
	 * DELETE route. Under its lock: no end comes between the look and
	 * the stop. */
	int (*cancel)(srv_entry *e, int only_running);
	/* Restore: a job from the payload of {plural}/ID.bin (taken), not
	 * yet in the registry, or NULL with the reason in why. */
	srv_entry *(*load)(void *payload, size_t len, char *why, size_t whylen);
	/* Restore: a job whose record is unusable, listed in state "damaged"
	 * with why (as a damaged session is; what can still be served of it,
	 * a stored result, is), or NULL when out of memory; NULL hook: such
	 * a record is only logged. */
	srv_entry *(*damaged)(const char *id, const char *why);
	/* After a restored job is published: queue what was pending. NULL:
	 * nothing to do. */
	void (*resume)(srv_entry *e);
} srv_job_kind;

extern const srv_job_kind srv_sweep_job, srv_fit_job, srv_experiment_job;

/* Open kind's registry with room for cap jobs; close: drop every job
 * (the daemon stops, nothing runs them any more). */
void srv_job_open(const srv_job_kind *kind, size_t cap);
void srv_job_close(const srv_job_kind *kind);
/* Every job of kind found in {plural}/ (*.bin), published and resumed;
 * the others are logged. Returns the count. */
size_t srv_job_restore(const srv_job_kind *kind);
/* Frame payload (borrowed) as kind's store_kind and queue its write to
 * {plural}/ID.bin with done(arg) (store.h). Returns 0 when queued (done
 * will be called), -1 when not (store off, out of memory). */
int srv_job_save(const srv_job_kind *kind, const char *id, const void *payload, size_t len,
		  void (*done)(void *arg, int err, const char *what), void *arg);
/* The same written now, on this thread (srv_store_write_now): a job's
 * record at its creation, under its lock, before its answer. 0 (also
 * without a data directory), or the errno with the sentence in msg. */
int srv_job_save_now(const srv_job_kind *kind, const char *id, const void *payload, size_t len,
		     char *msg, size_t msglen);

/* The job's own lock (the kind's lock hook), where its kind has one, as
 * text, view and cancel are called under it; nothing where it has none. */
void srv_job_lock(const srv_job_kind *kind, srv_entry *e);
void srv_job_unlock(const srv_job_kind *kind, srv_entry *e);

/* The handlers; r->job names the kind (the route table's). */
enum MHD_Result srv_h_job_create(srv_req *r);
enum MHD_Result srv_h_job_list(srv_req *r);
enum MHD_Result srv_h_job_get(srv_req *r);
enum MHD_Result srv_h_job_delete(srv_req *r);

#endif
