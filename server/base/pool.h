/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pool.h - a fixed pool of worker threads for sweep points: jobs are
 * fn(arg) pairs run once each, in order of submission.
 */
#ifndef CONVSIM_POOL_H
#define CONVSIM_POOL_H

#include <stddef.h>

#include "pmap.h"

/* Start n threads. Returns 0 or -1 (nothing left running). */
int srv_pool_start(int threads);
/* Queue fn(arg); returns 0, or -1 when stopping or out of memory (fn is
 * then not called: the caller still owns arg). */
int srv_pool_submit(void (*fn)(void *), void *arg);
/* Stop taking jobs, run what is queued (jobs see srv_stopping()), join. */
void srv_pool_stop(void);
/* Jobs waiting for a thread. */
int srv_pool_queued(void);
/* The pool as a parallel map (pmap.h's pmap_fn; ctx unused): job(arg, i)
 * for i = 0..n-1 as pool jobs, each run inline when the pool cannot take
 * it; returns when all are done. The jobs check for a stop themselves. */
void srv_pool_map(void *ctx, size_t n, pmap_job job, void *arg);

#endif
