/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * workprec.c - work-precision benchmark of the integrators (`make bench`).
 *
 *   workprec scene NAME [quick]   run one scene's reference and ladders,
 *                                 one TSV row per run on stdout
 *   workprec report DIR CMD       read the scenes' TSV files in DIR, write DIR/workprec.md and
 *                                 DIR/workprec.svg (CMD: the command line
 *                                 that made them, printed at the top)
 *
 * Scenes: "nofeed" (the machine without feed, Kloss motor start), "full"
 * (czubak2016: 5 x 8 feed, motor start, beta 38 deg, cw), "reduced" (the
 * same with trough_rotation=false: alpha dropped, one column counting 5
 * times), "reductions" (each model reduction against the full model at
 * equal integrator settings).
 *
 * For every run: CPU seconds per simulated second (CLOCK_PROCESS_CPUTIME_ID,
 * one thread), the RMS distance of the trough's (x, y) from the reference
 * over the first 20 excitation periods (0.8 s of samples every 2 ms, which
 * every fixed step of the ladders divides, so sampling never cuts a step),
 * the transport velocity over [2 s, horizon] and its relative error, and
 * the energy-balance residual at the end.
 *
 * The parts: workprec_run.c (one run and its TSV row), workprec_scenes.c
 * (references and ladders), workprec_report.c (the table and the plot).
 *
 * References. Trajectory: the finest run of two different methods; the
 * RMS distance between them is the reference's uncertainty and is printed.
 * Transport velocity: dem at its finest step, confirmed by Richardson
 * extrapolation of the three finest rk4 runs (observed order from the three,
 * limit from the two finest); both values and their difference are printed.
 */
#include <stdio.h>
#include <string.h>

#include "workprec.h"

int main(int argc, char **argv)
{
	if (argc >= 3 && strcmp(argv[1], "scene") == 0) {
		int quick = argc >= 4 && strcmp(argv[3], "quick") == 0;
		return wp_scene(argv[2], quick) ? 2 : 0;
	}
	if (argc >= 4 && strcmp(argv[1], "report") == 0) {
		wp_report(argv[2], argv[3]);
		return 0;
	}
	fprintf(stderr, "usage: workprec scene nofeed|full|reduced|reductions [quick]\n"
			"       workprec report DIR COMMAND\n");
	return 2;
}
