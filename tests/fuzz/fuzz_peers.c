/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_peers.c - libFuzzer harness of what a replica takes from its
 * --peers (server/base/peers.c, api/list_json.c): a peer's whole HTTP
 * answer to GET /api/v1/KIND?scope=local (srv_peer_answer: the status
 * line, the head, the body) merged into this replica's own listing
 * (api_list_new, api_list_add, api_list_unreachable, api_list_finish).
 *
 * Input: byte 0 picks the listing (bits 0-1: sessions, experiments,
 * sweeps, fits; bit 2: CSV); the rest is the peer's answer as it came off
 * the socket. Oracles: a refused answer says why and leaves the listing
 * this replica's own (JSON: with the peer named under "unreachable"); an
 * accepted one adds exactly the peer's entries (this replica's own
 * listings are api/'s, empty), each an object with an
 * "id" (JSON), or its rows, each of the header's fields, on lines of
 * their own (CSV); the merged text is a listing of the same kind again.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "api_jobs.h"
#include "peers.h"

static const char *const members[4] = {"sessions", "experiments", "sweeps", "fits"};

/* This replica's own listings, empty (api/'s own texts: the headers a
 * peer's CSV must repeat); made once. */
static char *local_json[4], *local_csv[4];

static void locals(void)
{
	if (local_json[0])
		return;
	local_json[0] = api_session_list_json(NULL, 0);
	local_json[1] = api_experiment_list_json(NULL, 0);
	local_json[2] = api_sweep_list_json(NULL, 0);
	local_json[3] = api_fit_list_json(NULL, 0);
	local_csv[0] = api_session_csv(NULL, 0);
	local_csv[1] = api_experiment_csv(NULL, 0);
	local_csv[2] = api_sweep_list_csv(NULL, 0);
	local_csv[3] = api_fit_list_csv(NULL, 0);
	for (int k = 0; k < 4; k++)
		FUZZ_CHECK(local_json[k] && local_csv[k], "out of memory");
}

/* The entries of a JSON listing's member array (-1: not such a listing). */
static int json_entries(const char *text, size_t len, const char *member, int check_ids)
{
	cJSON *root = cJSON_ParseWithLength(text, len);
	cJSON *items = cJSON_GetObjectItemCaseSensitive(root, member);
	int n = cJSON_IsArray(items) ? cJSON_GetArraySize(items) : -1;
	const cJSON *it;
	if (n >= 0 && check_ids)
		cJSON_ArrayForEach(it, items) {
			const cJSON *id = cJSON_GetObjectItemCaseSensitive(it, "id");
			FUZZ_CHECK(cJSON_IsObject(it) && cJSON_IsString(id) && id->valuestring[0] &&
					   strlen(id->valuestring) < 64,
				   "a merged %s entry without its id", member);
		}
	cJSON_Delete(root);
	return n;
}

static void check_json(const char *text, const char *member, const char *body, size_t blen,
		       int ok)
{
	cJSON *root = cJSON_Parse(text);
	FUZZ_CHECK(root, "the merged listing is not JSON: %.200s", text);
	const cJSON *unreachable = cJSON_GetObjectItemCaseSensitive(root, "unreachable");
	FUZZ_CHECK(ok ? !unreachable : cJSON_GetArraySize(unreachable) == 1,
		   "the peer is named unreachable %s", ok ? "though taken" : "not once");
	cJSON_Delete(root);
	int n = json_entries(text, strlen(text), member, 1);
	int peer = ok ? json_entries(body, blen, member, 0) : 0;
	FUZZ_CHECK(peer >= 0 && n == peer, "%d %s merged, %d the peer's", n, member, peer);
}

/* Every line of text ends with a newline and has the first line's commas. */
static void check_csv(const char *text, const char *local, const char *body, size_t blen, int ok)
{
	size_t own = strlen(local), len = strlen(text);
	FUZZ_CHECK(strncmp(text, local, own) == 0, "the merged CSV does not start with our own");
	if (!ok) {
		FUZZ_CHECK(len == own, "a refused peer's CSV changed the listing");
		return;
	}
	size_t head = strchr(local, '\n') - local + 1, rows = blen - head;
	FUZZ_CHECK(len == own + rows + (rows && body[blen - 1] != '\n'),
		   "the peer's rows are not all merged, or more is");
	FUZZ_CHECK(memcmp(text + own, body + head, rows) == 0, "the peer's rows changed");
	size_t fields = 0;
	for (size_t i = 0; local[i] != '\n'; i++)
		fields += local[i] == ',';
	for (const char *line = text; *line;) {
		const char *nl = strchr(line, '\n');
		FUZZ_CHECK(nl, "a merged CSV line without its newline");
		size_t commas = 0;
		for (const char *c = line; c < nl; c++)
			commas += *c == ',';
		FUZZ_CHECK(nl > line && commas == fields, "a merged CSV row of %zu fields, not %zu",
			   commas + 1, fields + 1);
		line = nl + 1;
	}
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1)
		return 0;
	locals();
	int kind = data[0] & 3, csv = (data[0] >> 2) & 1;
	size_t n = size - 1;
	char *buf = malloc(n + 1); /* srv_peer_answer ends it with a NUL */
	FUZZ_CHECK(buf, "out of memory");
	memcpy(buf, data + 1, n);
	char reason[96] = "";
	size_t blen = 0;
	const char *body = srv_peer_answer(buf, n, &blen, reason, sizeof reason);
	if (body)
		FUZZ_CHECK(body >= buf && body + blen == buf + n && !reason[0],
			   "a body outside the answer, or a reason with it");
	else
		FUZZ_CHECK(reason[0], "an answer refused without a reason");
	const char *local = csv ? local_csv[kind] : local_json[kind];
	api_list *l = api_list_new(members[kind], csv, local);
	FUZZ_CHECK(l, "our own %s listing is refused", members[kind]);
	int ok = body && api_list_add(l, body, blen) == 0;
	if (!ok) {
		fuzz_refused("the peer's answer", body ? "not a listing of its kind" : reason);
		api_list_unreachable(l, "http://127.0.0.1:1", body ? "not a list" : reason);
	}
	char *text = api_list_finish(l);
	FUZZ_CHECK(text, "out of memory");
	if (csv)
		check_csv(text, local, body, blen, ok);
	else
		check_json(text, members[kind], body, blen, ok);
	free(text);
	free(buf);
	return 0;
}
