/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_util.c - the oracles the harnesses share (fuzz_util.h).
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "json_int.h"
#include "store.h"

void fuzz_fail(const char *fmt, ...)
{
	va_list ap;
	va_start(ap, fmt);
	fputs("fuzz oracle: ", stderr);
	vfprintf(stderr, fmt, ap);
	fputc('\n', stderr);
	va_end(ap);
	abort();
}

void fuzz_refused(const char *what, const char *why)
{
	if (getenv("FUZZ_MUST_ACCEPT"))
		fuzz_fail("a committed seed is refused (%s: %s): the seeds are stale, make them "
			  "again (docs/fuzzing.md \"Fuzzing\")",
			  what, why);
}

char *fuzz_exact(const uint8_t *data, size_t size)
{
	char *b = malloc(size ? size : 1);
	FUZZ_CHECK(b, "out of memory");
	if (size)
		memcpy(b, data, size);
	return b;
}

char *fuzz_string(const uint8_t *data, size_t size)
{
	char *b = malloc(size + 1);
	FUZZ_CHECK(b, "out of memory");
	if (size)
		memcpy(b, data, size);
	b[size] = '\0';
	return b;
}

void fuzz_fix_checksum(char *buf, size_t n, size_t len_at, size_t sum_at, size_t size)
{
	if (n < size)
		return;
	uint64_t len;
	memcpy(&len, buf + len_at, sizeof len);
	if (len > n - size)
		return;
	uint64_t sum = sim_checksum(buf + size, (size_t)len);
	memcpy(buf + sum_at, &sum, sizeof sum);
}

/* A char array holds a terminated string. */
static int terminated(const char *s, size_t cap)
{
	return memchr(s, '\0', cap) != NULL;
}

/* A problem's text as written: the same as given when that is ASCII;
 * otherwise bytes that are not valid UTF-8 came back as U+FFFD (docs/operations.md
 * "Security"), so only its being a string is checked. */
static int as_given(const char *written, const char *given)
{
	for (const unsigned char *c = (const unsigned char *)given; *c; c++)
		if (*c >= 0x80)
			return 1;
	return strcmp(written, given) == 0;
}

void fuzz_check_problem(api_err code, const api_problem *pb)
{
	FUZZ_CHECK(code != API_OK && code == pb->code && code < API_NERR,
		   "returned %d, problem code %d", (int)code, (int)pb->code);
	int status = api_status(code);
	FUZZ_CHECK(status >= 400 && status < 600, "status %d for code %d", status, (int)code);
	FUZZ_CHECK(terminated(pb->field, sizeof pb->field) &&
			   terminated(pb->detail, sizeof pb->detail) &&
			   terminated(pb->choices, sizeof pb->choices),
		   "problem strings not terminated");
	FUZZ_CHECK(pb->detail[0], "empty detail (code %d)", (int)code);
	FUZZ_CHECK(!pb->has_range || pb->min <= pb->max, "range [%g, %g]", pb->min, pb->max);
	char *text = api_problem_json(pb, "/fuzz");
	FUZZ_CHECK(text, "api_problem_json gave NULL");
	cJSON *o = cJSON_Parse(text);
	FUZZ_CHECK(cJSON_IsObject(o), "problem body is not a JSON object: %s", text);
	const cJSON *st = cJSON_GetObjectItemCaseSensitive(o, "status");
	FUZZ_CHECK(cJSON_IsNumber(st) && st->valueint == status, "status member: %s", text);
	const cJSON *ty = cJSON_GetObjectItemCaseSensitive(o, "type");
	FUZZ_CHECK(cJSON_IsString(ty) && strncmp(ty->valuestring, "/api/v1/problems/", 17) == 0,
		   "type member: %s", text);
	const cJSON *fi = cJSON_GetObjectItemCaseSensitive(o, "field");
	if (pb->field[0])
		FUZZ_CHECK(cJSON_IsString(fi) && as_given(fi->valuestring, pb->field),
			   "field member: %s", text);
	const cJSON *de = cJSON_GetObjectItemCaseSensitive(o, "detail");
	FUZZ_CHECK(cJSON_IsString(de) && as_given(de->valuestring, pb->detail),
		   "detail member: %s", text);
	cJSON_Delete(o);
	free(text);
}

char *fuzz_print(cJSON *tree)
{
	/* the API's printer: cJSON's own loses the last bit of some doubles */
	char *text = api_print_free(tree);
	FUZZ_CHECK(text, "out of memory");
	return text;
}

cJSON *fuzz_spec_body(const api_spec *spec, int with_until)
{
	api_view v;
	memset(&v, 0, sizeof v);
	snprintf(v.id, sizeof v.id, "0123456789abcdef");
	v.spec = spec;
	v.state = "running";
	v.pace = spec->pace;
	v.until = spec->until;
	char *doc = api_session_json(&v, 1);
	FUZZ_CHECK(doc, "api_session_json gave NULL");
	cJSON *d = cJSON_Parse(doc);
	FUZZ_CHECK(cJSON_IsObject(d), "the session document is not JSON: %s", doc);
	free(doc);
	cJSON *body = cJSON_CreateObject();
	static const char *const top[] = {"preset", "pace", "until", "sample_rate"};
	for (size_t i = 0; i < sizeof top / sizeof *top; i++) {
		if (i == 2 && !with_until)
			continue;
		cJSON *it = cJSON_DetachItemFromObjectCaseSensitive(d, top[i]);
		FUZZ_CHECK(it, "the session document has no %s", top[i]);
		cJSON_AddItemToObject(body, top[i], it);
	}
	cJSON *sp = cJSON_GetObjectItemCaseSensitive(d, "spec");
	static const char *const groups[] = {"params", "scene", "integrator"};
	for (size_t g = 0; g < 3; g++) {
		cJSON *it = cJSON_DetachItemFromObjectCaseSensitive(sp, groups[g]);
		FUZZ_CHECK(cJSON_IsObject(it), "the session document's spec has no %s", groups[g]);
		cJSON_AddItemToObject(body, groups[g], it);
	}
	cJSON_Delete(d);
	return body;
}

/* a and b within 4 ulp of each other (both finite). */
static int near_ulp(double a, double b)
{
	if (a == b)
		return 1;
	double tol = 4 * (nextafter(fabs(a), INFINITY) - fabs(a));
	return fabs(a - b) <= tol;
}

void fuzz_same_spec(const api_spec *a, const api_spec *b, int with_until, const char *what)
{
	FUZZ_CHECK(strcmp(a->preset, b->preset) == 0, "%s: preset %s / %s", what, a->preset,
		   b->preset);
	FUZZ_CHECK(a->pace == b->pace && a->sample_rate == b->sample_rate &&
			   (!with_until || a->until == b->until),
		   "%s: pace %.17g / %.17g, until %.17g / %.17g, sample_rate %.17g / %.17g", what,
		   a->pace, b->pace, a->until, b->until, a->sample_rate, b->sample_rate);
	FUZZ_CHECK(strcmp(a->method.name, b->method.name) == 0, "%s: method %s / %s", what,
		   a->method.name, b->method.name);
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	for (size_t i = 0; i < n; i++) {
		double va, vb;
		if (sim_get(&a->params, &a->scene, &a->method, tab[i].name, &va) != SIM_OK)
			continue;
		FUZZ_CHECK(sim_get(&b->params, &b->scene, &b->method, tab[i].name, &vb) == SIM_OK,
			   "%s: %s readable in one spec only", what, tab[i].name);
		int same = tab[i].scale == 1.0 ? va == vb : near_ulp(va, vb);
		FUZZ_CHECK(same, "%s: %s %.17g / %.17g", what, tab[i].name, va, vb);
	}
}

const api_spec *fuzz_default_spec(void)
{
	static api_spec spec;
	static int made;
	if (!made) {
		api_problem pb;
		FUZZ_CHECK(api_parse_session("{}", 2, &spec, &pb) == API_OK, "{}: %s", pb.detail);
		made = 1;
	}
	return &spec;
}

/* store.c's frame header: magic, version, kind, pad (unused, written as
 * 0), then the payload's length and checksum. */
enum { FRAME_PAD = 12, FRAME_LEN = 16, FRAME_CHECKSUM = 24, FRAME_SIZE = 32 };

char *fuzz_unframe(const uint8_t *data, size_t n, uint32_t kind, int fixed, size_t *plen)
{
	char *buf = fuzz_exact(data, n);
	if (fixed)
		fuzz_fix_checksum(buf, n, FRAME_LEN, FRAME_CHECKSUM, FRAME_SIZE);
	char *copy = fuzz_exact((const uint8_t *)buf, n);
	const char *bad = NULL;
	int older = 0;
	char *payload = srv_store_unframe(buf, n, kind, plen, &older, &bad);
	if (!payload) {
		FUZZ_CHECK(bad && bad[0], "a frame refused without a reason");
		fuzz_refused("srv_store_unframe", bad);
		free(copy);
		return NULL;
	}
	size_t len;
	memset(copy + FRAME_PAD, 0, 4);
	/* an earlier format comes back upgraded (store_v1.c, store_v2.c):
	 * framed again, it is this build's */
	char *again = older ? NULL : srv_store_frame(kind, payload, *plen, &len);
	FUZZ_CHECK(older || (again && len == n && memcmp(again, copy, n) == 0),
		   "an accepted file framed again differs");
	free(again);
	free(copy);
	return payload;
}

void fuzz_job_document(const srv_job_kind *kind, srv_entry *e, const char *id, char *state,
		       size_t statelen)
{
	srv_job_lock(kind, e);
	char *t = kind->text(e, 0);
	srv_job_unlock(kind, e);
	FUZZ_CHECK(t, "%s %s: no JSON document", kind->name, id);
	cJSON *doc = cJSON_Parse(t);
	FUZZ_CHECK(cJSON_IsObject(doc), "%s %s: its document does not parse:\n%s", kind->name, id,
		   t);
	const cJSON *jid = cJSON_GetObjectItemCaseSensitive(doc, "id");
	FUZZ_CHECK(cJSON_IsString(jid) && strcmp(jid->valuestring, id) == 0,
		   "%s: the document's id is not %s:\n%s", kind->name, id, t);
	const cJSON *st = cJSON_GetObjectItemCaseSensitive(doc, "state");
	snprintf(state, statelen, "%s", cJSON_IsString(st) ? st->valuestring : "");
	cJSON_Delete(doc);
	free(t);
}
