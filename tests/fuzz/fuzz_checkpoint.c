/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_checkpoint.c - libFuzzer harness of the core's checkpoint reader,
 * sim_restore (core/checkpoint.c), on the instances the daemon checkpoints.
 *
 * Input: byte 0 picks the instance the checkpoint is read for (bits 0-2:
 * one of the models below) and whether the harness first writes the
 * right checksum into the header (bit 7), so that mutated payloads get
 * past the checksum and reach the checks behind it; the rest is the
 * checkpoint buffer. Oracles: a refusal is SIM_ECHECKPOINT with a reason
 * (any other code only for a model the core refuses); an instance that is
 * restored is checkpointed again, restored again, checkpointed again, and
 * the two buffers are identical (the restore keeps everything it read);
 * then it is stepped for a few steps, which must not crash and leaves it
 * running or failed with a reason.
 *
 * FUZZ_SEEDS=DIR writes one real checkpoint per model (taken 0.05 s into
 * a run, after a beta ramp began) into DIR and exits: the committed seeds
 * of tests/fuzz/corpus/checkpoint were made so.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "units.h"

typedef struct model {
	const char *method;
	int feed;
	int columns;
} model;

/* The integrators the daemon offers, with and without feed (dem needs
 * it), on the czubak2016 preset. */
static const model models[] = {
	{"dem", 1, 0}, {"rk4", 1, 4}, {"dopri5", 1, 4}, {"euler", 1, 4},
	{"rk4", 0, 0}, {"dopri5", 0, 0}, {"euler", 0, 0}, {"dem", 1, 2},
};
#define NMODELS (sizeof models / sizeof *models)

typedef struct setup {
	sim_params p;
	sim_scene sc;
	sim_method m;
} setup;
static setup setups[NMODELS];

static void make_setup(size_t i)
{
	setup *u = &setups[i];
	char msg[256];
	FUZZ_CHECK(sim_preset("czubak2016", &u->p, &u->sc, &u->m) == SIM_OK, "no preset");
	FUZZ_CHECK(sim_set_str(&u->p, &u->sc, &u->m, "method", models[i].method, msg,
			       sizeof msg) == SIM_OK, "%s", msg);
	u->sc.feed = models[i].feed;
	u->sc.start = SIM_START_REST; /* the layout is the same; the seeds come quicker */
	if (models[i].columns)
		u->sc.columns = models[i].columns;
	FUZZ_CHECK(sim_validate(&u->p, &u->sc, &u->m, msg, sizeof msg) == SIM_OK, "model %zu: %s",
		   i, msg);
}

/* The checkpoint of s (malloc'd, its length in *len). */
static char *checkpoint_of(const sim *s, size_t *len)
{
	*len = sim_checkpoint_size(s);
	char *buf = malloc(*len);
	FUZZ_CHECK(buf, "out of memory");
	FUZZ_CHECK(sim_checkpoint(s, buf, *len) == SIM_OK, "sim_checkpoint refused its own size");
	return buf;
}

static void write_seeds(const char *dir)
{
	for (size_t i = 0; i < NMODELS; i++) {
		const setup *u = &setups[i];
		char msg[256], path[512];
		int err;
		sim *s = sim_new(&u->p, &u->sc, &u->m, &err, msg, sizeof msg);
		FUZZ_CHECK(s, "model %zu: %s", i, msg);
		FUZZ_CHECK(sim_advance(s, 0.02) == SIM_OK, "model %zu does not run", i);
		FUZZ_CHECK(sim_set_beta(s, 120 * RAD_PER_DEG, 0) == SIM_OK, "beta refused");
		FUZZ_CHECK(sim_advance(s, 0.05) == SIM_OK, "model %zu does not run", i);
		size_t len;
		char *buf = checkpoint_of(s, &len);
		snprintf(path, sizeof path, "%s/%s-%s%s.bin", dir, models[i].method,
			 models[i].feed ? "feed" : "nofeed", models[i].columns == 2 ? "-2" : "");
		FILE *f = fopen(path, "wb");
		FUZZ_CHECK(f, "cannot write %s", path);
		unsigned char pick = (unsigned char)(i | 0x80); /* checksum fixed up */
		FUZZ_CHECK(fwrite(&pick, 1, 1, f) == 1 && fwrite(buf, 1, len, f) == len &&
				   fclose(f) == 0,
			   "cannot write %s", path);
		free(buf);
		sim_free(s);
	}
}

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc;
	(void)argv;
	for (size_t i = 0; i < NMODELS; i++)
		make_setup(i);
	const char *dir = getenv("FUZZ_SEEDS");
	if (dir) {
		write_seeds(dir);
		exit(0);
	}
	return 0;
}

/* Checkpoint -> restore -> checkpoint gives the same bytes. */
static void round_trip(const setup *u, const sim *s)
{
	size_t len1, len2;
	char *one = checkpoint_of(s, &len1);
	char msg[256] = "";
	int err;
	sim *again = sim_restore(&u->p, &u->sc, &u->m, one, len1, &err, msg, sizeof msg);
	FUZZ_CHECK(again, "a checkpoint of a restored instance is refused: %s", msg);
	char *two = checkpoint_of(again, &len2);
	FUZZ_CHECK(len1 == len2 && memcmp(one, two, len1) == 0,
		   "checkpoint -> restore -> checkpoint changed the bytes");
	free(one);
	free(two);
	sim_free(again);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	if (size < 1)
		return 0;
	const setup *u = &setups[(data[0] & 7) % NMODELS];
	char *buf = fuzz_exact(data + 1, size - 1);
	if (data[0] & 0x80)
		fuzz_fix_checksum(buf, size - 1, FUZZ_CKPT_PAYLOAD, FUZZ_CKPT_CHECKSUM,
				  FUZZ_CKPT_HEADER);
	char msg[256] = "";
	int err = -1;
	sim *s = sim_restore(&u->p, &u->sc, &u->m, buf, size - 1, &err, msg, sizeof msg);
	free(buf);
	if (!s) {
		FUZZ_CHECK(err == SIM_ECHECKPOINT && strncmp(msg, "checkpoint refused: ", 20) == 0,
			   "refused with code %d: %s", err, msg);
		fuzz_refused("sim_restore", msg);
		return 0;
	}
	FUZZ_CHECK(err == SIM_OK, "restored with code %d", err);
	round_trip(u, s);
	sim_status st;
	sim_get_status(s, &st);
	/* a few steps of the instance's own size on from the checkpoint */
	double h = st.dt > 0 && isfinite(st.dt) ? st.dt : 1e-4;
	int rc = sim_advance(s, st.t + 4 * h);
	FUZZ_CHECK(rc == SIM_OK || rc == SIM_ETIME || rc == SIM_EDIVERGED || rc == SIM_ESTEP,
		   "sim_advance gave %d", rc);
	if (rc == SIM_EDIVERGED || rc == SIM_ESTEP)
		FUZZ_CHECK(sim_last_error(s)[0], "failed without a reason");
	sim_free(s);
	return 0;
}
