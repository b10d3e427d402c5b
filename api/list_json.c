/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * list_json.c - one listing gathered from several replicas (--peers): the
 * receiving daemon's own list, then each peer's, in one answer.
 *
 * JSON: the entries of each answer's array member ("sessions", ...) in
 * one array, and "unreachable" naming the peers whose entries are missing.
 * CSV: the first answer's header once, then every answer's rows. A peer's
 * answer that does not have the same shape (not JSON with that array of
 * entries, each an object with its "id"; or another CSV header, or a row
 * of another number of fields) is refused whole, and the caller reports
 * that peer as unreachable instead: what one replica sends cannot put
 * into a listing what no replica's own listing holds. The one replica's
 * listing of every kind is written here too (api_list_json).
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

/* The commas of a CSV line (len bytes; the listings quote nothing). */
static size_t commas(const char *line, size_t len)
{
	size_t n = 0;
	for (size_t i = 0; i < len; i++)
		n += line[i] == ',';
	return n;
}

/* Whether rows (len bytes after the header) are lines of the header's
 * fields each: no NUL, carriage return or quote, no empty line. */
static int rows_fit(const char *rows, size_t len, size_t fields)
{
	if (memchr(rows, '\0', len) || memchr(rows, '\r', len) || memchr(rows, '"', len))
		return 0;
	for (size_t at = 0; at < len;) {
		const char *nl = memchr(rows + at, '\n', len - at);
		size_t n = nl ? (size_t)(nl - (rows + at)) : len - at;
		if (n == 0 || commas(rows + at, n) != fields)
			return 0;
		at += n + 1;
	}
	return 1;
}

/* Whether every entry of a peer's array is an object with an "id" of 1
 * to API_LIST_ID_MAX characters, as every replica's own entries are. */
#define API_LIST_ID_MAX 63
static int entries_fit(const cJSON *items)
{
	const cJSON *it;
	cJSON_ArrayForEach(it, items) {
		const cJSON *id = cJSON_GetObjectItemCaseSensitive(it, "id");
		if (!cJSON_IsObject(it) || !cJSON_IsString(id) || !id->valuestring[0] ||
		    strlen(id->valuestring) > API_LIST_ID_MAX)
			return 0;
	}
	return 1;
}

int api_list_add(api_list *l, const char *body, size_t len)
{
	if (l->csv) {
		size_t h = header_length(body, len);
		if (h != l->header_len || memcmp(body, l->text.text, h) != 0 ||
		    !rows_fit(body + h, len - h, commas(body, h)))
			return -1;
		api_buf_put(&l->text, body + h, len - h);
		/* a last row without its newline gets one: the next peer's
		 * rows start on a line of their own */
		if (len > h && body[len - 1] != '\n')
			api_buf_put(&l->text, "\n", 1);
		return l->text.failed ? -1 : 0;
	}
	cJSON *peer = cJSON_ParseWithLength(body, len);
	cJSON *items = cJSON_GetObjectItemCaseSensitive(peer, l->items->string);
	int ok = cJSON_IsArray(items) && entries_fit(items);
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
