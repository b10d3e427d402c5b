/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_load.c - a session's files in the data directory read back at a
 * restart (session_store.c writes them; docs/operations.md "Persistence").
 * A restore never fails the daemon: a checkpoint that does not pass its
 * checks falls back to the previous one; a session whose spec or both
 * checkpoints are unusable is listed as "damaged" with the reason; a
 * session with a spec and no checkpoint yet starts again from its spec.
 * Last the restored sessions' workers are started, once all are in.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "records.h"
#include "session_int.h"
#include "store.h"
#include "util.h"

/* sessions/ID/spec.bin (records.h) */
typedef srv_spec_record spec_record;

/* ---- restore ------------------------------------------------------------ */

int srv_ckpt_decode(const char *p, size_t len, srv_ckpt_record *r, char *why,
		    size_t whylen)
{
	if (len < sizeof *r) {
		snprintf(why, whylen, "cut off");
		return -1;
	}
	memcpy(r, p, sizeof *r);
	/* exp_len first: a length between len - sizeof *r and len wrapped
	 * the difference below and let sim_len point past the buffer; the
	 * core's checkpoint ends the payload or is followed by the trailer */
	size_t left = r->exp_len <= len - sizeof *r ? len - sizeof *r - (size_t)r->exp_len : 0;
	if (r->exp_len > len - sizeof *r ||
	    (r->sim_len != left && !(left >= SRV_CKPT_TRAILER && r->sim_len == left - SRV_CKPT_TRAILER)) ||
	    r->state < SRV_RUNNING || r->state > SRV_FAILED) {
		snprintf(why, whylen, "inconsistent lengths or state");
		return -1;
	}
	r->error[sizeof r->error - 1] = '\0';
	r->exp_id[SRV_ID_LEN - 1] = '\0';
	return 0;
}

/* The checkpoint of s from file (relative): restores s->sim, run state and
 * the experiment (found with find, given back with put), and *logged, the
 * bytes of the control log it holds; 0, or -1 with why and *unread set
 * when the file could not be read at all (missing). */
static int load_checkpoint(srv_session *s, const char *file, const srv_exp_finder *ef,
			   size_t *logged, int *unread, char *why, size_t whylen)
{
	size_t n = 0, len;
	char *raw = srv_store_read_text(file, &n);
	const char *bad = "missing or unreadable";
	int older = 0;
	char *p = raw ? srv_store_unframe(raw, n, SRV_STORE_CHECKPOINT, &len, &older, &bad) : NULL;
	*unread = !raw;
	if (older)
		s->restore.upgrade = 1; /* written again in this build's format */
	if (!p) {
		snprintf(why, whylen, "%s: %s", file, bad);
		return -1;
	}
	srv_ckpt_record r;
	int rc = -1;
	char msg[256] = "";
	if (srv_ckpt_decode(p, len, &r, msg, sizeof msg) != 0) {
		snprintf(why, whylen, "%s: %s", file, msg);
		goto done;
	}
	*logged = SIZE_MAX; /* a checkpoint without the trailer: unknown */
	srv_ckpt_trailer tr = {.t = NAN, .cpu_seconds = NAN};
	if (len == sizeof r + r.exp_len + r.sim_len + SRV_CKPT_TRAILER) {
		memcpy(&tr, p + len - sizeof tr, sizeof tr);
		*logged = tr.logged <= SIZE_MAX ? (size_t)tr.logged : SIZE_MAX;
		if (isfinite(tr.t) && tr.t > s->restore.catch_up_t)
			s->restore.catch_up_t = tr.t; /* where it was, if the core's
						 part is refused */
	}
	int err;
	sim *sm = sim_restore(&s->spec.params, &s->spec.scene, &s->spec.method,
			      p + sizeof r + r.exp_len, r.sim_len, &err, msg,
			      sizeof msg);
	if (!sm) {
		snprintf(why, whylen, "%s: %s", file, msg);
		goto done;
	}
	s->restore.catch_up_t = 0;
	sim_free(s->sim);
	s->sim = sm;
	s->state = r.state;
	/* its CPU budget (format 3 on): srv_restore_budget */
	int kept = isfinite(tr.cpu_seconds) && tr.cpu_seconds >= 0 && isfinite(tr.cpu_limit);
	s->restore.cpu_seconds = kept ? tr.cpu_seconds : NAN;
	s->restore.cpu_limit = kept ? tr.cpu_limit : NAN;
	s->restore.cpu_paused = kept && tr.cpu_paused;
	s->pace = r.pace;
	s->until = r.until;
	snprintf(s->error, sizeof s->error, "%s", r.error);
	if (r.exp_started && r.exp_len) {
		srv_experiment *e = ef->find(r.exp_id);
		if (e && srv_exp_resume(e, p + sizeof r, r.exp_len) == 0) {
			s->exp = e;
			s->exp_started = 1;
		}
		if (e)
			ef->put(e); /* the registry keeps it */
	}
	rc = 0;
done:
	free(p);
	return rc;
}

/* What a request may ask and a stored spec cannot hold: feed_model auto
 * is resolved at creation (srv_dem_pick) and the model picked is the one
 * stored. 0, or -1 with why. */
static int stored_spec_check(const api_spec *spec, char *why, size_t whylen)
{
	if (spec->scene.feed_model != SIM_FEED_AUTO)
		return 0;
	snprintf(why, whylen, "feed_model auto, which a session resolves at its creation "
			      "(a stored spec holds column or liggghts)");
	return -1;
}

int srv_spec_decode(const void *p, size_t len, api_spec *spec, double *created,
		    int *owned, char *why, size_t whylen)
{
	spec_record r;
	if (len != sizeof r) {
		snprintf(why, whylen, "of another size");
		return -1;
	}
	memcpy(&r, p, sizeof r);
	api_problem pb;
	if (api_check_spec(&r.spec, &pb) != API_OK) {
		/* the reason cut to the caller's room, as snprintf would */
		snprintf(why, whylen, "%.*s", whylen > 0 ? (int)(whylen - 1) : 0, pb.detail);
		return -1;
	}
	if (stored_spec_check(&r.spec, why, whylen) != 0)
		return -1;
	*spec = r.spec;
	*created = r.created;
	*owned = r.owned != 0;
	return 0;
}

/* A checkpoint that did not keep its CPU budget (format 2, or none): the
 * budget of the controls it holds (the log's first `held` bytes), which
 * nothing replays: the last cpu_budget, unless a running: true came after
 * it (a resume of a session its budget paused grants --max-cpu-seconds),
 * and whether a paused session was paused by its budget (its client's
 * last running was not false). Applied by srv_restore_budget. */
static void held_budget(srv_session *s, const char *text, size_t held)
{
	if (isfinite(s->restore.cpu_seconds))
		return; /* the checkpoint kept it */
	int running = 1;
	for (size_t at = 0; at < held;) {
		const char *nl = memchr(text + at, '\n', held - at);
		size_t n = nl ? (size_t)(nl - (text + at)) : held - at;
		api_control c;
		api_problem pb;
		double t;
		if (n && api_parse_control_event(text + at, n, &s->spec, &c, &t, NULL, 0,
						 &pb) == API_OK) {
			if (c.set & API_C_CPU)
				s->restore.cpu_grant = c.cpu_budget;
			if (c.set & API_C_RUNNING) {
				running = c.running;
				if (c.running)
					s->restore.cpu_grant = 0;
			}
		}
		at += n + 1;
	}
	s->restore.cpu_paused = s->state == SRV_PAUSED && running;
}

/* The control log back into s->controls (later controls are appended to
 * it), and the controls logged after its first `logged` bytes (what the
 * checkpoint restored holds; 0 without one; SIZE_MAX: a checkpoint that
 * does not say) into s->restore.replay, for the worker to apply again. */
static void load_controls(srv_session *s, size_t logged)
{
	char path[128];
	srv_session_file(path, sizeof path, s->entry.id, "controls.ndjson");
	size_t len = 0;
	char *text = srv_store_read_text(path, &len);
	if (!text)
		return;
	/* a line a crash cut short was never acknowledged: the log ends at
	 * its last newline (the file is cut there when it is next written) */
	while (len > 0 && text[len - 1] != '\n')
		len--;
	s->controls = text;
	s->controls_len = s->log.synced = len;
	s->controls_cap = len + 1;
	held_budget(s, text, logged < len ? logged : len);
	if (logged >= len)
		return;
	size_t lines = 0;
	for (size_t i = logged; i < len; i++)
		lines += text[i] == '\n';
	s->restore.replay = calloc(lines ? lines : 1, sizeof *s->restore.replay);
	for (size_t at = logged; s->restore.replay && at < len;) {
		const char *nl = memchr(text + at, '\n', len - at);
		size_t n = nl ? (size_t)(nl - (text + at)) : len - at;
		srv_replay *rp = &s->restore.replay[s->restore.nreplay];
		api_problem pb;
		char exp[SRV_ID_LEN];
		if (n && api_parse_control_event(text + at, n, &s->spec, &rp->cmd.c,
						 &rp->at, exp, sizeof exp, &pb) == API_OK) {
			/* the experiment resumed from the checkpoint sends its
			 * segments' commands again: applied twice, the second
			 * would move the estimator's restart */
			snprintf(rp->exp, sizeof rp->exp, "%s", exp);
			rp->exp_own = s->exp && exp[0] && strcmp(exp, srv_exp_id(s->exp)) == 0;
			s->restore.exp_relogged += rp->exp_own;
			s->restore.nreplay++;
		}
		else if (n)
			srv_log(SRV_LOG_WARN, "session %s: a line of %s not "
					      "replayed: %s", s->entry.id, path, pb.detail);
		at += n + 1;
	}
	if (s->restore.nreplay)
		srv_log(SRV_LOG_INFO, "session %s: %zu controls logged after "
				      "its checkpoint are replayed", s->entry.id,
			s->restore.nreplay);
}

/* The spec of s from spec.json (the API's JSON: this build on) or, when
 * there is none, spec.bin (earlier builds); 0, or -1 with why. */
static int load_spec(srv_session *s, char *why, size_t whylen)
{
	char path[128], msg[256];
	size_t len = 0;
	srv_session_file(path, sizeof path, s->entry.id, "spec.json");
	char *text = srv_store_read_text(path, &len);
	if (text) {
		api_problem pb;
		int format = 0;
		api_err e = api_parse_spec_file(text, len, &s->spec, &s->created,
						&s->owned, &format, &s->pick, &s->picked, &pb);
		free(text);
		if (e != API_OK)
			snprintf(why, whylen, "%s: %s", path, pb.detail);
		else if (stored_spec_check(&s->spec, msg, sizeof msg) != 0) {
			snprintf(why, whylen, "%s: %s", path, msg);
			e = API_INVALID;
		}
		if (e == API_OK && format < API_SPEC_FILE_FORMAT)
			s->restore.upgrade = 1;
		return e == API_OK ? 0 : -1;
	}
	/* no spec.json: a build before it (c793934) wrote only spec.bin */
	srv_session_file(path, sizeof path, s->entry.id, "spec.bin");
	int older = 0;
	void *r = srv_store_read(path, SRV_STORE_SESSION, &len, &older, why, whylen);
	int rc = r ? srv_spec_decode(r, len, &s->spec, &s->created, &s->owned,
				     msg, sizeof msg)
		   : -1;
	if (r && rc)
		snprintf(why, whylen, "%s: %s", path, msg);
	s->restore.upgrade = 1; /* spec.json (and spec.bin) in this build's format */
	free(r);
	return rc;
}

/* s restored at t0 with its log loaded: it runs flat out (and answers
 * 503 meanwhile: srv_session_replaying) to the later of where a refused
 * checkpoint said it was (rebuilt) and its last control's time, so that
 * no client sees it before the controls it acknowledged. */
static void catch_up(srv_session *s)
{
	for (size_t i = 0; i < s->restore.nreplay; i++)
		if (s->restore.replay[i].at > s->restore.catch_up_t)
			s->restore.catch_up_t = s->restore.replay[i].at;
	s->restore.replay_t0 = s->sim ? sim_effective_time(s->sim) : 0;
	if (!(s->restore.catch_up_t > s->restore.replay_t0))
		s->restore.catch_up_t = 0;
	s->restore.replay_wall = srv_now();
}

/* s was re-created from its spec because neither checkpoint could be used
 * (why, why2): its worker replays the whole control log and runs flat out
 * to where it was, the later of the time a checkpoint's trailer gave and
 * the last control's, then at its pace again (worker.c). */
static void rebuild(srv_session *s, const char *why, const char *why2)
{
	s->restore.rebuilt = 1;
	s->restore.replay_seconds = s->restore.catch_up_t > 0 ? NAN : 0; /* 0: nowhere to go */
	srv_log(SRV_LOG_WARN, "session %s: %.200s; %.200s; re-created from its "
			      "spec, %zu controls replayed to t = %g s",
		s->entry.id, why, why2, s->restore.nreplay, s->restore.catch_up_t);
}

/* The files of session id into s (srv_persist_load). */
static void load_files(srv_session *s, const char *id, const srv_exp_finder *ef)
{
	char path[128], why[512] = "", why2[512] = "";
	snprintf(s->entry.id, sizeof s->entry.id, "%s", id);
	s->restore.cpu_seconds = NAN; /* until a checkpoint says */
	s->created = srv_unix_time();
	s->spec.sample_rate = API_DEFAULT_SAMPLE_RATE;
	if (load_spec(s, why, sizeof why) != 0) {
		s->damaged = 1;
		snprintf(s->error, sizeof s->error, "damaged: %.240s", why);
		return;
	}
	s->pace = s->spec.pace;
	s->until = s->spec.until;
	s->state = SRV_RUNNING;
	srv_session_file(path, sizeof path, id, "checkpoint.bin");
	size_t logged = 0;
	int unread = 0, unread_prev = 0;
	if (load_checkpoint(s, path, ef, &logged, &unread, why, sizeof why) == 0) {
		load_controls(s, logged);
		catch_up(s);
		return;
	}
	char prev[160];
	snprintf(prev, sizeof prev, "%s.prev", path);
	if (load_checkpoint(s, prev, ef, &logged, &unread_prev, why2, sizeof why2) == 0) {
		srv_log(SRV_LOG_WARN, "session %s: %s; restored from the "
				      "previous checkpoint", id, why);
		load_controls(s, logged);
		catch_up(s);
		return;
	}
	/* none: created less than one interval before the crash; else both
	 * copies are unusable (another build's, damaged): either way it
	 * starts again from its spec and takes every control it took */
	int none = unread && unread_prev;
	char msg[256] = "";
	int err;
	s->sim = sim_new(&s->spec.params, &s->spec.scene, &s->spec.method,
			 &err, msg, sizeof msg);
	if (s->sim) {
		load_controls(s, 0);
		if (none)
			s->restore.catch_up_t = 0;
		catch_up(s);
		if (!none)
			rebuild(s, why, why2);
		return;
	}
	snprintf(why, sizeof why, "its spec is refused: %s", msg);
	s->damaged = 1;
	snprintf(s->error, sizeof s->error, "damaged: %.120s; %.120s", why, why2);
}

void srv_restore_budget(srv_session *s, double max_cpu)
{
	srv_session_budget *b = &s->budget;
	if (isfinite(s->restore.cpu_seconds)) {
		/* what it spent stays spent: a restart grants nothing */
		b->cpu_base = b->cpu_seconds = s->restore.cpu_seconds;
		b->cpu_limit = b->cpu_seconds + fmin(s->restore.cpu_limit - b->cpu_seconds, max_cpu);
	} else {
		b->cpu_limit = s->restore.cpu_grant > 0 ? fmin(s->restore.cpu_grant, max_cpu)
							: max_cpu;
	}
	b->cpu_paused = s->restore.cpu_paused && s->state == SRV_PAUSED;
	for (size_t i = 0; i < s->restore.nreplay; i++)
		s->restore.replay[i].cmd.cpu_grant = max_cpu;
}

void srv_persist_load(srv_session *s, const char *id, const srv_exp_finder *ef)
{
	load_files(s, id, ef);
	if (s->damaged) {
		srv_store_count_damaged(SRV_STORE_SESSION);
		return;
	}
	srv_session_readopt(s, ef);
	if (!s->restore.upgrade)
		return;
	/* an earlier format: its spec written again at once (spec.json and
	 * spec.bin, each atomically: store.c), its checkpoint at the next
	 * interval, in this build's format */
	srv_persist_spec(s, 0);
	s->persist.ckpt_dirty = 1;
	srv_store_count_upgraded(SRV_STORE_SESSION);
	srv_log(SRV_LOG_INFO, "session %s: read from an earlier format, written again "
			      "in format %d", s->entry.id, SRV_STORE_VERSION);
}

/* ---- the restored sessions' workers ------------------------------------ */

size_t srv_sessions_start_restored(void)
{
	srv_session **all = NULL;
	size_t n = srv_sessions_all(&all), started = 0;
	for (size_t i = 0; i < n; i++) {
		srv_session *s = all[i];
		if (s->damaged || s->worker_started)
			continue;
		if (pthread_create(&s->worker, NULL, srv_worker_main, s) == 0) {
			s->worker_started = 1;
			started++;
		} else {
			pthread_mutex_lock(&s->lock);
			s->state = SRV_FAILED;
			snprintf(s->error, sizeof s->error,
				 "cannot start the session's worker thread");
			pthread_mutex_unlock(&s->lock);
		}
	}
	/* the restored controls due now applied before anyone can read a
	 * status: a GET right after the start shows the targets the session
	 * acknowledged, not its checkpoint's (bounded: a worker that does not
	 * get there within 5 s is read as it is) */
	double until = srv_now() + 5.0;
	for (size_t i = 0; i < n; i++) {
		srv_session *s = all[i];
		if (!s->worker_started)
			continue;
		pthread_mutex_lock(&s->lock);
		while (!s->first_applied && srv_now() < until) {
			struct timespec ts;
			clock_gettime(CLOCK_REALTIME, &ts);
			ts.tv_nsec += 10000000; /* 10 ms */
			if (ts.tv_nsec >= 1000000000) {
				ts.tv_sec++;
				ts.tv_nsec -= 1000000000;
			}
			pthread_cond_timedwait(&s->data, &s->lock, &ts);
		}
		pthread_mutex_unlock(&s->lock);
	}
	srv_sessions_release(all, n);
	return started;
}
