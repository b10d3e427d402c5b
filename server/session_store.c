/*
 * session_store.c - a session's files in the data directory, written and
 * read back (README "Persistence"); session.c's restore calls it.
 *
 *   sessions/ID/spec.bin         the spec as created (framed, store.h)
 *   sessions/ID/controls.ndjson  every acknowledged control, one JSON
 *                                object a line with t_effective (s)
 *   sessions/ID/checkpoint.bin   the latest checkpoint: run state, pace,
 *                                until, the attached experiment's state
 *                                and the core's checkpoint (sim.h); the
 *                                one before it as checkpoint.bin.prev
 *
 * Everything is written by the store's writer (store.c); the worker only
 * serialises, between steps, with the session lock held. A restore never
 * fails the daemon: a checkpoint that does not pass its checks falls back
 * to the previous one; a session whose spec or both checkpoints are
 * unusable is listed as "damaged" with the reason; a session with a spec
 * and no checkpoint yet starts again from its spec.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "metrics.h"
#include "session_int.h"
#include "store.h"
#include "util.h"

/* sessions/ID/spec.bin */
typedef struct spec_record {
	char id[SRV_ID_LEN];
	api_spec spec;
	double created;
	int32_t owned, pad;
} spec_record;

static void session_dir(char *out, size_t len, const char *id,
			const char *file)
{
	snprintf(out, len, "sessions/%s%s%s", id, file ? "/" : "",
		 file ? file : "");
}

/* A write's outcome for session id (malloc'd, freed here): a failure puts
 * the session in state "error" with the reason; a later success clears
 * it. */
static void written(void *arg, int err, const char *what)
{
	char *id = arg;
	srv_session *s = srv_session_get(id);
	free(id);
	if (!s)
		return;
	pthread_mutex_lock(&s->lock);
	if (err)
		snprintf(s->store_error, sizeof s->store_error, "%s", what);
	else if (what && what[0] == '\0' && s->store_error[0])
		s->store_error[0] = '\0';
	pthread_mutex_unlock(&s->lock);
	srv_session_put(s);
}

static void queue(const srv_session *s, const char *file, void *buf,
		  size_t len, int keep_prev)
{
	char path[128];
	session_dir(path, sizeof path, s->entry.id, file);
	srv_store_write(path, buf, len, keep_prev, written,
			strdup(s->entry.id));
}

void srv_persist_spec(srv_session *s)
{
	if (!srv_store_enabled() || s->damaged)
		return;
	spec_record r;
	memset(&r, 0, sizeof r);
	snprintf(r.id, sizeof r.id, "%s", s->entry.id);
	r.spec = s->spec;
	r.created = s->created;
	r.owned = s->owned;
	size_t len;
	void *buf = srv_store_frame(SRV_STORE_SESSION, &r, sizeof r, &len);
	if (buf)
		queue(s, "spec.bin", buf, len, 0);
}

void srv_persist_control(srv_session *s, const char *json)
{
	if (!srv_store_enabled())
		return;
	size_t add = strlen(json) + 1;
	if (s->controls_len + add + 1 > s->controls_cap) {
		size_t cap = s->controls_cap ? 2 * s->controls_cap : 4096;
		while (cap < s->controls_len + add + 1)
			cap *= 2;
		char *nc = realloc(s->controls, cap);
		if (!nc)
			return;
		s->controls = nc;
		s->controls_cap = cap;
	}
	memcpy(s->controls + s->controls_len, json, add - 1);
	s->controls_len += add;
	s->controls[s->controls_len - 1] = '\n';
	char *copy = malloc(s->controls_len ? s->controls_len : 1);
	if (!copy)
		return;
	memcpy(copy, s->controls, s->controls_len);
	queue(s, "controls.ndjson", copy, s->controls_len, 0);
}

void srv_persist_checkpoint(srv_session *s, int force)
{
	if (!srv_store_enabled() || !s->sim)
		return;
	double now = srv_now();
	int due = now - s->ckpt_wall >= srv_store_interval() &&
		  (s->state == SRV_RUNNING || s->ckpt_dirty);
	if (!due && !(force && s->ckpt_dirty))
		return;
	srv_ckpt_record r;
	memset(&r, 0, sizeof r);
	r.state = s->state;
	r.pace = s->pace;
	r.until = s->until;
	snprintf(r.error, sizeof r.error, "%s", s->error);
	void *exp = NULL;
	if (s->exp && s->exp_started) {
		size_t n = 0;
		exp = srv_exp_save(s->exp, &n);
		r.exp_len = exp ? n : 0;
		r.exp_started = 1;
		snprintf(r.exp_id, sizeof r.exp_id, "%s", srv_exp_id(s->exp));
	}
	r.sim_len = sim_checkpoint_size(s->sim);
	size_t plen = sizeof r + r.exp_len + r.sim_len;
	char *payload = malloc(plen);
	if (payload) {
		memcpy(payload, &r, sizeof r);
		if (r.exp_len)
			memcpy(payload + sizeof r, exp, r.exp_len);
		sim_checkpoint(s->sim, payload + sizeof r + r.exp_len,
			       r.sim_len);
		size_t len;
		void *buf = srv_store_frame(SRV_STORE_CHECKPOINT, payload, plen,
					    &len);
		if (buf)
			queue(s, "checkpoint.bin", buf, len, 1);
	}
	free(payload);
	free(exp);
	s->ckpt_wall = now;
	s->ckpt_dirty = 0;
}

void srv_persist_remove(const srv_session *s)
{
	char path[128];
	session_dir(path, sizeof path, s->entry.id, NULL);
	srv_store_remove(path);
}

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
	 * the difference below and let sim_len point past the buffer */
	if (r->exp_len > len - sizeof *r || r->sim_len != len - sizeof *r - r->exp_len ||
	    r->state < SRV_RUNNING || r->state > SRV_FAILED) {
		snprintf(why, whylen, "inconsistent lengths or state");
		return -1;
	}
	r->error[sizeof r->error - 1] = '\0';
	r->exp_id[SRV_ID_LEN - 1] = '\0';
	return 0;
}

/* The checkpoint of s from file (relative): restores s->sim, run state and
 * the experiment (found with find, given back with put); 0, or -1 with
 * why and *unread set when the file could not be read at all (missing). */
static int load_checkpoint(srv_session *s, const char *file, const srv_exp_finder *ef,
			   int *unread, char *why, size_t whylen)
{
	size_t n = 0, len;
	char *raw = srv_store_read_text(file, &n);
	const char *bad = "missing or unreadable";
	char *p = raw ? srv_store_unframe(raw, n, SRV_STORE_CHECKPOINT, &len, &bad) : NULL;
	*unread = !raw;
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
	int err;
	sim *sm = sim_restore(&s->spec.params, &s->spec.scene, &s->spec.method,
			      p + sizeof r + r.exp_len, r.sim_len, &err, msg,
			      sizeof msg);
	if (!sm) {
		snprintf(why, whylen, "%s: %s", file, msg);
		goto done;
	}
	sim_free(s->sim);
	s->sim = sm;
	s->state = r.state;
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
	*spec = r.spec;
	*created = r.created;
	*owned = r.owned != 0;
	return 0;
}

void srv_persist_load(srv_session *s, const char *id, const srv_exp_finder *ef)
{
	char path[128], why[512] = "", why2[512] = "";
	snprintf(s->entry.id, sizeof s->entry.id, "%s", id);
	s->created = srv_unix_time();
	s->spec.sample_rate = API_DEFAULT_SAMPLE_RATE;
	session_dir(path, sizeof path, id, "spec.bin");
	size_t len;
	void *r = srv_store_read(path, SRV_STORE_SESSION, &len, why, sizeof why);
	char msg[256];
	if (r && srv_spec_decode(r, len, &s->spec, &s->created, &s->owned, msg,
				 sizeof msg) != 0) {
		snprintf(why, sizeof why, "%s: %s", path, msg);
		free(r);
		r = NULL;
	}
	if (!r) {
		s->damaged = 1;
		snprintf(s->error, sizeof s->error, "damaged: %.240s", why);
		return;
	}
	free(r);
	s->pace = s->spec.pace;
	s->until = s->spec.until;
	s->state = SRV_RUNNING;
	session_dir(path, sizeof path, id, "checkpoint.bin");
	int unread = 0, unread_prev = 0;
	if (load_checkpoint(s, path, ef, &unread, why, sizeof why) == 0)
		return;
	char prev[160];
	snprintf(prev, sizeof prev, "%s.prev", path);
	if (load_checkpoint(s, prev, ef, &unread_prev, why2, sizeof why2) == 0) {
		srv_log(SRV_LOG_WARN, "session %s: %s; restored from the "
				      "previous checkpoint", id, why);
		return;
	}
	int none = unread && unread_prev;
	if (none) { /* created less than one interval before the crash */
		char msg[256] = "";
		int err;
		s->sim = sim_new(&s->spec.params, &s->spec.scene,
				 &s->spec.method, &err, msg, sizeof msg);
		if (s->sim)
			return;
		snprintf(why, sizeof why, "its spec is refused: %s", msg);
	}
	s->damaged = 1;
	snprintf(s->error, sizeof s->error, "damaged: %.120s; %.120s", why, why2);
}

