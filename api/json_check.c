/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * json_check.c - the strict reading of a request body, before cJSON sees
 * it. cJSON is lenient: it reads `01` and `1.` as numbers, stops a string
 * at a raw NUL, passes control bytes and invalid UTF-8 through, and keeps
 * the first of two members of the same name. A body is checked here
 * against the grammar of RFC 8259 (numbers, strings, literals, whitespace)
 * and the rules of I-JSON, RFC 7493 (UTF-8 only, no unpaired surrogate
 * escapes, no two members of one object with the same name after their
 * escapes are decoded), so that what JSON forbids is refused with the byte
 * where it starts and cJSON only ever reads valid text. One thing JSON
 * allows is refused too: a string whose decoded value holds U+0000
 * (written `\u0000`), which cJSON's C strings would cut there.
 *
 * The check is linear in the body: to find the same name given twice,
 * the names of an object are sorted by the hash of their code points
 * (radix passes), then names of one hash by their code points (merge
 * sort), so that no choice of names, colliding hashes included, costs
 * more than n log n comparisons.
 */
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"

/* Deeper than any body the API reads (a fit's points are two levels). */
#define CHECK_DEPTH 64

/* A member's name inside an object: where its text starts (after the
 * quote) and the hash of its decoded code points. */
typedef struct seen_name {
	uint32_t start, hash;
} seen_name;

typedef struct checker {
	const unsigned char *s;
	size_t len, at;
	const char *why; /* what is wrong at `where`; NULL while valid */
	size_t where;
	int json_ok;   /* the fault is one JSON allows (U+0000) */
	char name[48]; /* the duplicated member's name, cut */
	/* the names of the open objects, innermost last, and room as large
	 * for sorting them (one allocation, freed at the end) */
	seen_name *names, *sorted;
	size_t n_names, cap_names;
} checker;

static int fail_at(checker *c, size_t where, const char *why)
{
	if (!c->why) {
		c->why = why;
		c->where = where;
	}
	return -1;
}

static void skip_ws(checker *c)
{
	while (c->at < c->len && (c->s[c->at] == ' ' || c->s[c->at] == '\t' ||
				  c->s[c->at] == '\n' || c->s[c->at] == '\r'))
		c->at++;
}

static int hex_digit(unsigned char h)
{
	return h >= '0' && h <= '9'   ? h - '0'
	       : h >= 'a' && h <= 'f' ? h - 'a' + 10
	       : h >= 'A' && h <= 'F' ? h - 'A' + 10
				      : -1;
}

/* The 4 hex digits at s[at..] as a code unit, -1 if they are not. */
static long hex4(const unsigned char *s, size_t len, size_t at)
{
	if (len - at < 4)
		return -1;
	long v = 0;
	for (size_t i = 0; i < 4; i++) {
		int d = hex_digit(s[at + i]);
		if (d < 0)
			return -1;
		v = v * 16 + d;
	}
	return v;
}

/* The next code point of a string already checked (at just past the
 * opening quote or a previous code point); -1 at the closing quote. */
static long next_code_point(const unsigned char *s, size_t len, size_t *at)
{
	size_t i = *at;
	if (s[i] == '"')
		return -1;
	if (s[i] != '\\') {
		size_t n = api_utf8_seq(s + i, len - i);
		long cp = n == 1 ? s[i] : s[i] & (0x7f >> n);
		for (size_t k = 1; k < n; k++)
			cp = cp << 6 | (s[i + k] & 0x3f);
		*at = i + n;
		return cp;
	}
	static const char esc[] = "\"\\/bfnrt", val[] = "\"\\/\b\f\n\r\t";
	if (s[i + 1] != 'u') {
		*at = i + 2;
		return val[strchr(esc, s[i + 1]) - esc];
	}
	long cp = hex4(s, len, i + 2);
	*at = i + 6;
	if (cp >= 0xd800 && cp <= 0xdbff) {
		cp = 0x10000 + ((cp - 0xd800) << 10) + (hex4(s, len, i + 8) - 0xdc00);
		*at = i + 12;
	}
	return cp;
}

/* Check the string whose opening quote is at c->at; leaves c->at past
 * the closing quote and *hash the FNV-1a hash of its code points. */
static int check_string(checker *c, uint32_t *hash)
{
	size_t open = c->at++;
	uint32_t h = 2166136261u;
	for (;;) {
		if (c->at >= c->len)
			return fail_at(c, open, "a string is not closed");
		unsigned char b = c->s[c->at];
		size_t here = c->at;
		long cp;
		if (b == '"') {
			c->at++;
			break;
		}
		if (b < 0x20)
			return fail_at(c, here, "a control character (U+0000 to "
						"U+001F) inside a string must be "
						"escaped");
		if (b == '\\') {
			if (c->at + 1 >= c->len ||
			    !strchr("\"\\/bfnrtu", c->s[c->at + 1]) ||
			    c->s[c->at + 1] == '\0')
				return fail_at(c, here, "an invalid escape inside "
							"a string");
			if (c->s[c->at + 1] == 'u') {
				long u = hex4(c->s, c->len, c->at + 2);
				if (u < 0)
					return fail_at(c, here, "\\u needs four "
								"hex digits");
				if (u == 0) {
					fail_at(c, here, "a string may not hold "
							 "U+0000 (\\u0000)");
					c->json_ok = 1;
					return -1;
				}
				if (u >= 0xdc00 && u <= 0xdfff)
					return fail_at(c, here, "an unpaired "
								"surrogate escape");
				if (u >= 0xd800 && u <= 0xdbff) {
					long lo = c->len - c->at >= 12 &&
							  c->s[c->at + 6] == '\\' &&
							  c->s[c->at + 7] == 'u'
						  ? hex4(c->s, c->len, c->at + 8)
						  : -1;
					if (lo < 0xdc00 || lo > 0xdfff)
						return fail_at(c, here, "an unpaired "
									"surrogate escape");
				}
			}
		} else if (api_utf8_seq(c->s + c->at, c->len - c->at) == 0) {
			return fail_at(c, here, "invalid UTF-8 inside a string");
		}
		cp = next_code_point(c->s, c->len, &c->at);
		for (int k = 0; k < 4; k++) {
			h ^= (uint32_t)(cp >> (8 * k)) & 0xff;
			h *= 16777619u;
		}
	}
	if (hash)
		*hash = h;
	return 0;
}

/* The order of the code points of two checked strings starting at a and
 * b (past their quotes): <0, 0 (the same name) or >0. */
static int code_point_order(const checker *c, size_t a, size_t b)
{
	for (;;) {
		long x = next_code_point(c->s, c->len, &a);
		long y = next_code_point(c->s, c->len, &b);
		if (x != y)
			return x < y ? -1 : 1;
		if (x < 0)
			return 0;
	}
}

/* The order of two names: by hash, then by code points, then by place. */
static int name_order(const checker *c, const seen_name *a, const seen_name *b)
{
	if (a->hash != b->hash)
		return a->hash < b->hash ? -1 : 1;
	int o = code_point_order(c, a->start, b->start);
	if (o)
		return o;
	return a->start < b->start ? -1 : a->start > b->start;
}

/* Sort n names (tmp: room for n more) bottom-up by name_order: n log n
 * comparisons whatever the names. */
static void merge_sort_names(const checker *c, seen_name *v, seen_name *tmp, size_t n)
{
	seen_name *from = v, *to = tmp;
	for (size_t width = 1; width < n; width *= 2) {
		for (size_t lo = 0; lo < n; lo += 2 * width) {
			size_t mid = lo + width < n ? lo + width : n;
			size_t hi = lo + 2 * width < n ? lo + 2 * width : n;
			size_t i = lo, j = mid, k = lo;
			while (i < mid && j < hi)
				to[k++] = name_order(c, &from[j], &from[i]) < 0
						  ? from[j++]
						  : from[i++];
			while (i < mid)
				to[k++] = from[i++];
			while (j < hi)
				to[k++] = from[j++];
		}
		seen_name *t = from;
		from = to;
		to = t;
	}
	if (from != v)
		memcpy(v, from, n * sizeof *v);
}

/* Sort n names (tmp: room for n more) by name_order: by hash in four
 * stable passes of 8 bits (the names arrive by place), then each run of
 * one hash by merge sort. Linear unless hashes collide, n log n if all
 * do. */
static void sort_names(const checker *c, seen_name *v, seen_name *tmp, size_t n)
{
	if (n < 64) {
		merge_sort_names(c, v, tmp, n);
		return;
	}
	seen_name *from = v, *to = tmp;
	for (unsigned shift = 0; shift < 32; shift += 8) {
		size_t count[257] = {0};
		for (size_t k = 0; k < n; k++)
			count[((from[k].hash >> shift) & 0xff) + 1]++;
		for (size_t d = 0; d < 256; d++)
			count[d + 1] += count[d];
		for (size_t k = 0; k < n; k++)
			to[count[(from[k].hash >> shift) & 0xff]++] = from[k];
		seen_name *t = from;
		from = to;
		to = t;
	}
	/* four passes: the names are back in v */
	for (size_t lo = 0, hi; lo < n; lo = hi) {
		for (hi = lo + 1; hi < n && v[hi].hash == v[lo].hash; hi++)
			;
		if (hi - lo > 1)
			merge_sort_names(c, v + lo, tmp, hi - lo);
	}
}

/* Add a name to the innermost open object; -1 out of memory. The room
 * is taken once, for as many names as the body can hold (a member takes
 * at least 5 bytes, `"":0,`), so that nothing is copied as it fills. */
static int push_name(checker *c, size_t start, uint32_t hash)
{
	if (!c->names) {
		size_t cap = c->len / 5 + 2;
		c->names = malloc(2 * cap * sizeof *c->names);
		if (!c->names)
			return -1;
		c->sorted = c->names + cap;
		c->cap_names = cap;
	}
	if (c->n_names == c->cap_names) /* cannot happen: the room is the most */
		return -1;
	c->names[c->n_names++] = (seen_name){(uint32_t)start, hash};
	return 0;
}

/* The names of the innermost object, from `first` on (then closed). A
 * name given twice is a fault at its earliest second occurrence, and the
 * first fault in the text. 0: every name once. */
static int check_names(checker *c, size_t first)
{
	size_t n = c->n_names - first;
	c->n_names = first;
	if (n < 2)
		return 0;
	seen_name *v = c->names + first;
	sort_names(c, v, c->sorted, n);
	const seen_name *again = NULL;
	for (size_t k = 1; k < n; k++)
		/* the same name sorts together, by place: v[k] is a second
		 * occurrence when v[k - 1] is the same name */
		if (v[k].hash == v[k - 1].hash &&
		    (!again || v[k].start < again->start) &&
		    code_point_order(c, v[k - 1].start, v[k].start) == 0)
			again = &v[k];
	if (!again)
		return 0;
	/* a fault found before stopped the reading after these names were
	 * read, so this one comes first in the text */
	size_t at = again->start;
	while (next_code_point(c->s, c->len, &at) >= 0)
		;
	size_t len = at - again->start;
	if (len >= sizeof c->name)
		len = sizeof c->name - 1;
	memcpy(c->name, c->s + again->start, len);
	c->name[len] = '\0';
	c->why = "a member's name is given twice in one object";
	c->where = again->start - 1;
	c->json_ok = 0;
	return -1;
}

/* RFC 8259 section 6: -? (0 | [1-9][0-9]*) (. [0-9]+)? ([eE][+-]?[0-9]+)? */
static int check_number(checker *c)
{
	const unsigned char *s = c->s;
	size_t start = c->at, i = c->at;
	if (i < c->len && s[i] == '-')
		i++;
	if (i >= c->len || s[i] < '0' || s[i] > '9')
		return fail_at(c, i, "a number needs a digit here");
	if (s[i] == '0' && i + 1 < c->len && s[i + 1] >= '0' && s[i + 1] <= '9')
		return fail_at(c, start, "a number may not have a leading zero");
	while (i < c->len && s[i] >= '0' && s[i] <= '9')
		i++;
	if (i < c->len && s[i] == '.') {
		if (++i >= c->len || s[i] < '0' || s[i] > '9')
			return fail_at(c, start, "a number's decimal point must "
						 "be followed by a digit");
		while (i < c->len && s[i] >= '0' && s[i] <= '9')
			i++;
	}
	if (i < c->len && (s[i] == 'e' || s[i] == 'E')) {
		if (++i < c->len && (s[i] == '+' || s[i] == '-'))
			i++;
		if (i >= c->len || s[i] < '0' || s[i] > '9')
			return fail_at(c, start, "a number's exponent needs a digit");
		while (i < c->len && s[i] >= '0' && s[i] <= '9')
			i++;
	}
	c->at = i;
	return 0;
}

static int check_value(checker *c, int depth);

/* After a member or an element: ',' (1: another follows) or the closing
 * bracket (0, consumed); -1 for anything else. */
static int next_item(checker *c, unsigned char close)
{
	skip_ws(c);
	if (c->at < c->len && (c->s[c->at] == ',' || c->s[c->at] == close))
		return c->s[c->at++] == ',';
	return fail_at(c, c->at, close == '}' ? "',' or '}' is expected"
					      : "',' or ']' is expected");
}

/* An object: members with distinct names (RFC 7493 section 2.3), checked
 * once its members are read or a fault stopped the reading (a name given
 * twice before that fault is the first fault). */
static int check_object(checker *c, int depth)
{
	size_t first = c->n_names;
	int rc = 0;
	c->at++;
	skip_ws(c);
	if (c->at < c->len && c->s[c->at] == '}') {
		c->at++;
		return 0;
	}
	for (;;) {
		skip_ws(c);
		if (c->at >= c->len || c->s[c->at] != '"') {
			rc = fail_at(c, c->at, "a member's name (a string) is "
					       "expected");
			break;
		}
		size_t start = c->at + 1;
		uint32_t hash;
		if ((rc = check_string(c, &hash)) != 0)
			break;
		if (push_name(c, start, hash) != 0) {
			rc = fail_at(c, start, "out of memory");
			break;
		}
		skip_ws(c);
		if (c->at >= c->len || c->s[c->at] != ':') {
			rc = fail_at(c, c->at, "':' is expected after a member's "
					       "name");
			break;
		}
		c->at++;
		if ((rc = check_value(c, depth + 1)) != 0)
			break;
		int more = next_item(c, '}');
		if (more <= 0) {
			rc = more;
			break;
		}
	}
	if (check_names(c, first) != 0)
		rc = -1;
	return rc;
}

static int check_array(checker *c, int depth)
{
	c->at++;
	skip_ws(c);
	if (c->at < c->len && c->s[c->at] == ']') {
		c->at++;
		return 0;
	}
	int more = 1;
	while (more > 0)
		more = check_value(c, depth + 1) ? -1 : next_item(c, ']');
	return more;
}

static int check_value(checker *c, int depth)
{
	static const char *const literals[] = {"true", "false", "null"};
	skip_ws(c);
	if (depth > CHECK_DEPTH)
		return fail_at(c, c->at, "values are nested too deeply");
	if (c->at >= c->len)
		return fail_at(c, c->at, "a value is expected");
	unsigned char b = c->s[c->at];
	if (b == '{')
		return check_object(c, depth);
	if (b == '[')
		return check_array(c, depth);
	if (b == '"')
		return check_string(c, NULL);
	if (b == '-' || (b >= '0' && b <= '9'))
		return check_number(c);
	for (size_t i = 0; i < 3; i++) {
		size_t n = strlen(literals[i]);
		if (c->len - c->at >= n && memcmp(c->s + c->at, literals[i], n) == 0) {
			c->at += n;
			return 0;
		}
	}
	return fail_at(c, c->at, "a value (object, array, string, number, "
				 "true, false or null) is expected");
}

api_err api_json_check(const char *text, size_t len, api_problem *pb)
{
	checker c = {.s = (const unsigned char *)text, .len = len};
	if (len > UINT32_MAX) /* a name's place is kept in 32 bits */
		fail_at(&c, 0, "the body is larger than 4 GiB");
	else if (check_value(&c, 0) == 0) {
		skip_ws(&c);
		if (c.at < c.len)
			fail_at(&c, c.at, "unexpected text after the JSON value");
	}
	free(c.names);
	if (!c.why)
		return API_OK;
	if (c.json_ok)
		api_fail(pb, API_MALFORMED, NULL,
			 "the request body is refused: %s (no member takes it; "
			 "it would cut the string short) at byte %zu", c.why,
			 c.where);
	else
		api_fail(pb, API_MALFORMED, c.name[0] ? c.name : NULL,
			 "the request body is not valid JSON (RFC 8259, I-JSON): "
			 "%s%s%s%s at byte %zu", c.why, c.name[0] ? " (\"" : "",
			 c.name, c.name[0] ? "\")" : "", c.where);
	pb->has_position = 1;
	pb->position = c.where;
	return API_MALFORMED;
}
