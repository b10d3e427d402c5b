/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_v2.c - the reader of format version 2 (store.h): a version-2
 * payload into version 3's layout (records.h), so that every reader sees
 * one layout (store_v1.c brings version 1 to version 2 first).
 *
 * Only the checkpoint changed. Version 2's trailer ended after the
 * checkpoint's time (the control log's length and t); version 3's goes on
 * with the session's CPU count, the count at which it pauses and whether
 * its budget paused it. A version-2 checkpoint gets cpu_seconds NAN
 * (unknown), and its session counts its CPU from 0 with the grant its
 * logged controls gave, as the releases that wrote it did (session_load.c).
 * The head is the same in both and is kept as it is; every other record
 * is version 3's as it is. Version 2's head and trailer are written out
 * here as those releases laid them out (x86-64 and aarch64 Linux), not
 * through today's types.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "records.h"
#include "store.h"

typedef struct v2_ckpt_record {
	int32_t state, exp_started;
	double pace, until;
	char error[256];
	char exp_id[24];
	uint64_t exp_len, sim_len;
} v2_ckpt_record;

typedef struct v2_ckpt_trailer {
	uint64_t logged;
	double t;
} v2_ckpt_trailer;

#if defined(__x86_64__) || defined(__aarch64__)
static_assert(sizeof(v2_ckpt_record) == 320 && sizeof(v2_ckpt_trailer) == 16,
	      "version 2's checkpoint head and trailer");
static_assert(sizeof(v2_ckpt_record) == sizeof(srv_ckpt_record),
	      "version 3 keeps version 2's checkpoint head");
#endif

static void *checkpoint_v2(char *p, size_t *len, const char **bad)
{
	size_t n = *len;
	v2_ckpt_record o;
	if (n >= sizeof o)
		memcpy(&o, p, sizeof o);
	size_t body = n >= sizeof o ? srv_store_ckpt_body(n, sizeof o, o.exp_len, o.sim_len) : 0;
	if (!body) {
		*bad = "inconsistent lengths";
		free(p);
		return NULL;
	}
	if (n == body)
		return p; /* no trailer: read as it is (srv_ckpt_decode) */
	v2_ckpt_trailer old;
	if (n != body + sizeof old) {
		*bad = "inconsistent lengths";
		free(p);
		return NULL;
	}
	memcpy(&old, p + body, sizeof old);
	srv_ckpt_trailer tr;
	memset(&tr, 0, sizeof tr);
	tr.logged = old.logged;
	tr.t = old.t;
	tr.cpu_seconds = tr.cpu_limit = NAN; /* not kept: unknown */
	char *out = realloc(p, body + sizeof tr);
	if (!out) {
		*bad = "out of memory";
		free(p);
		return NULL;
	}
	memcpy(out + body, &tr, sizeof tr);
	*len = body + sizeof tr;
	return out;
}

void *srv_store_upgrade_v2(uint32_t kind, void *p, size_t *len, const char **bad)
{
	switch (kind) {
	case SRV_STORE_CHECKPOINT:
		return checkpoint_v2(p, len, bad);
	case SRV_STORE_SESSION:
	case SRV_STORE_EXPERIMENT:
	case SRV_STORE_SWEEP:
	case SRV_STORE_FIT:
		return p; /* version 3's layout */
	default:
		*bad = "of an unknown kind";
		free(p);
		return NULL;
	}
}
