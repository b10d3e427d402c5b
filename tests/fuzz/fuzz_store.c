/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_store.c - libFuzzer harness of the daemon's stored-session reader:
 * a session's spec.bin and checkpoint.bin as a restart reads them back
 * (docs/operations.md "Persistence"): the frame (srv_store_unframe: magic, version,
 * kind, length, checksum), the spec record (srv_spec_decode, which checks
 * the spec with api_check_spec), the checkpoint's head (srv_ckpt_decode)
 * and the core's checkpoint behind it (sim_restore, for that spec).
 *
 * Input: byte 0 holds flags (bit 0: the harness writes the right frame
 * checksums first, bit 1: and the core checkpoint's, so that mutations
 * reach the checks behind them), bytes 1-4 the length L of the spec file
 * (little-endian), then L bytes of spec.bin and the rest checkpoint.bin.
 * Oracles: a file that is refused says why; one that is accepted, framed
 * again, is the same bytes (but the unused pad); an accepted spec, written back as a create
 * body by the API's writer, is accepted by POST /sessions' parser and is
 * the same spec; the experiment a checkpoint carries, resumed
 * (srv_exp_resume), serves its document running; a restored instance steps
 * (running, or failed with a reason). The committed seeds are real files
 * of a daemon run with --data-dir.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "experiment.h"
#include "fuzz_util.h"
#include "session_int.h"
#include "store.h"

/* The experiment a checkpoint carries (its head's exp_len bytes), resumed
 * on an experiment listed damaged, as a restart resumes it on the one of
 * experiments/ (srv_exp_resume); resumed, it serves a JSON document in
 * state "running" with that experiment's id. */
static void resume_experiment(const char *p, size_t len)
{
	static const char id[] = "0123456789abcdef";
	srv_experiment *e = srv_exp_damaged(id, "stands for the record of experiments/");
	FUZZ_CHECK(e, "out of memory");
	srv_entry *en = srv_exp_entry(e);
	char *copy = fuzz_exact((const uint8_t *)p, len);
	int rc = srv_exp_resume(e, copy, len);
	free(copy);
	if (rc == 0) {
		char state[32];
		fuzz_job_document(&srv_experiment_job, en, id, state, sizeof state);
		FUZZ_CHECK(strcmp(state, "running") == 0, "a resumed experiment in state '%s'", state);
	} else {
		fuzz_refused("srv_exp_resume", "its experiment");
	}
	srv_experiment_job.reg->destroy(en);
}

static void restore(const api_spec *spec, char *p, size_t len, int fix_core)
{
	srv_ckpt_record r;
	char why[256] = "";
	if (srv_ckpt_decode(p, len, &r, why, sizeof why) != 0) {
		FUZZ_CHECK(why[0], "a checkpoint head refused without a reason");
		fuzz_refused("srv_ckpt_decode", why);
		return;
	}
	FUZZ_CHECK(r.state >= SRV_RUNNING && r.state <= SRV_FAILED &&
			   (sizeof r + r.exp_len + r.sim_len == len ||
			    sizeof r + r.exp_len + r.sim_len + SRV_CKPT_TRAILER == len),
		   "checkpoint head accepted with state %d, lengths %zu + %llu + %llu of %zu",
		   (int)r.state, sizeof r, (unsigned long long)r.exp_len,
		   (unsigned long long)r.sim_len, len);
	if (r.exp_len > 0)
		resume_experiment(p + sizeof r, r.exp_len);
	char *core = p + sizeof r + r.exp_len;
	if (fix_core)
		fuzz_fix_checksum(core, r.sim_len, FUZZ_CKPT_PAYLOAD, FUZZ_CKPT_CHECKSUM,
				  FUZZ_CKPT_HEADER);
	char msg[256] = "";
	int err;
	sim *s = sim_restore(&spec->params, &spec->scene, &spec->method, core, r.sim_len, &err, msg,
			     sizeof msg);
	if (!s) {
		FUZZ_CHECK(err == SIM_ECHECKPOINT && msg[0], "sim_restore gave %d: %s", err, msg);
		fuzz_refused("sim_restore", msg);
		return;
	}
	sim_status st;
	sim_get_status(s, &st);
	/* two steps of the instance's own size, whatever the spec's dt */
	double h = st.dt > 0 && isfinite(st.dt) ? st.dt : 1e-4;
	int rc = sim_advance(s, st.t + 2 * h);
	if (rc == SIM_EDIVERGED || rc == SIM_ESTEP)
		FUZZ_CHECK(sim_last_error(s)[0], "failed without a reason");
	sim_free(s);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 5)
		return 0;
	uint32_t spec_len = (uint32_t)data[1] | (uint32_t)data[2] << 8 |
			    (uint32_t)data[3] << 16 | (uint32_t)data[4] << 24;
	if (spec_len > size - 5) {
		fuzz_refused("store seed", "spec length beyond the input");
		return 0;
	}
	size_t plen;
	char *payload = fuzz_unframe(data + 5, spec_len, SRV_STORE_SESSION, data[0] & 1, &plen);
	if (!payload)
		return 0;
	api_spec spec, again;
	double created;
	int owned;
	char why[256] = "";
	int rc = srv_spec_decode(payload, plen, &spec, &created, &owned, why, sizeof why);
	free(payload);
	if (rc != 0) {
		FUZZ_CHECK(why[0], "a spec refused without a reason");
		fuzz_refused("srv_spec_decode", why);
		return 0;
	}
	char *text = fuzz_print(fuzz_spec_body(&spec, 1));
	api_problem pb;
	FUZZ_CHECK(api_parse_session(text, strlen(text), &again, &pb) == API_OK,
		   "a restored spec written back is refused: %s\n%s", pb.detail, text);
	fuzz_same_spec(&spec, &again, 1, "restored spec");
	free(text);
	size_t rest = size - 5 - spec_len;
	payload = fuzz_unframe(data + 5 + spec_len, rest, SRV_STORE_CHECKPOINT, data[0] & 1, &plen);
	if (payload)
		restore(&spec, payload, plen, data[0] & 2);
	free(payload);
	return 0;
}
