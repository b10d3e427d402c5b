/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_jobs.c - libFuzzer harness of the daemon's stored-job readers: a
 * sweep's, a fit's or an experiment's record (sweeps/ID.bin, fits/ID.bin,
 * experiments/ID.bin) as a restart reads it back (server/jobs/job.c
 * restore_one: srv_store_unframe, then the kind's load hook), and the
 * documents the daemon then serves of it.
 *
 * Input: byte 0 picks the kind (bits 0-1: sweep, fit, experiment; 3 is
 * nothing) and bit 2 has the harness write the frame's right checksum
 * first, so that mutations reach the record's checks behind it; the rest
 * is the framed file. Oracles: a file that is refused says why, and the
 * job listed as damaged in its place (the kind's damaged hook, where it has
 * one) serves a JSON document in state "damaged"; an accepted job serves
 * its JSON document (GET /api/v1/{plural}/ID: an object with the file's
 * id), its CSV, and its row of the listing (GET /api/v1/{plural}: an
 * object whose member {plural} is an array of one row with that id). The
 * committed seeds are real files of a daemon run with --data-dir (the
 * release fixtures' data dirs).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "job.h"
#include "store.h"

static const srv_job_kind *const kinds[3] = {&srv_sweep_job, &srv_fit_job,
					     &srv_experiment_job};

/* An accepted job: its document, its CSV and its row of the listing. */
static void check_served(const srv_job_kind *kind, srv_entry *e)
{
	char state[32];
	fuzz_job_document(kind, e, e->id, state, sizeof state);
	FUZZ_CHECK(strcmp(state, "damaged") != 0, "%s %s: accepted but damaged", kind->name,
		   e->id);
	void *view = calloc(1, kind->view_size), *scratch = calloc(1, kind->scratch_size);
	FUZZ_CHECK(view && scratch, "out of memory");
	srv_job_lock(kind, e);
	char *csv = kind->text(e, 1);
	kind->view(e, view, scratch);
	srv_job_unlock(kind, e);
	FUZZ_CHECK(csv, "%s %s: no CSV", kind->name, e->id);
	free(csv);
	char *list = kind->list_text(view, 1, 0);
	cJSON *doc = list ? cJSON_Parse(list) : NULL;
	const cJSON *rows = cJSON_GetObjectItemCaseSensitive(doc, kind->plural);
	const cJSON *jid = cJSON_GetObjectItemCaseSensitive(cJSON_GetArrayItem(rows, 0), "id");
	FUZZ_CHECK(cJSON_IsArray(rows) && cJSON_GetArraySize(rows) == 1 && cJSON_IsString(jid) &&
			   strcmp(jid->valuestring, e->id) == 0,
		   "%s %s: its listing is not one row with its id:\n%s", kind->name, e->id,
		   list ? list : "(none)");
	cJSON_Delete(doc);
	free(list);
	free(scratch);
	free(view);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1 || (data[0] & 3) == 3)
		return 0;
	const srv_job_kind *kind = kinds[data[0] & 3];
	size_t len;
	char *payload = fuzz_unframe(data + 1, size - 1, kind->store_kind, data[0] & 4, &len);
	if (!payload)
		return 0;
	char why[300] = "";
	srv_entry *e = kind->load(payload, len, why, sizeof why); /* takes payload */
	if (e) {
		check_served(kind, e);
		kind->reg->destroy(e);
		return 0;
	}
	FUZZ_CHECK(why[0], "a %s record refused without a reason", kind->name);
	fuzz_refused(kind->name, why);
	if (!kind->damaged)
		return 0;
	static const char id[] = "0123456789abcdef";
	e = kind->damaged(id, why);
	FUZZ_CHECK(e, "out of memory");
	char state[32];
	fuzz_job_document(kind, e, id, state, sizeof state);
	FUZZ_CHECK(strcmp(state, "damaged") == 0, "%s: a damaged job in state '%s'", kind->name,
		   state);
	kind->reg->destroy(e);
	return 0;
}
