/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * json_out.c - exact JSON text out of api/.
 *
 * cJSON's own printer picks %1.15g and falls back to %1.17g only when a
 * tolerance test fails, so some doubles do not round-trip, and it follows
 * the C locale's decimal point. Here every number is written as the
 * shortest of %.15g, %.16g and %.17g that strtod reads back bit for bit
 * (sim_fmt_double of core/table.h, which the CLI prints with too);
 * non-finite numbers become null. The same growable buffer serves the
 * CSV writers.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"

int api_fmt_double(char *buf, size_t len, double v)
{
	return sim_fmt_double(buf, len, v, "null");
}

int api_fmt_time(char *buf, size_t len, double t)
{
	return sim_fmt_double(buf, len, sim_time_ns(t), "null");
}

void api_buf_put(api_buf *b, const char *s, size_t n)
{
	if (b->failed)
		return;
	if (b->len + n + 1 > b->cap) {
		size_t cap = b->cap ? b->cap : 256;
		while (cap < b->len + n + 1)
			cap *= 2;
		char *t = realloc(b->text, cap);
		if (!t) {
			b->failed = 1;
			return;
		}
		b->text = t;
		b->cap = cap;
	}
	memcpy(b->text + b->len, s, n);
	b->len += n;
	b->text[b->len] = '\0';
}

void api_buf_puts(api_buf *b, const char *s)
{
	api_buf_put(b, s, strlen(s));
}

void api_buf_printf(api_buf *b, const char *fmt, ...)
{
	char small[256];
	va_list ap;
	va_start(ap, fmt);
	int n = vsnprintf(small, sizeof small, fmt, ap);
	va_end(ap);
	if (n < 0) {
		b->failed = 1;
		return;
	}
	if ((size_t)n < sizeof small) {
		api_buf_put(b, small, (size_t)n);
		return;
	}
	char *big = malloc((size_t)n + 1);
	if (!big) {
		b->failed = 1;
		return;
	}
	va_start(ap, fmt);
	vsnprintf(big, (size_t)n + 1, fmt, ap);
	va_end(ap);
	api_buf_put(b, big, (size_t)n);
	free(big);
}

void api_buf_double(api_buf *b, double v)
{
	char num[40];
	int n = api_fmt_double(num, sizeof num, v);
	api_buf_put(b, num, (size_t)n);
}

void api_buf_jstr(api_buf *b, const char *s)
{
	api_buf_put(b, "\"", 1);
	for (const unsigned char *p = (const unsigned char *)s; *p; p++) {
		char esc[8];
		switch (*p) {
		case '"': api_buf_put(b, "\\\"", 2); break;
		case '\\': api_buf_put(b, "\\\\", 2); break;
		case '\n': api_buf_put(b, "\\n", 2); break;
		case '\r': api_buf_put(b, "\\r", 2); break;
		case '\t': api_buf_put(b, "\\t", 2); break;
		default:
			if (*p < 0x20) {
				snprintf(esc, sizeof esc, "\\u%04x", *p);
				api_buf_put(b, esc, 6);
			} else {
				api_buf_put(b, (const char *)p, 1);
			}
		}
	}
	api_buf_put(b, "\"", 1);
}

char *api_buf_take(api_buf *b)
{
	if (b->failed) {
		free(b->text);
		b->text = NULL;
		return NULL;
	}
	if (!b->text)
		api_buf_put(b, "", 0);
	char *t = b->text;
	b->text = NULL;
	b->len = b->cap = 0;
	return t;
}

static void print_item(api_buf *b, const cJSON *it)
{
	const cJSON *c;
	switch (it->type & 0xff) {
	case cJSON_False: api_buf_puts(b, "false"); break;
	case cJSON_True: api_buf_puts(b, "true"); break;
	case cJSON_NULL: api_buf_puts(b, "null"); break;
	case cJSON_Number: api_buf_double(b, it->valuedouble); break;
	case cJSON_String:
		api_buf_jstr(b, it->valuestring ? it->valuestring : "");
		break;
	case cJSON_Raw:
		api_buf_puts(b, it->valuestring ? it->valuestring : "null");
		break;
	case cJSON_Array:
		api_buf_put(b, "[", 1);
		for (c = it->child; c; c = c->next) {
			print_item(b, c);
			if (c->next)
				api_buf_put(b, ",", 1);
		}
		api_buf_put(b, "]", 1);
		break;
	case cJSON_Object:
		api_buf_put(b, "{", 1);
		for (c = it->child; c; c = c->next) {
			api_buf_jstr(b, c->string ? c->string : "");
			api_buf_put(b, ":", 1);
			print_item(b, c);
			if (c->next)
				api_buf_put(b, ",", 1);
		}
		api_buf_put(b, "}", 1);
		break;
	default: api_buf_puts(b, "null");
	}
}

char *api_print(const cJSON *item)
{
	api_buf b = {0};
	if (!item)
		return NULL;
	print_item(&b, item);
	return api_buf_take(&b);
}

char *api_print_free(cJSON *item)
{
	char *text = api_print(item);
	cJSON_Delete(item);
	return text;
}

void api_add_number(cJSON *obj, const char *name, double v)
{
	if (isfinite(v))
		cJSON_AddNumberToObject(obj, name, v);
	else
		cJSON_AddNullToObject(obj, name);
}

void api_add_result_links(cJSON *obj, const char *collection, const char *id)
{
	char link[96];
	cJSON *links = cJSON_AddObjectToObject(obj, "links");
	snprintf(link, sizeof link, "/api/v1/%s/%s", collection, id);
	cJSON_AddStringToObject(links, "self", link);
	snprintf(link, sizeof link, "/api/v1/%s/%s?format=csv", collection, id);
	cJSON_AddStringToObject(links, "csv", link);
}
