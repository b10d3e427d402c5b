/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_util.h - what the libFuzzer harnesses of tests/fuzz/ share: the
 * oracle's failure (an abort libFuzzer keeps as a crash with its input),
 * the checks every answered problem must pass, and a session spec written
 * back as the create body that made it and compared with another.
 */
#ifndef CONVSIM_FUZZ_UTIL_H
#define CONVSIM_FUZZ_UTIL_H

#include <cjson/cJSON.h>
#include <stddef.h>
#include <stdint.h>

#include "api.h"
#include "job.h"

/* The oracle failed: print the message and abort (libFuzzer saves the
 * input as a crash). */
void fuzz_fail(const char *fmt, ...) __attribute__((format(printf, 1, 2), noreturn));
#define FUZZ_CHECK(cond, ...)                   \
	do {                                    \
		if (!(cond))                    \
			fuzz_fail(__VA_ARGS__); \
	} while (0)

/* A reader refused the input (what: which, why: its reason). Under
 * FUZZ_MUST_ACCEPT (tests/fuzz/run.sh, on the committed real seeds before
 * fuzzing) that fails the oracle: the seeds no longer match the formats
 * and must be made again (docs/fuzzing.md "Fuzzing"); otherwise nothing. */
void fuzz_refused(const char *what, const char *why);

/* The input as an exact-size heap buffer with no terminating NUL, so that
 * ASan sees any read past the length (caller frees). */
char *fuzz_exact(const uint8_t *data, size_t size);
/* The input as a NUL-terminated string (caller frees). */
char *fuzz_string(const uint8_t *data, size_t size);

/* Write into buf (n bytes) the checksum (sim_checksum, 8 bytes at sum_at)
 * of the payload behind a header of size bytes whose 8-byte length is at
 * len_at, when the lengths allow: the frames of the store and of the core's
 * checkpoints, so that mutated payloads reach the checks behind them. */
void fuzz_fix_checksum(char *buf, size_t n, size_t len_at, size_t sum_at, size_t size);
/* core/checkpoint.c's header: 8 bytes of magic, six 32-bit fields, then
 * the payload's length and its checksum. */
enum { FUZZ_CKPT_PAYLOAD = 32, FUZZ_CKPT_CHECKSUM = 40, FUZZ_CKPT_HEADER = 48 };

/* A framed file of the data directory (store.c's frame: magic, version,
 * kind, pad, the payload's length and checksum) unframed as kind, its
 * checksum first made right when fixed: the payload (malloc'd, *plen its
 * length) or NULL. Fails the oracle where a refusal gives no reason, or
 * where a file of this build's format, accepted, framed again is not the
 * same bytes (but the unused pad). */
char *fuzz_unframe(const uint8_t *data, size_t n, uint32_t kind, int fixed, size_t *plen);

/* A job's JSON document as GET /api/v1/{plural}/ID serves it (the kind's
 * text hook under srv_job_lock): fails the oracle unless it is an object
 * whose "id" is id; its "state" into state ("" where none). */
void fuzz_job_document(const srv_job_kind *kind, srv_entry *e, const char *id, char *state,
		       size_t statelen);

/* A refused request: code is the one returned, *pb the problem. Checks
 * that code is a 4xx/5xx of API_ERRNO_MAP equal to pb->code, that field
 * and detail are terminated strings and the detail is not empty, and that
 * the RFC 9457 body api_problem_json writes parses back as JSON with the
 * same status, a type naming the code, the same field and, with a range,
 * min <= max. */
void fuzz_check_problem(api_err code, const api_problem *pb);

/* The POST /sessions body that makes spec, written from what the
 * session document (api_session_json with its spec) shows: preset,
 * params, scene, integrator, pace, sample_rate and, when with_until,
 * until. A tree the caller deletes. */
cJSON *fuzz_spec_body(const api_spec *spec, int with_until);
/* Text of a tree by the API's exact printer (the tree is deleted); caller
 * frees. */
char *fuzz_print(cJSON *tree);
/* Fail unless a and b are the same spec: preset, pace, until (when
 * with_until), sample_rate and every setting of the settings table
 * (SI values equal; those with a unit scale, beta, within 4 ulp, since
 * the document shows them in degrees). what names the round trip. */
void fuzz_same_spec(const api_spec *a, const api_spec *b, int with_until, const char *what);
/* The czubak2016 defaults as POST /sessions {} makes them. */
const api_spec *fuzz_default_spec(void);

#endif
