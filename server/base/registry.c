/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * registry.c - the one registry of objects kept by id (see registry.h for
 * the contract and the daemon's lock order).
 *
 * A singly linked list, newest first, under the registry's mutex. Reserved
 * entries sit in the list (so that ids stay unique and the cap counts
 * them) but lookups, snapshots and counts skip them until published.
 */
#include <stdlib.h>
#include <string.h>

#include "registry.h"
#include "util.h"

void srv_registry_open(srv_registry *reg, size_t cap)
{
	pthread_mutex_lock(&reg->lock);
	reg->head = NULL;
	reg->count = 0;
	reg->cap = cap;
	pthread_mutex_unlock(&reg->lock);
}

/* The entry with this id, reserved or published (lock held). */
static srv_entry *find(srv_registry *reg, const char *id)
{
	srv_entry *e = reg->head;
	while (e && strcmp(e->id, id) != 0)
		e = e->next;
	return e;
}

/* Unlink e and give back its place (lock held); a claimed victim that
 * goes (deleted meanwhile) has made the room its claim stood for. */
static void unlink_entry(srv_registry *reg, srv_entry *e)
{
	srv_entry **pp = &reg->head;
	while (*pp && *pp != e)
		pp = &(*pp)->next;
	if (*pp)
		*pp = e->next;
	e->next = NULL;
	e->published = 0;
	reg->count--;
	if (e->claimed) {
		e->claimed = 0;
		reg->claims--;
	}
}

/* Drop a reference (lock held); returns e if it was the last. */
static srv_entry *unref(srv_entry *e)
{
	return --e->refs == 0 ? e : NULL;
}

/* The oldest published entry evictable accepts that no reservation has
 * claimed (lock held), or NULL. */
static srv_entry *oldest_evictable(srv_registry *reg, int (*evictable)(srv_entry *))
{
	srv_entry *victim = NULL;
	for (srv_entry *e = reg->head; evictable && e; e = e->next)
		if (e->published && !e->claimed && evictable(e))
			victim = e; /* newest first: the last is the oldest */
	return victim;
}

/* Whether the registry is full: its entries less those claimed (each
 * goes when its reservation's start is certain) at the cap. */
static int full(const srv_registry *reg)
{
	return reg->count - reg->claims >= reg->cap;
}

/* Take e's place (lock held), e's id kept or made; 0 if an id is taken. */
static int place(srv_registry *reg, srv_entry *e)
{
	if (e->id[0] && find(reg, e->id))
		return 0; /* a restored id that is taken already */
	while (!e->id[0] || find(reg, e->id))
		srv_new_id(e->id);
	e->refs = 0;
	e->published = 0;
	e->claimed = 0;
	e->next = reg->head;
	reg->head = e;
	reg->count++;
	return 1;
}

int srv_registry_reserve(srv_registry *reg, srv_entry *e,
			 int (*evictable)(srv_entry *e))
{
	srv_entry *dead = NULL;
	int room = 1;
	pthread_mutex_lock(&reg->lock);
	if (full(reg)) {
		srv_entry *victim = oldest_evictable(reg, evictable);
		room = victim != NULL;
		if (victim) {
			unlink_entry(reg, victim);
			dead = unref(victim);
		}
	}
	room = room && place(reg, e);
	pthread_mutex_unlock(&reg->lock);
	if (dead)
		reg->destroy(dead);
	return room ? 0 : -1;
}

int srv_registry_reserve_claim(srv_registry *reg, srv_entry *e,
			       int (*evictable)(srv_entry *e), srv_entry **victim)
{
	*victim = NULL;
	pthread_mutex_lock(&reg->lock);
	int room = 1;
	if (full(reg)) {
		*victim = oldest_evictable(reg, evictable);
		room = *victim != NULL;
	}
	room = room && place(reg, e);
	if (room && *victim) {
		(*victim)->claimed = 1;
		(*victim)->refs++;
		reg->claims++;
	} else {
		*victim = NULL;
	}
	pthread_mutex_unlock(&reg->lock);
	return room ? 0 : -1;
}

void srv_registry_evict_claim(srv_registry *reg, srv_entry *victim)
{
	if (!victim)
		return;
	srv_entry *dead = NULL, *last;
	pthread_mutex_lock(&reg->lock);
	if (victim->published) { /* not gone meanwhile */
		unlink_entry(reg, victim);
		dead = unref(victim); /* the registry's reference */
	}
	last = unref(victim); /* the claim's */
	pthread_mutex_unlock(&reg->lock);
	if (last)
		dead = last;
	if (dead)
		reg->destroy(dead);
}

int srv_registry_withdraw(srv_registry *reg, srv_entry *e, srv_entry *victim)
{
	srv_entry *dead = NULL, *last = NULL;
	pthread_mutex_lock(&reg->lock);
	int linked = e->published;
	if (linked) {
		unlink_entry(reg, e);
		dead = unref(e);
	}
	if (victim) {
		if (victim->claimed) {
			victim->claimed = 0;
			reg->claims--;
		}
		last = unref(victim);
	}
	pthread_mutex_unlock(&reg->lock);
	if (dead)
		reg->destroy(dead);
	if (last)
		reg->destroy(last);
	return linked;
}

void srv_registry_publish(srv_registry *reg, srv_entry *e)
{
	pthread_mutex_lock(&reg->lock);
	e->published = 1;
	e->refs = 2;
	pthread_mutex_unlock(&reg->lock);
}

void srv_registry_cancel(srv_registry *reg, srv_entry *e)
{
	pthread_mutex_lock(&reg->lock);
	unlink_entry(reg, e);
	pthread_mutex_unlock(&reg->lock);
}

srv_entry *srv_registry_get(srv_registry *reg, const char *id)
{
	pthread_mutex_lock(&reg->lock);
	srv_entry *e = find(reg, id);
	if (e && e->published)
		e->refs++;
	else
		e = NULL;
	pthread_mutex_unlock(&reg->lock);
	return e;
}

void srv_registry_hold(srv_registry *reg, srv_entry *e)
{
	pthread_mutex_lock(&reg->lock);
	e->refs++;
	pthread_mutex_unlock(&reg->lock);
}

void srv_registry_put(srv_registry *reg, srv_entry *e)
{
	if (!e)
		return;
	pthread_mutex_lock(&reg->lock);
	srv_entry *dead = unref(e);
	pthread_mutex_unlock(&reg->lock);
	if (dead)
		reg->destroy(dead);
}

int srv_registry_remove(srv_registry *reg, srv_entry *e)
{
	srv_entry *dead = NULL;
	pthread_mutex_lock(&reg->lock);
	int linked = e->published;
	if (linked) {
		unlink_entry(reg, e);
		dead = unref(e);
	}
	pthread_mutex_unlock(&reg->lock);
	if (dead)
		reg->destroy(dead);
	return linked;
}

void srv_registry_clear(srv_registry *reg)
{
	for (;;) {
		srv_entry **all = NULL;
		size_t n = srv_registry_snapshot(reg, &all);
		for (size_t i = 0; i < n; i++)
			srv_registry_remove(reg, all[i]);
		srv_registry_release(reg, all, n);
		if (n == 0)
			break;
	}
}

size_t srv_registry_count(srv_registry *reg)
{
	size_t n = 0;
	pthread_mutex_lock(&reg->lock);
	for (srv_entry *e = reg->head; e; e = e->next)
		n += e->published != 0;
	pthread_mutex_unlock(&reg->lock);
	return n;
}

size_t srv_registry_snapshot(srv_registry *reg, srv_entry ***out)
{
	pthread_mutex_lock(&reg->lock);
	size_t n = 0, k = 0;
	for (srv_entry *e = reg->head; e; e = e->next)
		n += e->published != 0;
	srv_entry **all = calloc(n ? n : 1, sizeof *all);
	for (srv_entry *e = reg->head; all && e; e = e->next)
		if (e->published) {
			e->refs++;
			all[k++] = e;
		}
	pthread_mutex_unlock(&reg->lock);
	*out = all;
	return k;
}

void srv_registry_release(srv_registry *reg, srv_entry **all, size_t n)
{
	for (size_t i = 0; i < n; i++)
		srv_registry_put(reg, all[i]);
	free(all);
}
