/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_route.c - libFuzzer harness of the daemon's path routing,
 * srv_route_resolve (server/http/routes.c): the route table and its "*"
 * segments decide, without libmicrohttpd, whether a method and a path are
 * a route (with its path arguments), a 405 with Allow, a 404 under /api,
 * or a static file.
 *
 * Input: the method up to the first space, the path after it (cut at a
 * NUL byte, as a C string from libmicrohttpd is). Oracles: an independent
 * matcher (paths split at '/', segment by segment) over the API's route
 * table (api/routes.c, which the OpenAPI document is made of) must come to
 * the same answer; a found route's pattern with its arguments put back in
 * is the path again; Allow lists exactly the other methods of the path;
 * the 405 and 404 problems are well-formed.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_routes.h"
#include "fuzz_util.h"
#include "routes.h"

/* Segment i of path p (after its i-th '/'): start and length; 0 if none. */
static int segment(const char *p, int i, const char **at, size_t *n)
{
	if (*p != '/')
		return 0;
	for (int k = 0; k < i; k++) {
		p = strchr(p + 1, '/');
		if (!p)
			return 0;
	}
	*at = p + 1;
	const char *end = strchr(p + 1, '/');
	*n = end ? (size_t)(end - (p + 1)) : strlen(p + 1);
	return 1;
}

static int segments(const char *p)
{
	int n = 0;
	for (; *p; p++)
		n += *p == '/';
	return n;
}

/* The reference: pattern and url have as many segments, literal ones
 * equal, "*" ones 1 to 63 bytes. */
static int ref_match(const char *pattern, const char *url)
{
	if (segments(pattern) != segments(url) || *url != '/')
		return 0;
	for (int i = 0; i < segments(pattern); i++) {
		const char *a, *b;
		size_t na, nb;
		if (!segment(pattern, i, &a, &na) || !segment(url, i, &b, &nb))
			return 0;
		if (na == 1 && *a == '*') {
			if (nb == 0 || nb >= 64)
				return 0;
		} else if (na != nb || memcmp(a, b, na) != 0) {
			return 0;
		}
	}
	return 1;
}

/* The pattern with "*" replaced by the arguments, in order. */
static void fill(const char *pattern, char arg[2][64], char *out, size_t len)
{
	size_t at = 0;
	int k = 0;
	for (const char *p = pattern; *p && at + 1 < len; p++) {
		if (*p == '*' && k < 2)
			at += (size_t)snprintf(out + at, len - at, "%s", arg[k++]);
		else
			out[at++] = *p;
	}
	out[at < len ? at : len - 1] = '\0';
}

static void check(const char *method, const char *url)
{
	srv_route_match m;
	srv_route_resolve(method, url, &m);
	const char *want = strcmp(method, "HEAD") == 0 ? "GET" : method;
	size_t n;
	const api_route *rt = api_routes(&n);
	const api_route *found = NULL;
	char allow[128] = "";
	for (size_t i = 0; i < n; i++) {
		if (!ref_match(rt[i].pattern, url))
			continue;
		if (strcmp(rt[i].method, want) == 0 && !found)
			found = &rt[i];
		else if (strcmp(rt[i].method, want) != 0 && !strstr(allow, rt[i].method)) {
			size_t at = strlen(allow);
			snprintf(allow + at, sizeof allow - at, "%s%s%s", at ? ", " : "",
				 rt[i].method, strcmp(rt[i].method, "GET") == 0 ? ", HEAD" : "");
		}
	}
	api_problem pb;
	switch (m.kind) {
	case SRV_ROUTE_FOUND: {
		FUZZ_CHECK(found && strcmp(m.method, found->method) == 0 &&
				   strcmp(m.pattern, found->pattern) == 0,
			   "%s %s: the server routes to %s %s, the API table to %s", method, url,
			   m.method, m.pattern, found ? found->pattern : "nothing");
		char back[512];
		fill(m.pattern, m.arg, back, sizeof back);
		FUZZ_CHECK(strcmp(back, url) == 0, "%s %s: arguments give back %s", method, url,
			   back);
		return;
	}
	case SRV_ROUTE_METHOD:
		FUZZ_CHECK(!found && allow[0] && strcmp(allow, m.allow) == 0,
			   "%s %s: 405 with Allow \"%s\", the API table says \"%s\"%s", method, url,
			   m.allow, allow, found ? " and finds the route" : "");
		fuzz_check_problem(api_fail(&pb, API_METHOD, NULL, "%s is not allowed on %s; "
						"allowed: %s", method, url, m.allow), &pb);
		return;
	case SRV_ROUTE_NOT_FOUND:
		FUZZ_CHECK(!found && !allow[0] &&
				   (strncmp(url, "/api/", 5) == 0 || strcmp(url, "/api") == 0),
			   "%s %s: 404, but the API table knows the path", method, url);
		fuzz_check_problem(api_fail(&pb, API_NOTFOUND, NULL, "no such resource: %s", url),
				   &pb);
		return;
	case SRV_ROUTE_STATIC_METHOD:
	case SRV_ROUTE_STATIC:
		FUZZ_CHECK(!found && !allow[0] && strncmp(url, "/api/", 5) != 0 &&
				   strcmp(url, "/api") != 0,
			   "%s %s: a static file, but the path is the API's", method, url);
		FUZZ_CHECK((m.kind == SRV_ROUTE_STATIC) == (strcmp(want, "GET") == 0),
			   "%s %s: static with kind %d", method, url, (int)m.kind);
		return;
	}
	fuzz_fail("%s %s: kind %d", method, url, (int)m.kind);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *text = fuzz_string(data, size);
	char *space = strchr(text, ' ');
	if (space) {
		*space = '\0';
		check(text, space + 1);
	}
	free(text);
	return 0;
}
