/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pmap.h - one parallel map: job(arg, i) for i = 0..n-1 on a few threads,
 * with a progress hook. `convsim sweep` runs its points on it, a fit its
 * batches of model evaluations; the daemon hands a fit its worker pool
 * instead, behind the same function type (pmap_fn), so a map is either
 * this library's threads or the caller's.
 */
#ifndef CONVSIM_PMAP_H
#define CONVSIM_PMAP_H

#include <stddef.h>

/* One job of a map: independent of the others and thread-safe. */
typedef void (*pmap_job)(void *arg, size_t i);
/* A map: runs job(arg, i) for i = 0..n-1, in parallel or not, and returns
 * when all are done. ctx is the map's own (a pool, ...). */
typedef void (*pmap_fn)(void *ctx, size_t n, pmap_job job, void *arg);
/* Called after job i, with the count done so far (1..n); calls are one at
 * a time, in the order the jobs end. */
typedef void (*pmap_progress)(void *arg, size_t i, size_t done);

/* The library's map on min(threads, n) threads (1..64; the caller's is
 * one of them, so threads 1 runs inline); progress may be NULL. Threads
 * that cannot be created leave their share to the others. */
void pmap_run(int threads, size_t n, pmap_job job, void *arg, pmap_progress progress);

#endif
