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

/* Unlink e and give back its place (lock held). */
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
}

/* Drop a reference (lock held); returns e if it was the last. */
static srv_entry *unref(srv_entry *e)
{
	return --e->refs == 0 ? e : NULL;
}

/* Remove the oldest published entry evictable accepts (lock held);
 * returns it if that dropped its last reference. 0 in *found if none. */
static srv_entry *evict(srv_registry *reg, int (*evictable)(srv_entry *),
			int *found)
{
	srv_entry *victim = NULL;
	for (srv_entry *e = reg->head; evictable && e; e = e->next)
		if (e->published && evictable(e))
			victim = e; /* newest first: the last is the oldest */
	*found = victim != NULL;
	if (!victim)
		return NULL;
	unlink_entry(reg, victim);
	return unref(victim);
}

int srv_registry_reserve(srv_registry *reg, srv_entry *e,
			 int (*evictable)(srv_entry *e))
{
	srv_entry *dead = NULL;
	int room = 1;
	pthread_mutex_lock(&reg->lock);
	if (reg->count >= reg->cap)
		dead = evict(reg, evictable, &room);
	if (room && e->id[0] && find(reg, e->id))
		room = 0; /* a restored id that is taken already */
	if (room) {
		while (!e->id[0] || find(reg, e->id))
			srv_new_id(e->id);
		e->refs = 0;
		e->published = 0;
		e->next = reg->head;
		reg->head = e;
		reg->count++;
	}
	pthread_mutex_unlock(&reg->lock);
	if (dead)
		reg->destroy(dead);
	return room ? 0 : -1;
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
