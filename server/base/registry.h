/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * registry.h - one registry for every kind of object the daemon keeps by
 * id (sessions, experiments, sweeps): a list under one lock, lookup by id,
 * a cap (with eviction of the oldest evictable entry when full), fresh
 * unique ids, reference counts and snapshots for iteration (libuv's
 * queue.h serves every handle type the same way).
 *
 * An object embeds a srv_entry and is found again with SRV_CONTAINER. An
 * entry is first reserved (it has its id and counts against the cap, but
 * lookups do not see it yet), then published or cancelled. The registry
 * holds one reference to each published entry; srv_registry_get and
 * srv_registry_snapshot hand out more. The last srv_registry_put calls the
 * registry's destroy function, outside the registry lock.
 *
 * Lock order of the daemon, written once here ("a > b": b may be taken
 * while a is held, never a while b is held):
 *
 *     registry lock > session lock > experiment lock
 *     registry lock > sweep lock
 *
 * A registry's lock is only held inside these functions: it is taken
 * before an object's lock only by the evictable test, and nothing takes it
 * while holding an object's lock. The pool's lock, the store's queue lock
 * (store.c), the budgets' locks (budget.c, budget_turns.c,
 * budget_settling.c) and the metrics are leaves: nothing is taken under
 * them; the store's callbacks run with no store lock held and may take any.
 */
#ifndef CONVSIM_REGISTRY_H
#define CONVSIM_REGISTRY_H

#include <pthread.h>
#include <stddef.h>

#define SRV_ID_LEN 24

typedef struct srv_entry {
	char id[SRV_ID_LEN];     /* srv_new_id's, set by reserve */
	int refs;                /* registry lock */
	int published;           /* registry lock */
	int claimed;             /* registry lock: a reservation's victim */
	struct srv_entry *next;  /* registry lock; newest first */
} srv_entry;

typedef struct srv_registry {
	pthread_mutex_t lock;
	srv_entry *head;
	size_t count;            /* reserved and published entries */
	size_t claims;           /* entries claimed as victims, still listed */
	size_t cap;
	void (*destroy)(srv_entry *e); /* on the last reference */
} srv_registry;

#define SRV_REGISTRY_INIT(destroy_fn) \
	{PTHREAD_MUTEX_INITIALIZER, NULL, 0, 0, 0, (destroy_fn)}

/* The object of type `type` whose srv_entry member `member` is at e. */
#define SRV_CONTAINER(e, type, member) \
	((type *)(void *)((char *)(e) - offsetof(type, member)))

/* Start empty with room for cap entries. */
void srv_registry_open(srv_registry *reg, size_t cap);

/* Take a place for e (borrowed until published or cancelled): keep the
 * id it has (an object restored from the data directory; -1 if another
 * entry has it) or, when e->id is empty, give it an id no other entry has and count it against the cap. When the registry is
 * full, the oldest published entry that evictable accepts (called under
 * the registry lock; it may take the object's lock) is removed first;
 * evictable NULL never evicts. Returns 0, or -1 when full. */
int srv_registry_reserve(srv_registry *reg, srv_entry *e,
			 int (*evictable)(srv_entry *e));
/* srv_registry_reserve for a start that may still be refused: when the
 * registry is full, the oldest published entry evictable accepts is not
 * removed but claimed (*victim, held: it stays listed and fetchable, no
 * other reservation claims it, and it leaves room for e), until one of
 * the two below. *victim NULL where there was room. Returns 0, or -1
 * when full. */
int srv_registry_reserve_claim(srv_registry *reg, srv_entry *e,
			       int (*evictable)(srv_entry *e), srv_entry **victim);
/* The start is certain: the claimed victim is removed now (unless it went
 * meanwhile) and the claim's reference dropped. NULL is accepted. */
void srv_registry_evict_claim(srv_registry *reg, srv_entry *victim);
/* The start was refused: the published e removed (as srv_registry_remove:
 * 1, or 0 if it was removed already) and the victim (NULL accepted) kept
 * as if never claimed, at once. The caller still holds its reference to e. */
int srv_registry_withdraw(srv_registry *reg, srv_entry *e, srv_entry *victim);
/* Make a reserved entry visible. It then has two references: the
 * registry's and the caller's (put it when done). */
void srv_registry_publish(srv_registry *reg, srv_entry *e);
/* Give a reserved entry's place back; the caller still owns e. */
void srv_registry_cancel(srv_registry *reg, srv_entry *e);

/* The published entry with this id as a new reference, or NULL. */
srv_entry *srv_registry_get(srv_registry *reg, const char *id);
/* One more reference to an entry the caller holds. */
void srv_registry_hold(srv_registry *reg, srv_entry *e);
/* Drop a reference; the last one destroys e. NULL is accepted. */
void srv_registry_put(srv_registry *reg, srv_entry *e);
/* Unlink a published entry and drop the registry's reference. Returns 1,
 * or 0 if it was removed already. The caller must hold a reference. */
int srv_registry_remove(srv_registry *reg, srv_entry *e);
/* Remove every published entry (the daemon stops). */
void srv_registry_clear(srv_registry *reg);

/* Published entries. */
size_t srv_registry_count(srv_registry *reg);
/* Every published entry, newest first, as new references in *out (a
 * malloc'd array: put each entry, then free it). Returns the count (0 and
 * *out NULL when out of memory). */
size_t srv_registry_snapshot(srv_registry *reg, srv_entry ***out);
/* Put each of n snapshot entries and free the array. */
void srv_registry_release(srv_registry *reg, srv_entry **all, size_t n);

#endif
