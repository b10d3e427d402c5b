/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * advance_cost.c - what the simulation of a default session costs in the
 * daemon's pattern against one long run, in one process (`make
 * bench-advance-cost`, tests/bench/advance_cost.sh): czubak2016 with the
 * defaults, its shadow over before the measure starts, then
 *
 *   long      one sim_advance over the whole span
 *   chunks    sim_advance to every sample time (250 a simulated second)
 *   sampled   the same, and each sample read out as a worker does:
 *             sim_get_status, sim_column_displacement, sim_feed_state
 *   sessions  N such sampled instances stepped in turn, 0.1 simulated s
 *             each (a paced worker's batch), so that each batch finds its
 *             instance's memory as hundreds of sessions leave it
 *
 * Usage: advance_cost MODE SECONDS [N]; prints one line: the mode and
 * the CPU s (CLOCK_PROCESS_CPUTIME_ID) per simulated s of one instance.
 * The script runs the modes in turns and under callgrind (instructions,
 * which the machine's other load does not change).
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim.h"

#define SAMPLE_RATE 250.0
#define BATCH 0.1
#define START 2.0 /* s: past the shadow's 40 periods (1.6 s) */

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* One instance's arrays of a sample's read-out. */
typedef struct readout {
	sim_status st;
	double *feed;
	int columns, layers;
} readout;

static void read_out(sim *s, readout *r)
{
	size_t n = (size_t)r->columns * (size_t)r->layers;
	sim_get_status(s, &r->st);
	sim_column_displacement(s, r->feed);
	sim_feed_state(s, r->feed + r->columns, r->feed + r->columns + n);
}

/* Advance s from t0 over span, every sample (read out with r). */
static int advance_sampled(sim *s, double t0, double span, readout *r)
{
	long n = (long)(span * SAMPLE_RATE + 0.5);
	for (long i = 1; i <= n; i++) {
		if (sim_advance(s, t0 + (double)i / SAMPLE_RATE) != SIM_OK)
			return -1;
		if (r)
			read_out(s, r);
	}
	return 0;
}

/* The measured part, apart for callgrind's --toggle-collect. */
__attribute__((noinline)) int measured(const char *mode, sim **S, int N, double T, readout *r)
{
	if (strcmp(mode, "long") == 0)
		return sim_advance(S[0], START + T) == SIM_OK ? 0 : -1;
	if (strcmp(mode, "chunks") == 0)
		return advance_sampled(S[0], START, T, NULL);
	if (strcmp(mode, "sampled") == 0)
		return advance_sampled(S[0], START, T, r);
	for (double t = START; t < START + T - 1e-9; t += BATCH)
		for (int i = 0; i < N; i++)
			if (advance_sampled(S[i], t, BATCH, &r[i]))
				return -1;
	return 0;
}

int main(int argc, char **argv)
{
	if (argc < 3) {
		fprintf(stderr, "usage: advance_cost long|chunks|sampled|sessions SECONDS [N]\n");
		return 2;
	}
	const char *mode = argv[1];
	double T = atof(argv[2]);
	int N = strcmp(mode, "sessions") == 0 && argc > 3 ? atoi(argv[3]) : 1;
	if (N < 1 || !(T > 0))
		return 2;
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	sim **S = calloc((size_t)N, sizeof *S);
	readout *r = calloc((size_t)N, sizeof *r);
	if (!S || !r)
		return 1;
	for (int i = 0; i < N; i++) {
		int err = 0;
		char msg[256] = "";
		S[i] = sim_new(&p, &sc, &m, &err, msg, sizeof msg);
		if (!S[i] || sim_advance(S[i], START) != SIM_OK) {
			fprintf(stderr, "advance_cost: %s\n", msg);
			return 1;
		}
		r[i].columns = sim_columns(S[i]);
		r[i].layers = sim_layers(S[i]);
		r[i].feed = calloc((size_t)r[i].columns * (1 + 2 * (size_t)r[i].layers) + 1,
				   sizeof(double));
		if (!r[i].feed)
			return 1;
	}
	double c0 = cpu_now();
	if (measured(mode, S, N, T, r))
		return 1;
	double c = cpu_now() - c0;
	sim_status st;
	sim_get_status(S[0], &st);
	printf("%s %d %.4f %.9g\n", mode, N, 1e3 * c / (T * N), st.transport_velocity);
	for (int i = 0; i < N; i++) {
		sim_free(S[i]);
		free(r[i].feed);
	}
	free(S);
	free(r);
	return 0;
}
