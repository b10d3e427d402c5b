/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * list_json.c - one listing gathered from several replicas (--peers): the
 * receiving daemon's own list, then each peer's, in one answer.
 *
 * JSON: the entries of each answer's array member ("sessions", ...) in
 * one array, and "unreachable" naming the peers whose entries are missing.
 * CSV: the first answer's header once, then every answer's rows. A peer's
 * answer that does not have the same shape (not JSON with that array, or
 * another CSV header) is refused, and the caller reports that peer as
 * unreachable instead. The one replica's listing of every kind is written
 * here too (api_list_json).
 */
#include <stdlib.h>
#include <string.h>

#include "json_int.h"

struct api_list {
	int csv;
	cJSON *root, *items, *unreachable; /* JSON */
	api_buf text;                       /* CSV */
	size_t header_len;                  /* CSV: its header line, with '\n' */
};

/* The CSV header's length with its newline (the whole text if none). */
static size_t header_length(const char *text, size_t len)
{
	const char *nl = memchr(text, '\n', len);
	return nl ? (size_t)(nl - text) + 1 : len;
}

api_list *api_list_new(const char *member, int csv, const char *local)
{
	api_list *l = calloc(1, sizeof *l);
	if (!l)
		return NULL;
	l->csv = csv;
	if (csv) {
		api_buf_puts(&l->text, local);
		l->header_len = header_length(local, strlen(local));
		if (!l->text.failed)
			return l;
	} else {
		l->root = cJSON_Parse(local);
		l->items = cJSON_GetObjectItemCaseSensitive(l->root, member);
		if (cJSON_IsArray(l->items))
			return l;
	}
	cJSON_Delete(l->root);
	free(l->text.text);
	free(l);
	return NULL;
}

int api_list_add(api_list *l, const char *body, size_t len)
{
	if (l->csv) {
		size_t h = header_length(body, len);
		if (h != l->header_len || memcmp(body, l->text.text, h) != 0)
			return -1;
		api_buf_put(&l->text, body + h, len - h);
		return l->text.failed ? -1 : 0;
	}
	cJSON *peer = cJSON_ParseWithLength(body, len);
	cJSON *items = cJSON_GetObjectItemCaseSensitive(peer, l->items->string);
	int ok = cJSON_IsArray(items);
	while (ok && items->child) {
		cJSON *it = cJSON_DetachItemViaPointer(items, items->child);
		cJSON_AddItemToArray(l->items, it);
	}
	cJSON_Delete(peer);
	return ok ? 0 : -1;
}

void api_list_unreachable(api_list *l, const char *peer, const char *reason)
{
	if (l->csv)
		return;
	if (!l->unreachable)
		l->unreachable = cJSON_AddArrayToObject(l->root, "unreachable");
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "peer", peer);
	cJSON_AddStringToObject(o, "reason", reason);
	cJSON_AddItemToArray(l->unreachable, o);
}

char *api_list_finish(api_list *l)
{
	if (!l)
		return NULL;
	char *text = l->csv ? api_buf_take(&l->text) : api_print_free(l->root);
	free(l);
	return text;
}

char *api_list_json(const char *member, const void *views, size_t n, size_t size,
		    cJSON *(*entry)(const void *view))
{
	cJSON *o = cJSON_CreateObject();
	cJSON *arr = cJSON_AddArrayToObject(o, member);
	for (size_t i = 0; i < n; i++)
		cJSON_AddItemToArray(arr, entry((const char *)views + i * size));
	return api_print_free(o);
}
