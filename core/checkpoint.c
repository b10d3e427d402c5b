/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * checkpoint.c - a sim's checkpoint: everything that determines its future
 * in one versioned binary buffer with a checksum, and an instance rebuilt
 * from one that continues bit for bit (sim.h "checkpoints").
 *
 * Layout (host byte order: a checkpoint is read back by the same build on
 * the same machine, which the layout fields below check):
 *
 *   header   magic "CVSCKPT1", version, the instance's layout (state
 *            length n, integrated columns, sizes of the controls, the
 *            estimator and the workspace's state), payload length, and
 *            the FNV-1a 64 checksum of the payload
 *   payload  y, y_obs, y_prev (n each); t_int, t_obs, t_prev, k_fixed,
 *            steps, rhs_evals, failed, error; the controls (model_ctl,
 *            ramps included); the estimator (records included); energy
 *            baselines e0, kin0, pot0, elastic0; feed origins X0, X0k;
 *            the workspace's state (ode_method.save); from version 3 on,
 *            the measured step error (shadow.c): step_error,
 *            shadow_until, shadow_window and the running shadow's own
 *            checkpoint (none: length 0), so that a restore in the middle
 *            of a shadow's window gives the same error bar at its end;
 *            from version 4 on, between the workspace's state and the
 *            step error's part, the feed's disturbances (sim_set_feed):
 *            m_n, mu and the energy they brought
 *
 * Versions 2 (without the step error's part) and 3 (without the
 * disturbances' part) are still read: a version 2 instance keeps the
 * calibrated step term until its next estimate starts, as it did; a
 * version 3 one has the m_n and mu it was created with.
 *
 * The core's structs are plain data (no pointers), so they are copied
 * whole; the sizes in the header refuse a buffer of a build whose structs
 * differ. A restore validates everything before it trusts anything:
 * length, magic, version, layout, checksum, then the finiteness of the
 * state, and never reads past the buffer.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sim_int.h"
#include "units.h"

#define CKPT_MAGIC "CVSCKPT1"
/* The last version without the step error's part, and the last without
 * the disturbances' part (each read as it was). */
#define CKPT_VERSION_NO_SHADOW 2
#define CKPT_VERSION_NO_DISTURB 3

typedef struct ckpt_header {
	char magic[8];
	uint32_t version;
	uint32_t n, columns;
	uint32_t ctl_size, est_size, ws_size;
	uint64_t payload;
	uint64_t checksum;
} ckpt_header;

/* The scalars of the instance, copied whole. */
typedef struct ckpt_scalars {
	double t_int, t_obs, t_prev;
	uint64_t k_fixed, steps, rhs_evals;
	int32_t failed, pad;
	char error[160];
	double e0, kin0, pot0, elastic0, X0;
} ckpt_scalars;

/* The measured step error (version 3 on), after the workspace's state;
 * the shadow's checkpoint (shadow_len bytes) follows it. */
typedef struct ckpt_shadow {
	double step_error, shadow_until, shadow_window;
	uint64_t shadow_len;
} ckpt_shadow;

/* The feed's disturbances (version 4 on), before the step error's part. */
typedef struct ckpt_disturb {
	double m_n, mu, e_disturb;
} ckpt_disturb;

/* FNV-1a, 64 bits (Fowler, Noll, Vo): enough to tell a torn or flipped
 * buffer from a whole one; not a defence against a forger. */
uint64_t sim_checksum(const void *buf, size_t len)
{
	const unsigned char *b = buf;
	uint64_t h = 1469598103934665603ULL;
	for (size_t i = 0; i < len; i++) {
		h ^= b[i];
		h *= 1099511628211ULL;
	}
	return h;
}

static size_t ws_state_size(const sim *s)
{
	return s->ode->state_size ? s->ode->state_size(s->ws) : 0;
}

static size_t columns_of(const sim *s)
{
	return (size_t)(s->md.dk.K > 0 ? s->md.dk.K : 1);
}

/* The length of the payload's part that every version holds. */
static size_t base_size(const sim *s)
{
	return 3 * sizeof(double) * (size_t)s->md.n + sizeof(ckpt_scalars) + sizeof(model_ctl) +
	       sizeof(estimator) + sizeof(double) * columns_of(s) + ws_state_size(s);
}

/* The payload's length for instance s (its shadow's checkpoint too). */
static size_t payload_size(const sim *s)
{
	return base_size(s) + sizeof(ckpt_disturb) + sizeof(ckpt_shadow) + (s->shadow ? sim_checkpoint_size(s->shadow) : 0);
}

static ckpt_header header_of(const sim *s)
{
	ckpt_header h;
	memset(&h, 0, sizeof h);
	memcpy(h.magic, CKPT_MAGIC, sizeof h.magic);
	h.version = SIM_CHECKPOINT_VERSION;
	h.n = (uint32_t)s->md.n;
	h.columns = (uint32_t)columns_of(s);
	h.ctl_size = sizeof(model_ctl);
	h.est_size = sizeof(estimator);
	h.ws_size = (uint32_t)ws_state_size(s);
	h.payload = payload_size(s);
	return h;
}

size_t sim_checkpoint_size(const sim *s)
{
	return sizeof(ckpt_header) + payload_size(s);
}

/* Copy len bytes at *at into dst (write: from src) and move on. */
static void put(char **at, const void *src, size_t len)
{
	memcpy(*at, src, len);
	*at += len;
}

static void get(const char **at, void *dst, size_t len)
{
	memcpy(dst, *at, len);
	*at += len;
}

int sim_checkpoint(const sim *s, void *buf, size_t len)
{
	if (!buf || len < sim_checkpoint_size(s))
		return SIM_EPARAM;
	ckpt_header h = header_of(s);
	size_t vec = sizeof(double) * (size_t)s->md.n;
	ckpt_scalars sc;
	memset(&sc, 0, sizeof sc);
	sc.t_int = s->t_int;
	sc.t_obs = s->t_obs;
	sc.t_prev = s->t_prev;
	sc.k_fixed = s->k_fixed;
	sc.steps = s->steps;
	sc.rhs_evals = s->sys.rhs_evals;
	sc.failed = s->failed;
	memcpy(sc.error, s->error, sizeof sc.error);
	sc.e0 = s->e0;
	sc.kin0 = s->kin0;
	sc.pot0 = s->pot0;
	sc.elastic0 = s->elastic0;
	sc.X0 = s->X0;
	char *at = (char *)buf + sizeof h, *payload = at;
	put(&at, s->y, vec);
	put(&at, s->y_obs, vec);
	put(&at, s->y_prev, vec);
	put(&at, &sc, sizeof sc);
	put(&at, &s->ctl, sizeof s->ctl);
	put(&at, &s->est, sizeof s->est);
	put(&at, s->X0k, sizeof(double) * columns_of(s));
	if (h.ws_size)
		s->ode->save(s->ws, at);
	at += h.ws_size;
	ckpt_disturb di = {s->md.p.m_n, s->md.p.mu, s->e_disturb};
	put(&at, &di, sizeof di);
	ckpt_shadow sh = {s->step_error, s->shadow_until, s->shadow_window,
			  s->shadow ? sim_checkpoint_size(s->shadow) : 0};
	put(&at, &sh, sizeof sh);
	if (sh.shadow_len)
		sim_checkpoint(s->shadow, at, sh.shadow_len);
	h.checksum = sim_checksum(payload, h.payload);
	memcpy(buf, &h, sizeof h);
	return SIM_OK;
}

static sim *restore_depth(const sim_params *p, const sim_scene *sc, const sim_method *m,
			  const void *buf, size_t len, int depth, int *err, char *msg,
			  size_t msglen);

/* Refuse with a reason (msg) and SIM_ECHECKPOINT. */
static int refuse(char *msg, size_t msglen, const char *why)
{
	if (msg)
		snprintf(msg, msglen, "checkpoint refused: %s", why);
	return SIM_ECHECKPOINT;
}

/* The disturbances' part's length in a payload of version v. */
static size_t disturb_size(uint32_t version)
{
	return version > CKPT_VERSION_NO_DISTURB ? sizeof(ckpt_disturb) : 0;
}

/* The disturbances' part at *at (version 4 on; moved past it) into s,
 * checked against the ranges a running instance takes. SIM_OK or
 * SIM_ECHECKPOINT with msg. */
static int restore_disturb(sim *s, const char **at, char *msg, size_t msglen)
{
	ckpt_disturb di;
	get(at, &di, sizeof di);
	double lo, hi;
	sim_feed_mass_range(&s->md.p, &s->md.sc, &s->cfg, &lo, &hi);
	if (!(di.m_n >= lo && di.m_n <= hi) ||
	    !sim_setting_check(sim_setting_find("mu"), di.mu) || !isfinite(di.e_disturb) ||
	    (s->md.nf == 0 && (di.m_n != s->md.p.m_n || di.mu != s->md.p.mu)))
		return refuse(msg, msglen, "the feed's disturbances' part is out of range");
	s->md.p.m_n = di.m_n;
	s->md.p.mu = di.mu;
	s->e_disturb = di.e_disturb;
	return SIM_OK;
}

/* Check buf against instance s (built for the same set): the frame, the
 * layout and the checksum. SIM_OK or SIM_ECHECKPOINT with msg. */
static int check_frame(const sim *s, const void *buf, size_t len, char *msg, size_t msglen)
{
	ckpt_header h, want = header_of(s);
	if (!buf || len < sizeof h)
		return refuse(msg, msglen, "shorter than its header (cut off)");
	memcpy(&h, buf, sizeof h);
	if (memcmp(h.magic, CKPT_MAGIC, sizeof h.magic) != 0)
		return refuse(msg, msglen, "not a checkpoint (bad magic)");
	if (h.version != SIM_CHECKPOINT_VERSION && h.version != CKPT_VERSION_NO_SHADOW &&
	    h.version != CKPT_VERSION_NO_DISTURB)
		return refuse(msg, msglen, "unknown version");
	size_t base = base_size(s);
	if (h.n != want.n || h.columns != want.columns || h.ctl_size != want.ctl_size ||
	    h.est_size != want.est_size || h.ws_size != want.ws_size ||
	    (h.version == CKPT_VERSION_NO_SHADOW ? h.payload != base
						  : h.payload < base + disturb_size(h.version) +
									sizeof(ckpt_shadow)))
		return refuse(msg, msglen, "layout differs from this session's model or build");
	if (len - sizeof h < h.payload)
		return refuse(msg, msglen, "cut off");
	if (sim_checksum((const char *)buf + sizeof h, h.payload) != h.checksum)
		return refuse(msg, msglen, "checksum mismatch");
	return SIM_OK;
}

/* The step error's part of a version 3 payload at at (left bytes to the
 * payload's end): the shadow restored (a shadow of a shadow is refused:
 * depth). SIM_OK or SIM_ECHECKPOINT with msg. */
static int restore_shadow(sim *s, const char *at, size_t left, int depth, char *msg,
			  size_t msglen)
{
	ckpt_shadow sh;
	if (left < sizeof sh)
		return refuse(msg, msglen, "cut off");
	get(&at, &sh, sizeof sh);
	if (sh.shadow_len != left - sizeof sh || (sh.shadow_len && depth > 0) ||
	    !(isnan(sh.step_error) || sh.step_error >= 0.0) || !isfinite(sh.shadow_until) ||
	    !(sh.shadow_window > 0.0) || !isfinite(sh.shadow_window))
		return refuse(msg, msglen, "the measured step error's part is inconsistent");
	s->step_error = sh.step_error;
	s->shadow_until = sh.shadow_until;
	s->shadow_window = sh.shadow_window;
	if (!sh.shadow_len)
		return SIM_OK;
	/* as shadow_begin made it: the same method with fewer sub-steps */
	sim_method m = s->cfg;
	m.substeps = (s->cfg.substeps + 1) / 2;
	char why[160] = "";
	int e;
	s->shadow = restore_depth(&s->md.p, &s->md.sc, &m, at, sh.shadow_len, depth + 1, &e, why,
				  sizeof why);
	if (!s->shadow) {
		if (msg)
			snprintf(msg, msglen, "its shadow: %s", why);
		return SIM_ECHECKPOINT;
	}
	return SIM_OK;
}

sim *sim_restore(const sim_params *p, const sim_scene *sc, const sim_method *m, const void *buf,
		 size_t len, int *err, char *msg, size_t msglen)
{
	return restore_depth(p, sc, m, buf, len, 0, err, msg, msglen);
}

static sim *restore_depth(const sim_params *p, const sim_scene *sc, const sim_method *m,
			  const void *buf, size_t len, int depth, int *err, char *msg,
			  size_t msglen)
{
	sim *s = sim_alloc(p, sc, m, err, msg, msglen);
	if (!s)
		return NULL;
	int e = check_frame(s, buf, len, msg, msglen);
	if (e != SIM_OK)
		goto fail;
	ckpt_header h;
	memcpy(&h, buf, sizeof h);
	size_t vec = sizeof(double) * (size_t)s->md.n;
	ckpt_scalars scl;
	const char *at = (const char *)buf + sizeof(ckpt_header);
	get(&at, s->y, vec);
	get(&at, s->y_obs, vec);
	get(&at, s->y_prev, vec);
	get(&at, &scl, sizeof scl);
	get(&at, &s->ctl, sizeof s->ctl);
	get(&at, &s->est, sizeof s->est);
	get(&at, s->X0k, sizeof(double) * columns_of(s));
	if (ws_state_size(s))
		s->ode->load(s->ws, at);
	at += ws_state_size(s);
	if (disturb_size(h.version) && (e = restore_disturb(s, &at, msg, msglen)) != SIM_OK)
		goto fail;
	if (h.version != CKPT_VERSION_NO_SHADOW) {
		e = restore_shadow(s, at, h.payload - base_size(s) - disturb_size(h.version), depth,
				   msg, msglen);
		if (e != SIM_OK)
			goto fail;
	}
	s->t_int = scl.t_int;
	s->t_obs = scl.t_obs;
	s->t_prev = scl.t_prev;
	s->k_fixed = scl.k_fixed;
	s->steps = scl.steps;
	s->sys.rhs_evals = scl.rhs_evals;
	s->failed = scl.failed;
	memcpy(s->error, scl.error, sizeof s->error);
	s->error[sizeof s->error - 1] = '\0';
	s->e0 = scl.e0;
	s->kin0 = scl.kin0;
	s->pot0 = scl.pot0;
	s->elastic0 = scl.elastic0;
	s->X0 = scl.X0;
	/* a matching checksum on nonsense is not expected, but a state that
	 * is not finite or times out of order would poison everything */
	int bad = !isfinite(s->t_int) || !isfinite(s->t_obs) || s->t_obs > s->t_int + 1e-9 ||
		  (s->failed != SIM_OK && s->failed != SIM_EDIVERGED && s->failed != SIM_ESTEP) ||
		  s->est.n_rec < 0 || (!s->est.pending && s->est.n_rec < 1) ||
		  s->est.n_rec > EST_RECORDS || s->ctl.beta_ramp.n < 0 || s->ctl.beta_ramp.n > 4 ||
		  s->ctl.psi_ramp.n < 0 || s->ctl.psi_ramp.n > 4 ||
		  (!s->est.pending && s->est.stride < 1) || /* set at its first boundary */
		  (s->failed != SIM_OK && !s->error[0]); /* a failure says why */
	for (int i = 0; !bad && i < s->md.n; i++)
		bad = !isfinite(s->y[i]);
	if (bad) {
		e = refuse(msg, msglen, "values out of range");
		goto fail;
	}
	sim_update_status(s);
	if (err)
		*err = SIM_OK;
	return s;
fail:
	if (err)
		*err = e;
	sim_free(s);
	return NULL;
}
