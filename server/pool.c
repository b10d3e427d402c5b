/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pool.c - a fixed pool of worker threads for sweep points.
 *
 * Jobs are fn(arg) pairs on a FIFO list. Stopping lets the threads drain
 * what is queued (jobs check srv_stopping() and return at once), then joins
 * them, so every job runs exactly once and owners can count on it.
 */
#include <pthread.h>
#include <stdlib.h>

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
