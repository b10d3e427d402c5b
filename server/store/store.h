/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store.h - the daemon's state on disk (--data-dir): one writer thread
 * that writes every file as temporary file -> fsync -> rename -> fsync of
 * the directory, and the framed binary files it reads back at start-up.
 *
 * Nothing else writes under the data directory but the control logs
 * (control_log.c: appended and synced by the thread that answers for
 * them) and a new record (a session's spec.json, a job's record: written
 * by the thread that creates it, srv_store_write_now, so that its 201
 * follows it). Callers hand a finished buffer to the writer (srv_store_write)
 * and go on: no caller but the answer to a control or a creation waits
 * for a disk, none writes on a worker's step path or under a registry
 * lock. A pending write to the same path is replaced by a newer one (a checkpoint that
 * could not be written in time is superseded, never queued twice).
 * The outcome of each write comes back through its callback, on the
 * writer thread with no lock held: 0, or the errno (ENOSPC, EIO, EACCES,
 * ...) with a sentence naming the file; failures are logged and counted
 * (convsim_store_errors_total).
 *
 * Framed files: a header (magic "CVSF", format version, kind, payload
 * length, FNV-1a 64 checksum of the payload, sim_checksum) and the payload
 * (records.h: the layouts). Reading one checks all of it and says what is
 * wrong; a file of an earlier format version is upgraded to this one's
 * layout as it is read (store_v1.c), and its reader writes it back.
 *
 * Lock order: the store's queue lock is a leaf (registry.h): callbacks run
 * after it is released.
 */
#ifndef CONVSIM_STORE_H
#define CONVSIM_STORE_H

#include <stddef.h>
#include <stdint.h>

#include "api.h"
#include "config.h"

/* The format this build writes; it reads every one from
 * SRV_STORE_OLDEST on (docs/formats.md "Stored formats"):
 *   1  c793934 and the builds up to c3bc9a1: no word of the layout
 *      beyond the frame's version, two layouts under the same number
 *      (told apart by the records' sizes, store_v1.c)
 *   2  7e56a85 to b09537b: the layouts of records.h but the checkpoint's
 *      trailer, which ended after its time (store_v2.c)
 *   3  this build: the layouts of records.h, their sizes asserted at
 *      build time, the checkpoint's trailer with the session's CPU count
 *      and grant; spec.json says "format": 3 */
#define SRV_STORE_VERSION 3
#define SRV_STORE_OLDEST 1

/* Kinds of framed files. */
enum {
	SRV_STORE_SESSION = 1,    /* sessions/ID/spec.bin */
	SRV_STORE_CHECKPOINT = 2, /* sessions/ID/checkpoint.bin (+ .prev) */
	SRV_STORE_EXPERIMENT = 3, /* experiments/ID.bin */
	SRV_STORE_SWEEP = 4,      /* sweeps/ID.bin */
	SRV_STORE_FIT = 5,        /* fits/ID.bin */
};

/* Called on the writer thread after a write: err 0 or an errno, what a
 * sentence naming the file and the failed step. */
typedef void (*srv_store_done)(void *arg, int err, const char *what);

/* Start the writer on cfg->data_dir (nothing when it is NULL) and create
 * its sub-directories. 0, or -1 with a message on stderr. */
int srv_store_open(const srv_config *cfg);
/* Finish every queued write and stop the writer. */
void srv_store_close(void);
/* From now on, note every write that fails (the shutdown's final
 * checkpoints and records); srv_store_failed then says how many failed
 * and names them (up to len bytes into what: the first failure's
 * sentence, then the other files). */
void srv_store_watch(void);
size_t srv_store_failed(char *what, size_t len);
/* 1 when a data directory is in use. */
int srv_store_enabled(void);
/* The absolute path of rel (relative to the data directory) into out. */
void srv_store_path(char *out, size_t len, const char *rel);
/* --checkpoint-interval, s of wall time. */
double srv_store_interval(void);

/* Queue a write of buf (len bytes; ownership taken, freed after the
 * write) to path (relative to the data directory, parent directories
 * created). keep_prev: the file it replaces is kept as path.prev. done
 * (may be NULL) is called once, always on the writer thread (the caller
 * may hold locks it takes), with the outcome, also when superseded (err
 * 0, what ""). Callers check srv_store_enabled() first: with the store
 * off, or out of memory, buf is freed and done is never called. */
void srv_store_write(const char *path, void *buf, size_t len, int keep_prev,
		     srv_store_done done, void *arg);
/* Write buf (len bytes, borrowed) to path now, on the calling thread, as
 * the writer would (temporary file, fsync, rename, fsync of the
 * directory): 0 (also without a data directory), or the errno with a
 * sentence in msg; counted and logged as the writer's writes are. Only
 * for a record's first version (its creation, before the answer): a
 * session's spec.json before its worker runs, a job's record under the
 * job's lock. Its temporary file is path.now.tmp, so that a queued write
 * of the same path (an experiment that ended at once) cannot mix with
 * it. */
int srv_store_write_now(const char *path, const void *buf, size_t len, char *msg,
			size_t msglen);
/* srv_store_write with before (may be NULL) called on the writer thread
 * just before the file is written (not when superseded): a checkpoint
 * makes the control log it accounts for durable first. */
void srv_store_write_after(const char *path, void *buf, size_t len, int keep_prev,
			   void (*before)(void *arg), srv_store_done done, void *arg);
/* Call fn(arg) on the writer thread after the jobs queued before it
 * (nothing without a data directory: fn is not called). */
void srv_store_call(void (*fn)(void *arg), void *arg);
/* Create the directory rel (relative; its parent exists) now, and make
 * its name durable: 0 (also when it exists or without a data directory),
 * or -1 with errno. */
int srv_store_make_dir(const char *rel);
/* Open the append-only file rel (relative; its directory exists: never
 * created here, so a file removed with its directory is not made again)
 * for writing with pwrite, cut to len bytes (a tail past what was made
 * durable is dropped), its name durable: the descriptor, or -1 with
 * errno. The control log (control_log.c) is the one file written outside
 * the writer thread. */
int srv_store_open_log(const char *rel, uint64_t len);
/* Queue the removal of path (a file, or a directory and what it holds),
 * after every write queued before it. */
void srv_store_remove(const char *path);
/* API_OK if what rel (relative) names could be removed now: the directory
 * holding it, and rel itself when it is a directory, may be written
 * (always API_OK without a data directory). Else 503 in *pb naming the
 * cause (a read-only file system: EROFS), so that a DELETE answers it
 * and changes nothing rather than answering 204 for files that stay. */
api_err srv_store_check_removable(const char *rel, api_problem *pb);

/* A framed file of kind around payload (borrowed): malloc'd, its length
 * in *len; NULL when out of memory. */
void *srv_store_frame(uint32_t kind, const void *payload, size_t plen,
		      size_t *len);
/* Read path (relative) as a framed file of kind: the payload in this
 * build's layout (malloc'd, caller frees) and its length, *older set when
 * the file is of an earlier format (upgraded: the caller writes it back),
 * or NULL with the reason in why (missing, cut off, checksum, a newer
 * format, a layout no release wrote, ...). */
void *srv_store_read(const char *path, uint32_t kind, size_t *len, int *older,
		     char *why, size_t whylen);
/* The payload of a framed file of kind held in buf (n bytes, malloc'd,
 * taken): the payload in this build's layout (malloc'd; buf or another
 * buffer) and its length in *len, *older as above, or NULL (buf freed)
 * with the reason in *bad (static text). No file system: srv_store_read
 * reads, this checks and upgrades (and the fuzz harness
 * tests/fuzz/fuzz_store.c calls it). */
void *srv_store_unframe(char *buf, size_t n, uint32_t kind, size_t *len, int *older,
			const char **bad);
/* A version-1 payload of kind (taken) in version 2's layout (store_v1.c),
 * and a version-2 one in version 3's (store_v2.c): the payload (malloc'd;
 * p itself when already in it) and *len, or NULL (p freed) with the
 * reason in *bad. A version-1 file goes through both. */
void *srv_store_upgrade_v1(uint32_t kind, void *p, size_t *len, const char **bad);
void *srv_store_upgrade_v2(uint32_t kind, void *p, size_t *len, const char **bad);
/* An older checkpoint's head (head bytes stating exp_len and sim_len) and
 * its two parts within the n bytes read: their length, or 0 when the
 * lengths the head states do not fit (exp_len checked first, so that the
 * differences cannot wrap). */
static inline size_t srv_store_ckpt_body(size_t n, size_t head, uint64_t exp_len,
					 uint64_t sim_len)
{
	return n >= head && exp_len <= n - head && sim_len <= n - head - exp_len
		       ? head + (size_t)exp_len + (size_t)sim_len
		       : 0;
}

/* What a start-up restore found, by kind (SRV_STORE_SESSION for sessions,
 * else a job kind's store_kind): a record listed damaged, and one read
 * from an earlier format and written back in this one. */
void srv_store_count_damaged(uint32_t kind);
void srv_store_count_upgraded(uint32_t kind);
size_t srv_store_damaged(uint32_t kind);
size_t srv_store_upgraded(uint32_t kind);
/* Read a whole plain file (relative path); malloc'd with a final NUL,
 * NULL if missing. */
char *srv_store_read_text(const char *path, size_t *len);
/* Entries of a directory (relative path), malloc'd array of malloc'd
 * names (free each and the array); the count, 0 if none. */
size_t srv_store_list(const char *path, char ***names);
/* 1 when the directory rel holds no file but the store's temporary ones
 * (a record whose first write a crash cut short). */
int srv_store_dir_unwritten(const char *rel);
/* The same for the entries of one kind of record under rel: directories
 * named by an id (dirs) or regular files ID.bin. Anything else is skipped
 * with one log line each (the store's own .tmp and .prev files without). */
size_t srv_store_list_ids(const char *rel, int dirs, char ***names);

#endif
