/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * job.c - the one path every kind of job takes (job.h): the handlers of
 * /api/v1/{kind} and /api/v1/{kind}/{id}, the listing with the peers'
 * merge, the restore of {kind}/ID.bin and the files a deleted job leaves.
 * What differs between kinds is in their descriptors' hooks.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "job.h"
#include "peers.h"
#include "store.h"
#include "util.h"

void srv_job_open(const srv_job_kind *kind, size_t cap)
{
	srv_registry_open(kind->reg, cap);
}

void srv_job_close(const srv_job_kind *kind)
{
	srv_registry_clear(kind->reg);
}

int srv_job_save(const srv_job_kind *kind, const char *id, const void *payload, size_t len,
		 void (*done)(void *arg, int err, const char *what), void *arg)
{
	if (!srv_store_enabled())
		return -1;
	size_t framed;
	void *buf = srv_store_frame(kind->store_kind, payload, len, &framed);
	if (!buf)
		return -1;
	char path[64];
	snprintf(path, sizeof path, "%s/%s.bin", kind->plural, id);
	srv_store_write(path, buf, framed, 0, done, arg);
	return 0;
}

int srv_job_save_now(const srv_job_kind *kind, const char *id, const void *payload, size_t len,
		     char *msg, size_t msglen)
{
	if (!srv_store_enabled())
		return 0;
	size_t framed;
	void *buf = srv_store_frame(kind->store_kind, payload, len, &framed);
	char path[64];
	snprintf(path, sizeof path, "%s/%s.bin", kind->plural, id);
	if (!buf) {
		snprintf(msg, msglen, "cannot write %s: out of memory", path);
		return ENOMEM;
	}
	int err = srv_store_write_now(path, buf, framed, msg, msglen);
	free(buf);
	return err;
}

/* One file of {plural}/: 1 when its job is back. */
static size_t restore_one(const srv_job_kind *kind, const char *name)
{
	char path[300], why[300];
	snprintf(path, sizeof path, "%s/%s", kind->plural, name);
	size_t len = 0;
	int older = 0;
	void *payload = srv_store_read(path, kind->store_kind, &len, &older, why, sizeof why);
	/* an earlier format, upgraded as it was read: written back in this
	 * build's once its job loads (atomically: store.c) */
	void *again = older && payload ? malloc(len ? len : 1) : NULL;
	if (again)
		memcpy(again, payload, len);
	srv_entry *e = NULL;
	if (payload) {
		char reason[200];
		e = kind->load(payload, len, reason, sizeof reason);
		if (!e)
			snprintf(why, sizeof why, "%.90s: %.190s", path, reason);
	}
	int damaged = !e;
	if (!damaged && again) {
		char id[64];
		snprintf(id, sizeof id, "%.*s", (int)(strlen(name) - 4), name);
		if (srv_job_save(kind, id, again, len, NULL, NULL) == 0) {
			srv_store_count_upgraded(kind->store_kind);
			srv_log(SRV_LOG_INFO, "%s %s: read from an earlier format, written again "
					      "in format %d", kind->name, id, SRV_STORE_VERSION);
		}
	}
	free(again);
	if (damaged) {
		srv_store_count_damaged(kind->store_kind);
		srv_log(SRV_LOG_WARN, "%s not restored: %s", kind->name, why);
		if (!kind->damaged)
			return 0;
		/* listed as damaged under its id (the name less ".bin") */
		char id[64];
		snprintf(id, sizeof id, "%.*s", (int)(strlen(name) - 4), name);
		e = kind->damaged(id, why);
		if (!e)
			return 0;
	}
	if (srv_registry_reserve(kind->reg, e,
				 kind->restore_evicts && !damaged ? kind->evictable : NULL)) {
		kind->reg->destroy(e);
		return 0;
	}
	srv_registry_publish(kind->reg, e);
	if (kind->resume && !damaged)
		kind->resume(e);
	srv_registry_put(kind->reg, e);
	return 1;
}

size_t srv_job_restore(const srv_job_kind *kind)
{
	char **names = NULL;
	size_t n = srv_store_enabled() ? srv_store_list_ids(kind->plural, 0, &names) : 0,
	       count = 0;
	for (size_t i = 0; i < n; i++) {
		size_t l = strlen(names[i]);
		if (l > 4 && strcmp(names[i] + l - 4, ".bin") == 0)
			count += restore_one(kind, names[i]);
		free(names[i]);
	}
	free(names);
	return count;
}

/* A deleted job's files: its record and its result. */
static void forget(const srv_job_kind *kind, const char *id)
{
	if (!srv_store_enabled())
		return;
	char path[64];
	snprintf(path, sizeof path, "%s/%s.bin", kind->plural, id);
	srv_store_remove(path);
	if (kind->result_file) {
		char name[64];
		snprintf(name, sizeof name, kind->result_file, id);
		srv_store_remove(name);
	}
}

/* The job's lock around a hook, when its kind has one. */
void srv_job_lock(const srv_job_kind *kind, srv_entry *e)
{
	if (kind->lock)
		pthread_mutex_lock(kind->lock(e));
}

void srv_job_unlock(const srv_job_kind *kind, srv_entry *e)
{
	if (kind->lock)
		pthread_mutex_unlock(kind->lock(e));
}

static enum MHD_Result not_found(srv_req *r)
{
	return srv_reply_not_found(r, r->job->name);
}

/* A job's place is reserved before its start, which may still refuse it
 * (an experiment's session: 404, 422, 503); an old finished job that
 * makes room is only claimed then, and removed once the start is certain,
 * so that a refusal changes nothing. */
enum MHD_Result srv_h_job_create(srv_req *r)
{
	const srv_job_kind *kind = r->job;
	api_problem pb;
	srv_entry *e = kind->create(r->body, r->body_len, &pb), *victim;
	if (!e)
		return srv_reply_problem(r, &pb, NULL);
	if (srv_registry_reserve_claim(kind->reg, e, kind->evictable, &victim)) {
		kind->discard(e);
		double cap = (double)kind->reg->cap;
		api_fail(&pb, API_LIMIT, NULL, "%zu %s %s %s", kind->reg->cap,
			 api_plural(cap, kind->name, kind->plural), api_plural(cap, "is", "are"),
			 kind->limit);
		api_budget(&pb, kind->plural, (double)kind->reg->cap, 1);
		return srv_reply_problem(r, &pb, NULL);
	}
	srv_registry_publish(kind->reg, e);
	char *text = NULL;
	if (kind->start(e, srv_client_fd(r), &text, &pb) != API_OK) {
		if (srv_registry_withdraw(kind->reg, e, victim))
			forget(kind, e->id);
		srv_registry_put(kind->reg, e);
		return srv_reply_problem(r, &pb, NULL);
	}
	srv_registry_evict_claim(kind->reg, victim);
	char prefix[48];
	snprintf(prefix, sizeof prefix, "/api/v1/%s", kind->plural);
	enum MHD_Result res = srv_reply_created(r, kind->created_status, text, prefix, e->id);
	srv_registry_put(kind->reg, e);
	return res;
}

enum MHD_Result srv_h_job_get(srv_req *r)
{
	srv_entry *e = srv_registry_get(r->job->reg, r->arg[0]);
	if (!e)
		return not_found(r);
	srv_job_lock(r->job, e);
	char *text = r->job->text(e, r->csv);
	srv_job_unlock(r->job, e);
	srv_registry_put(r->job->reg, e);
	return srv_reply_result(r, text);
}

enum MHD_Result srv_h_job_list(srv_req *r)
{
	const srv_job_kind *kind = r->job;
	srv_entry **all = NULL;
	size_t n = srv_registry_snapshot(kind->reg, &all);
	char *views = calloc(n + 1, kind->view_size);
	char *scratch = calloc(n + 1, kind->scratch_size ? kind->scratch_size : 1);
	char *text = NULL;
	if (views && scratch) {
		for (size_t i = 0; i < n; i++) {
			srv_job_lock(kind, all[i]);
			kind->view(all[i], views + i * kind->view_size,
				   scratch + i * kind->scratch_size);
			srv_job_unlock(kind, all[i]);
		}
		text = kind->list_text(views, n, r->csv);
	}
	srv_registry_release(kind->reg, all, n);
	free(views);
	free(scratch);
	return srv_peers_reply(r, text, kind->plural);
}

enum MHD_Result srv_h_job_delete(srv_req *r)
{
	const srv_job_kind *kind = r->job;
	srv_entry *e = srv_registry_get(kind->reg, r->arg[0]);
	if (!e)
		return not_found(r);
	/* a record that cannot be removed (a read-only data directory) is
	 * said, not answered 204 for files that stay; nothing is changed */
	char rec[64];
	api_problem pb;
	snprintf(rec, sizeof rec, "%s/%s.bin", kind->plural, e->id);
	if (srv_store_check_removable(rec, &pb) != API_OK) {
		srv_registry_put(kind->reg, e);
		return srv_reply_problem(r, &pb, NULL);
	}
	/* ?only=running: a job that has ended is kept and said (409) */
	const char *only = srv_query(r, "only");
	if (only && strcmp(only, "running") != 0) {
		srv_registry_put(kind->reg, e);
		return srv_fail(r, API_QUERY, "only", "only must be running, not \"%.40s\"", only);
	}
	srv_job_lock(kind, e);
	int stopped = kind->cancel(e, only != NULL);
	srv_job_unlock(kind, e);
	if (!stopped) {
		srv_registry_put(kind->reg, e);
		return srv_fail(r, API_CONFLICT, "only", "the %s has ended already; nothing was "
				"stopped or deleted (only=running)", kind->name);
	}
	int removed = srv_registry_remove(kind->reg, e);
	if (removed)
		forget(kind, e->id);
	srv_registry_put(kind->reg, e);
	return srv_reply_deleted(r, removed, kind->name);
}
