/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_v1.c - the reader of format version 1 (store.h): a version-1
 * payload into version 2's layout (records.h's but the checkpoint's
 * trailer, which store_v2.c then takes to version 3), so that every reader
 * sees one layout and a data directory of an earlier release comes back
 * whole.
 *
 * Version 1 is two layouts under one number, told apart by the sizes the
 * payload's own lengths imply:
 *   - c3bc9a1's (the last build before version 2): the layout of
 *     records.h, taken as it is;
 *   - c793934's (the release before it): sim_method without `tol`, so
 *     api_spec is 8 bytes shorter wherever it is held; a sweep's request
 *     without its study, band and seed, its points with velocity,
 *     uncertainty and steady where sim_measurement now is; no fits; a
 *     checkpoint without the trailer (its time is read from the core's
 *     part, whose own layout the core refuses: the session is re-created
 *     from its spec and control log, session_load.c).
 * The c793934 structs are written out in records_v1.h as that build laid them out
 * (x86-64 and aarch64 Linux), not through today's types, so that a later
 * change to those types cannot move them; the static_asserts hold the
 * sizes that build wrote. A setting a version-1 record lacks (tol) takes
 * the value its preset gives today, as a request without it would.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "records.h"
#include "records_v1.h"
#include "sim.h"
#include "store.h"

/* ---- conversions ------------------------------------------------------------ */

static void params_from_v1(const v1_params *from, sim_params *to)
{
	V1_PARAMS(V1_COPY)
}

/* feed_model, a later setting, is the column model: all c793934 had */
static void scene_from_v1(const v1_scene *from, sim_scene *to)
{
	V1_SCENE(V1_COPY)
}

static void spec_from_v1(const v1_spec *o, api_spec *s)
{
	memset(s, 0, sizeof *s);
	memcpy(s->preset, o->preset, sizeof s->preset);
	s->preset[sizeof s->preset - 1] = '\0';
	/* tol and any later setting: the preset's, as a request without
	 * them gets */
	if (sim_preset(s->preset, &s->params, &s->scene, &s->method) != 0)
		sim_preset_czubak2016(&s->params, &s->scene, &s->method);
	params_from_v1(&o->params, &s->params);
	scene_from_v1(&o->scene, &s->scene);
	s->scene.feed_model = SIM_FEED_COLUMN;
	memcpy(s->method.name, o->method.name, sizeof s->method.name);
	s->method.name[sizeof s->method.name - 1] = '\0';
	s->method.dt = o->method.dt;
	s->method.rtol = o->method.rtol;
	s->method.atol = o->method.atol;
	s->method.substeps = o->method.substeps;
	s->method.feed_events = o->method.feed_events;
	s->pace = o->pace;
	s->until = o->until;
	s->sample_rate = o->sample_rate;
}

static void exp_from_v1(const v1_exp_record *o, srv_exp_record *r)
{
	memset(r, 0, sizeof *r);
	memcpy(r->id, o->id, sizeof r->id);
	memcpy(r->session_id, o->session_id, sizeof r->session_id);
	r->req.fresh = o->req.fresh;
	spec_from_v1(&o->req.spec, &r->req.spec);
	memcpy(r->req.session_id, o->req.session_id, sizeof r->req.session_id);
	r->req.beta_rate.si = o->req.beta_rate.si;
	r->req.beta_rate.user = o->req.beta_rate.user;
	r->req.keep_session = o->req.keep_session;
	r->req.nseg = o->req.nseg;
	for (int k = 0; k < API_EXP_MAX_SEGMENTS && k < 32; k++) {
		const v1_segment *a = &o->req.seg[k];
		api_segment *b = &r->req.seg[k];
		b->beta.si = a->beta.si;
		b->beta.user = a->beta.user;
		b->until = a->until;
		b->state = a->state;
		b->t_command = a->t_command;
		b->t_end = a->t_end;
		b->steady_velocity = a->steady_velocity;
		b->mean_velocity = a->mean_velocity;
		b->uncertainty = a->uncertainty;
		b->steady = a->steady;
		b->reversal_time = a->reversal_time;
		b->start_velocity = a->start_velocity;
	}
	r->state = o->state;
	r->cur = o->cur;
	memcpy(r->error, o->error, sizeof r->error);
	r->t0 = o->t0;
	r->t_now = o->t_now;
	r->seg_first = o->seg_first;
	r->rec_n = o->rec_n;
	r->rec_spacing = o->rec_spacing;
}

/* A c793934 experiment state (its record and 2 rec_n doubles) at p (n
 * bytes) into version 2's, malloc'd with its length in *len; NULL when it
 * is not one. */
static char *exp_state_from_v1(const char *p, size_t n, size_t *len)
{
	v1_exp_record o;
	if (n < sizeof o)
		return NULL;
	memcpy(&o, p, sizeof o);
	if (o.rec_n > (n - sizeof o) / (2 * sizeof(double)) ||
	    n != sizeof o + 2 * o.rec_n * sizeof(double))
		return NULL;
	size_t vec = n - sizeof o;
	char *out = malloc(sizeof(srv_exp_record) + vec);
	if (!out)
		return NULL;
	srv_exp_record r;
	exp_from_v1(&o, &r);
	memcpy(out, &r, sizeof r);
	memcpy(out + sizeof r, p + sizeof o, vec);
	*len = sizeof r + vec;
	return out;
}

static void point_from_v1(const v1_sweep_point *o, api_sweep_point *p)
{
	memset(p, 0, sizeof *p);
	p->beta.si = o->beta.si;
	p->beta.user = o->beta.user;
	p->rotation = o->rotation;
	p->state = o->state;
	/* what c793934 measured; the rest it did not say */
	p->m.transport_velocity = o->velocity;
	p->m.uncertainty = o->uncertainty;
	p->m.steady = o->steady;
	p->m.periods = p->m.rotor_speed_mean = p->m.cpu_seconds = NAN;
	p->m.step_error = p->m.dt = NAN;
	p->mirrored = o->mirrored;
	memcpy(p->error, o->error, sizeof p->error);
	p->error[sizeof p->error - 1] = '\0';
	for (size_t a = 0; a < sizeof p->vary / sizeof *p->vary; a++)
		p->vary[a] = NAN;
	p->band[0] = p->band[1] = NAN;
}

/* ---- by kind ---------------------------------------------------------------- */

static void *spec_v1(char *p, size_t *len, const char **bad)
{
	if (*len == sizeof(srv_spec_record))
		return p; /* c3bc9a1's */
	if (*len != sizeof(v1_spec_record)) {
		*bad = "of another size than any release wrote";
		free(p);
		return NULL;
	}
	v1_spec_record o;
	memcpy(&o, p, sizeof o);
	free(p);
	srv_spec_record *r = calloc(1, sizeof *r);
	if (!r) {
		*bad = "out of memory";
		return NULL;
	}
	memcpy(r->id, o.id, sizeof r->id);
	spec_from_v1(&o.spec, &r->spec);
	r->created = o.created;
	r->owned = o.owned;
	*len = sizeof *r;
	return r;
}

static void *exp_v1(char *p, size_t *len, const char **bad)
{
	if (*len == sizeof(srv_exp_record))
		return p;
	if (*len != sizeof(v1_exp_record)) {
		*bad = "of another size than any release wrote";
		free(p);
		return NULL;
	}
	v1_exp_record o;
	memcpy(&o, p, sizeof o);
	free(p);
	srv_exp_record *r = malloc(sizeof *r);
	if (!r) {
		*bad = "out of memory";
		return NULL;
	}
	exp_from_v1(&o, r);
	*len = sizeof *r;
	return r;
}

/* A sweep's payload is its head, nbeta values and total points: the
 * layout whose lengths add up to the payload's is the one that wrote it. */
static int sweep_fits(size_t len, size_t head, size_t point, uint64_t nbeta, uint64_t total)
{
	return nbeta <= API_SWEEP_MAX_POINTS && total <= API_SWEEP_MAX_POINTS &&
	       len == head + nbeta * sizeof(v1_value) + total * point;
}

static void *sweep_v1(char *p, size_t *len, const char **bad)
{
	size_t n = *len;
	if (n >= sizeof(srv_sweep_record)) {
		srv_sweep_record r;
		memcpy(&r, p, sizeof r);
		if (r.req.nbeta >= 0 &&
		    sweep_fits(n, sizeof r, sizeof(api_sweep_point), (uint64_t)r.req.nbeta, r.total))
			return p; /* c3bc9a1's */
	}
	v1_sweep_record o;
	if (n >= sizeof o)
		memcpy(&o, p, sizeof o);
	if (n < sizeof o || o.req.nbeta < 0 ||
	    !sweep_fits(n, sizeof o, sizeof(v1_sweep_point), (uint64_t)o.req.nbeta, o.total)) {
		*bad = "inconsistent: no release's layout";
		free(p);
		return NULL;
	}
	size_t nb = (size_t)o.req.nbeta * sizeof(api_value), np = o.total * sizeof(api_sweep_point);
	char *out = malloc(sizeof(srv_sweep_record) + nb + np);
	if (!out) {
		*bad = "out of memory";
		free(p);
		return NULL;
	}
	srv_sweep_record r;
	memset(&r, 0, sizeof r);
	memcpy(r.id, o.id, sizeof r.id);
	spec_from_v1(&o.req.spec, &r.req.spec);
	r.req.nbeta = o.req.nbeta;
	r.req.nrot = o.req.nrot;
	r.req.rotations[0] = o.req.rotations[0];
	r.req.rotations[1] = o.req.rotations[1];
	r.req.t_end = o.req.t_end;
	r.req.nvary = 0; /* a v(beta) sweep, all c793934 had */
	r.total = o.total;
	r.done = o.done;
	r.cancelled = o.cancelled;
	memcpy(out, &r, sizeof r);
	const char *at = p + sizeof o;
	char *to = out + sizeof r;
	for (int32_t b = 0; b < o.req.nbeta; b++, at += sizeof(v1_value), to += sizeof(api_value)) {
		v1_value v;
		memcpy(&v, at, sizeof v);
		api_value w = {.si = v.si, .user = v.user};
		memcpy(to, &w, sizeof w);
	}
	for (uint64_t k = 0; k < o.total; k++, at += sizeof(v1_sweep_point), to += sizeof(api_sweep_point)) {
		v1_sweep_point a;
		api_sweep_point b;
		memcpy(&a, at, sizeof a);
		point_from_v1(&a, &b);
		memcpy(to, &b, sizeof b);
	}
	free(p);
	*len = sizeof r + nb + np;
	return out;
}

/* t_obs of a c793934 core checkpoint (sim_len bytes at p), NaN when it
 * does not hold one. */
static double core_time_v1(const char *p, size_t n)
{
	v1_core_header h;
	if (n < sizeof h)
		return NAN;
	memcpy(&h, p, sizeof h);
	size_t at = sizeof h + 3 * sizeof(double) * (size_t)h.n + sizeof(double);
	if (memcmp(h.magic, "CVSCKPT1", 8) != 0 || h.n > 1u << 20 ||
	    h.payload != n - sizeof h || at + sizeof(double) > n ||
	    sim_checksum(p + sizeof h, n - sizeof h) != h.checksum)
		return NAN;
	double t;
	memcpy(&t, p + at, sizeof t);
	return isfinite(t) && t >= 0 ? t : NAN;
}

static void *checkpoint_v1(char *p, size_t *len, const char **bad)
{
	size_t n = *len;
	v1_ckpt_record o;
	if (n >= sizeof o)
		memcpy(&o, p, sizeof o);
	size_t body = n >= sizeof o ? srv_store_ckpt_body(n, sizeof o, o.exp_len, o.sim_len) : 0;
	if (!body) {
		*bad = "inconsistent lengths";
		free(p);
		return NULL;
	}
	v1_ckpt_trailer tr = {.logged = UINT64_MAX, .t = NAN};
	char *exp = NULL;
	size_t exp_len = o.exp_len;
	if (n == body + sizeof tr) {
		memcpy(&tr, p + body, sizeof tr); /* c3bc9a1's: as it is */
		exp = malloc(exp_len ? exp_len : 1);
		if (exp)
			memcpy(exp, p + sizeof o, exp_len);
	} else if (n == body) {
		/* c793934's: no trailer; the time from the core's part */
		tr.t = core_time_v1(p + sizeof o + o.exp_len, o.sim_len);
		exp = o.exp_len ? exp_state_from_v1(p + sizeof o, o.exp_len, &exp_len)
				: malloc(1);
		if (!exp) { /* not an experiment's state: it is not resumed */
			exp_len = 0;
			exp = malloc(1);
			o.exp_started = 0;
		}
	} else {
		*bad = "inconsistent lengths";
		free(p);
		return NULL;
	}
	srv_ckpt_record r;
	memset(&r, 0, sizeof r);
	r.state = o.state;
	r.exp_started = o.exp_started;
	r.pace = o.pace;
	r.until = o.until;
	memcpy(r.error, o.error, sizeof r.error < sizeof o.error ? sizeof r.error : sizeof o.error);
	r.error[sizeof r.error - 1] = '\0';
	memcpy(r.exp_id, o.exp_id, sizeof r.exp_id);
	r.exp_id[sizeof r.exp_id - 1] = '\0';
	r.exp_len = exp_len;
	r.sim_len = o.sim_len;
	/* version 2's trailer is version 1's (store_v2.c takes it on) */
	size_t out_len = sizeof r + exp_len + o.sim_len + sizeof tr;
	char *out = exp ? malloc(out_len) : NULL;
	if (out) {
		memcpy(out, &r, sizeof r);
		memcpy(out + sizeof r, exp, exp_len);
		memcpy(out + sizeof r + exp_len, p + sizeof o + o.exp_len, o.sim_len);
		memcpy(out + sizeof r + exp_len + o.sim_len, &tr, sizeof tr);
		*len = out_len;
	} else {
		*bad = "out of memory";
	}
	free(exp);
	free(p);
	return out;
}

void *srv_store_upgrade_v1(uint32_t kind, void *p, size_t *len, const char **bad)
{
	switch (kind) {
	case SRV_STORE_SESSION:
		return spec_v1(p, len, bad);
	case SRV_STORE_CHECKPOINT:
		return checkpoint_v1(p, len, bad);
	case SRV_STORE_EXPERIMENT:
		return exp_v1(p, len, bad);
	case SRV_STORE_SWEEP:
		return sweep_v1(p, len, bad);
	case SRV_STORE_FIT:
		return p; /* c3bc9a1 wrote the first (c793934 kept no fits) */
	default:
		*bad = "of an unknown kind";
		free(p);
		return NULL;
	}
}
