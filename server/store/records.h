/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * records.h - the layouts of the framed records in the data directory at
 * format version SRV_STORE_VERSION (store.h), in one place: what a build
 * writes and, through the upgraders of earlier versions (store_v1.c,
 * store_v2.c), what it hands its readers whatever version the file says
 * (docs/formats.md "Stored formats").
 *
 *   sessions/ID/spec.bin        srv_spec_record
 *   sessions/ID/checkpoint.bin  srv_ckpt_record, the
 *                               experiment's srv_exp_record and feed
 *                               velocity record (and its kind's api_exp_ext), the core's checkpoint
 *                               (its own version, core/checkpoint.c),
 *                               srv_ckpt_trailer
 *   experiments/ID.bin          srv_exp_record, and for an identification
 *                               or a closed loop its api_exp_ext (a plain
 *                               schedule's record has no tail: builds
 *                               before the kinds read it as they wrote it)
 *   sweeps/ID.bin               srv_sweep_record, api_value[nbeta],
 *                               api_sweep_point[total]
 *   fits/ID.bin                 srv_fit_record, the request body, the
 *                               result's JSON and CSV
 *
 * The records copy API structs whole (host byte order, read back on the
 * machine that wrote them), so any change to api_spec, api_experiment_req,
 * api_sweep_req, api_sweep_point or the structs they hold changes the
 * format. The sizes below are asserted at build time: a build that changes
 * one does not compile until SRV_STORE_VERSION is raised, the sizes here
 * are updated and the layout it replaces gets its reader (as store_v1.c
 * reads version 1), with a fixture written by the last release
 * (tests/fixtures/datadir/).
 */
#ifndef CONVSIM_RECORDS_H
#define CONVSIM_RECORDS_H

#include <assert.h>
#include <stdint.h>

#include "api.h"
#include "fit.h"
#include "registry.h"

/* sessions/ID/spec.bin: the spec as created (spec.json holds the same as
 * the API's JSON and is read first). */
typedef struct srv_spec_record {
	char id[SRV_ID_LEN];
	api_spec spec;
	double created;
	int32_t owned, pad;
} srv_spec_record;

/* experiments/ID.bin, and the head of an experiment's state in its
 * session's checkpoint. */
typedef struct srv_exp_record {
	char id[SRV_ID_LEN], session_id[SRV_ID_LEN];
	api_experiment_req req;
	int32_t state, cur;
	char error[256];
	double t0, t_now;
	uint64_t seg_first, rec_n;
	double rec_spacing;
} srv_exp_record;

/* sweeps/ID.bin's head (the varied settings' names in its request). */
typedef struct srv_sweep_record {
	char id[SRV_ID_LEN];
	api_sweep_req req;     /* betas, values: NULL here; betas follow */
	uint64_t total, done;
	int32_t cancelled, pad;
} srv_sweep_record;

/* fits/ID.bin's head. */
typedef struct srv_fit_record {
	char id[SRV_ID_LEN];
	int32_t over, status, has_pr, phase; /* phase: index in fitjob.c's phases, or -1 */
	int32_t iteration, pad;
	int64_t evaluations;
	double cost, x[FIT_MAX_FREE];
	uint64_t body_len, json_len, csv_len;
} srv_fit_record;

/* sessions/ID/checkpoint.bin: this head, the experiment's state (exp_len
 * bytes), the core's checkpoint (sim_len bytes), then this trailer: the
 * length of the control log it holds, so that a restore replays what came
 * after; its time, so that a session re-created from its spec knows where
 * it was (c793934's checkpoints had no trailer: store_v1.c adds it); and
 * its CPU budget, so that a restart does not grant it again (format 2's
 * trailer ended after t: store_v2.c gives it cpu_seconds NAN, unknown). */
typedef struct srv_ckpt_trailer {
	uint64_t logged;
	double t;              /* s */
	double cpu_seconds;    /* s: the CPU the session had spent (NAN:
				  unknown, a format-2 checkpoint) */
	double cpu_limit;      /* s: the count at which it pauses */
	int32_t cpu_paused;    /* paused by its CPU budget */
	int32_t pad;
} srv_ckpt_trailer;
#define SRV_CKPT_TRAILER sizeof(srv_ckpt_trailer)
typedef struct srv_ckpt_record {
	int32_t state, exp_started;
	double pace, until;
	char error[256];
	char exp_id[SRV_ID_LEN];
	uint64_t exp_len, sim_len;
} srv_ckpt_record;

/* Version 3's sizes (x86-64 and aarch64 Linux, where the daemon is built
 * and tested): see the top of this file before changing one. */
#if defined(__x86_64__) || defined(__aarch64__)
static_assert(sizeof(srv_spec_record) == 576, "spec.bin's layout changed: a new format version");
static_assert(sizeof(srv_exp_record) == 4016, "the experiment record changed: a new format version");
static_assert(sizeof(api_exp_ext) == 5040, "an experiment kind's tail changed: a new format version");
static_assert(sizeof(srv_sweep_record) == 1888, "the sweep record changed: a new format version");
static_assert(sizeof(api_sweep_point) == 352, "the sweep point changed: a new format version");
static_assert(sizeof(srv_fit_record) == 152, "the fit record changed: a new format version");
static_assert(sizeof(srv_ckpt_record) == 320 && sizeof(srv_ckpt_trailer) == 40,
	      "the checkpoint's head or trailer changed: a new format version");
#endif

#endif
