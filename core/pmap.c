/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * pmap.c - the library's parallel map (pmap.h): threads that take the
 * next index under one lock until none is left.
 */
#include <pthread.h>

#include "pmap.h"

typedef struct pmap {
	size_t n, next, done;
	pmap_job job;
	void *arg;
	pmap_progress progress;
	pthread_mutex_t lock;
} pmap;

static void *pmap_worker(void *arg)
{
	pmap *m = arg;
	pthread_mutex_lock(&m->lock);
	while (m->next < m->n) {
		size_t i = m->next++;
		pthread_mutex_unlock(&m->lock);
		m->job(m->arg, i);
		pthread_mutex_lock(&m->lock);
		m->done++;
		if (m->progress)
			m->progress(m->arg, i, m->done);
	}
	pthread_mutex_unlock(&m->lock);
	return NULL;
}

void pmap_run(int threads, size_t n, pmap_job job, void *arg, pmap_progress progress)
{
	pmap m = {n, 0, 0, job, arg, progress, PTHREAD_MUTEX_INITIALIZER};
	pthread_t th[64];
	int nth = threads < 1 ? 1 : threads > 64 ? 64 : threads, started = 0;
	if ((size_t)nth > n)
		nth = (int)n;
	for (int t = 1; t < nth; t++)
		if (pthread_create(&th[started], NULL, pmap_worker, &m) == 0)
			started++;
	pmap_worker(&m);
	for (int t = 0; t < started; t++)
		pthread_join(th[t], NULL);
	pthread_mutex_destroy(&m.lock);
}
