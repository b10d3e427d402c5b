/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget_turns.h - CPU turns for pace "max" sessions (budget_turns.c): at
 * most --max-busy of them step at once, taking turns in time slices, first
 * come first served. Part of the budgets (budget.h), in a header of its
 * own so that budget_turns.c sees nothing of budget.c. Its lock is a leaf
 * of the lock order (registry.h).
 */
#ifndef CONVSIM_BUDGET_TURNS_H
#define CONVSIM_BUDGET_TURNS_H

#include <pthread.h>

#include "config.h"

/* cfg (borrowed) gives --max-busy (srv_budget_init calls it). */
void srv_cpu_turns_init(const srv_config *cfg);

/* A session's place among the pace "max" sessions. Zeroed at start; the
 * worker owns it. */
typedef struct srv_cpu_turn {
	pthread_cond_t *wake;   /* signalled when its turn may have come */
	int holding, queued;    /* budget lock; written by its owner only */
	double since;           /* srv_now() when it took its slot */
	struct srv_cpu_turn *next;
} srv_cpu_turn;

/* 1 if t holds a slot (now or already); else t joins the queue (once) and
 * its wake condition is signalled when a slot frees: 0. */
int srv_cpu_take(srv_cpu_turn *t);
/* 1 if t has held its slot for a whole slice and others wait: it should
 * leave and take again (to the back of the queue). */
int srv_cpu_turn_over(const srv_cpu_turn *t);
/* Give the slot back and leave the queue (either may be the case). */
void srv_cpu_leave(srv_cpu_turn *t);
/* Slots in use, sessions waiting. */
void srv_cpu_counts(int *busy, int *waiting);

#endif
