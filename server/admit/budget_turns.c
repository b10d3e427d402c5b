/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget_turns.c - CPU turns for pace "max" sessions: a first-come-first-
 * served queue of at most --max-busy holders, each holding its slot for a
 * time slice while others wait (round robin: each gets an equal share of
 * the cores). Its lock is a leaf (registry.h).
 */
#include <pthread.h>

#include "budget_turns.h"
#include "util.h"

/* How long a pace "max" session holds its CPU slot while others wait. */
#define CPU_SLICE_S 0.1

static const srv_config *cfg;
static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static srv_cpu_turn *queue_head, *queue_tail; /* lock */
static int busy, waiting;               /* lock */

void srv_cpu_turns_init(const srv_config *config)
{
	cfg = config;
}

/* ---- CPU turns ------------------------------------------------------------------ */

/* Unlink t from the queue (lock held). */
static void unqueue(srv_cpu_turn *t)
{
	srv_cpu_turn **pp = &queue_head, *prev = NULL;
	while (*pp && *pp != t) {
		prev = *pp;
		pp = &(*pp)->next;
	}
	if (!*pp)
		return;
	*pp = t->next;
	if (queue_tail == t)
		queue_tail = prev;
	t->next = NULL;
	t->queued = 0;
	waiting--;
}

int srv_cpu_take(srv_cpu_turn *t)
{
	pthread_mutex_lock(&lock);
	if (!t->holding) {
		if (!t->queued) {
			t->next = NULL;
			if (queue_tail)
				queue_tail->next = t;
			else
				queue_head = t;
			queue_tail = t;
			t->queued = 1;
			waiting++;
		}
		if (busy < cfg->max_busy && queue_head == t) {
			unqueue(t);
			busy++;
			t->holding = 1;
			t->since = srv_now();
		}
	}
	int holding = t->holding;
	pthread_mutex_unlock(&lock);
	return holding;
}

int srv_cpu_turn_over(const srv_cpu_turn *t)
{
	pthread_mutex_lock(&lock);
	int over = t->holding && queue_head &&
		   srv_now() - t->since >= CPU_SLICE_S;
	pthread_mutex_unlock(&lock);
	return over;
}

void srv_cpu_leave(srv_cpu_turn *t)
{
	/* neither holding nor queued: nothing to give up, and the lock (one
	 * for all sessions) is not taken; every paced worker calls this on
	 * each loop, 250 times a simulated second. Only t's owner changes
	 * these two (take and leave), so it reads them without the lock. */
	if (!t->holding && !t->queued)
		return;
	pthread_mutex_lock(&lock);
	if (t->holding) {
		busy--;
		t->holding = 0;
	}
	if (t->queued)
		unqueue(t);
	/* the next in line may take the slot now */
	if (queue_head && busy < cfg->max_busy)
		pthread_cond_broadcast(queue_head->wake);
	pthread_mutex_unlock(&lock);
}

void srv_cpu_counts(int *b, int *w)
{
	pthread_mutex_lock(&lock);
	*b = busy;
	*w = waiting;
	pthread_mutex_unlock(&lock);
}
