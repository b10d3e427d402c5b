/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pool.c - a fixed pool of worker threads for sweep points and, as a
 * parallel map (pmap.h's pmap_fn: srv_pool_map), for a fit's batches.
 *
 * Jobs are fn(arg) pairs on a FIFO list. Stopping lets the threads drain
 * what is queued (jobs check srv_stopping() and return at once), then joins
 * them, so every job runs exactly once and owners can count on it.
 */
#include <pthread.h>
#include <stdlib.h>

#include "pmap.h"
#include "pool.h"
#include "util.h"

typedef struct job {
	void (*fn)(void *);
	void *arg;
	struct job *next;
} job;

static pthread_mutex_t pool_lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t pool_cond = PTHREAD_COND_INITIALIZER;
static job *queue_head, *queue_tail;
static int queued, stopping, nthreads;
static pthread_t *threads;

static void *pool_main(void *unused)
{
	(void)unused;
	srv_thread_background("pool");
	pthread_mutex_lock(&pool_lock);
	for (;;) {
		while (!queue_head && !stopping)
			pthread_cond_wait(&pool_cond, &pool_lock);
		job *j = queue_head;
		if (!j)
			break; /* stopping and drained */
		queue_head = j->next;
		if (!queue_head)
			queue_tail = NULL;
		queued--;
		pthread_mutex_unlock(&pool_lock);
		j->fn(j->arg);
		free(j);
		pthread_mutex_lock(&pool_lock);
	}
	pthread_mutex_unlock(&pool_lock);
	return NULL;
}

int srv_pool_start(int n)
{
	threads = calloc((size_t)n, sizeof *threads);
	if (!threads)
		return -1;
	for (nthreads = 0; nthreads < n; nthreads++)
		if (pthread_create(&threads[nthreads], NULL, pool_main, NULL)) {
			srv_pool_stop();
			return -1;
		}
	return 0;
}

int srv_pool_submit(void (*fn)(void *), void *arg)
{
	job *j = malloc(sizeof *j);
	if (!j)
		return -1;
	j->fn = fn;
	j->arg = arg;
	j->next = NULL;
	pthread_mutex_lock(&pool_lock);
	if (stopping) {
		pthread_mutex_unlock(&pool_lock);
		free(j);
		return -1;
	}
	if (queue_tail)
		queue_tail->next = j;
	else
		queue_head = j;
	queue_tail = j;
	queued++;
	pthread_cond_signal(&pool_cond);
	pthread_mutex_unlock(&pool_lock);
	return 0;
}

void srv_pool_stop(void)
{
	pthread_mutex_lock(&pool_lock);
	stopping = 1;
	pthread_cond_broadcast(&pool_cond);
	pthread_mutex_unlock(&pool_lock);
	for (int i = 0; i < nthreads; i++)
		pthread_join(threads[i], NULL);
	nthreads = 0;
	free(threads);
	threads = NULL;
}

int srv_pool_queued(void)
{
	pthread_mutex_lock(&pool_lock);
	int n = queued;
	pthread_mutex_unlock(&pool_lock);
	return n;
}

/* ---- the pool as a parallel map (pmap.h) ----------------------------------- */

typedef struct batch {
	pthread_mutex_t lock;
	pthread_cond_t done;
	size_t left;
	pmap_job job;
	void *arg;
} batch;

typedef struct batch_item {
	batch *b;
	size_t i;
} batch_item;

static void batch_finish(batch *b)
{
	pthread_mutex_lock(&b->lock);
	if (--b->left == 0)
		pthread_cond_signal(&b->done);
	pthread_mutex_unlock(&b->lock);
}

static void run_item(void *arg)
{
	batch_item *it = arg;
	batch *b = it->b;
	size_t i = it->i;
	free(it);
	b->job(b->arg, i); /* cheap when cancelled or stopping: it checks */
	batch_finish(b);
}

/* Every job of the batch on the pool (inline when it cannot take one);
 * returns when all are done. */
void srv_pool_map(void *ctx, size_t n, pmap_job job, void *arg)
{
	(void)ctx;
	batch b = {PTHREAD_MUTEX_INITIALIZER, PTHREAD_COND_INITIALIZER, n, job, arg};
	for (size_t i = 0; i < n; i++) {
		batch_item *it = malloc(sizeof *it);
		if (it)
			*it = (batch_item){&b, i};
		if (!it || srv_pool_submit(run_item, it) != 0) {
			free(it);
			job(arg, i);
			batch_finish(&b);
		}
	}
	pthread_mutex_lock(&b.lock);
	while (b.left)
		pthread_cond_wait(&b.done, &b.lock);
	pthread_mutex_unlock(&b.lock);
	pthread_mutex_destroy(&b.lock);
	pthread_cond_destroy(&b.done);
}
