/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * convsim_bed.c - `convsim-bed --serve`: one LIGGGHTS bed in a process of
 * its own, driven over stdin and answering on stdout in the bed protocol
 * (bed_proto.h, docs/dem.md "The bed process"). The daemon spawns one per
 * LIGGGHTS session (feed_remote.c) so that LIGGGHTS, which ends its process
 * on a command it refuses, never runs inside convsimd.
 *
 * Its answers go to the stdout it was started with; its own descriptor 1
 * is pointed at stderr first, so that nothing LIGGGHTS or MPI prints can
 * break a line of the protocol. It ends with 0 on `quit` or the end of
 * stdin.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include "bed_proto.h"
#include "dem.h"

static const char usage[] =
	"usage: convsim-bed --serve [--nice N]\n"
	"  A LIGGGHTS bed driven over stdin, answering on stdout, one line each way\n"
	"  (the bed protocol, docs/dem.md). The daemon convsimd starts it for each\n"
	"  session with feed_model liggghts; --nice N lowers its priority by N.\n";

/* Write one answer line and flush it; 0 or -1. */
static int bed_answer(FILE *out, const char *line)
{
	return fputs(line, out) < 0 || fflush(out) ? -1 : 0;
}

/* The state answer of bed b. */
static int bed_state(FILE *out, dem_bed *b, int grains)
{
	char line[DEM_PROTO_LINE];
	dem_bed_state st;
	dem_bed_get(b, &st);
	if (dem_proto_state_line(line, sizeof line, &st, dem_cpu_now(), grains) < 0)
		return bed_answer(out, "error the state does not fit a line\n");
	return bed_answer(out, line);
}

/* Serve requests from in until quit or its end. 0 or 1 (the answers
 * cannot be written). */
static int bed_serve(FILE *in, FILE *out)
{
	char line[DEM_PROTO_LINE], msg[300], err[400];
	dem_bed *b = NULL;
	int grains = 0, rc = 0;
	while (!rc && fgets(line, sizeof line, in)) {
		dem_bed_spec spec;
		double ax, ay, h;
		if (!strncmp(line, "quit", 4))
			break;
		if (!strncmp(line, "bed ", 4)) {
			if (b) {
				rc = bed_answer(out, "error a bed is built already\n");
			} else if (dem_proto_bed_parse(line + 4, &spec)) {
				rc = bed_answer(out, "error the bed request's numbers do not read\n");
			} else if (!(b = dem_bed_new(&spec, NULL, msg, sizeof msg))) {
				snprintf(err, sizeof err, "error %s\n", msg);
				rc = bed_answer(out, err);
			} else {
				grains = spec.grains;
				rc = bed_state(out, b, grains);
			}
		} else if (!strncmp(line, "advance ", 8)) {
			if (!b) {
				rc = bed_answer(out, "error no bed yet\n");
			} else if (dem_proto_advance_parse(line + 8, &ax, &ay, &h)) {
				rc = bed_answer(out, "error the advance request's numbers do not read\n");
			} else if (dem_bed_advance(b, ax, ay, h, msg, sizeof msg)) {
				snprintf(err, sizeof err, "error %s\n", msg);
				rc = bed_answer(out, err);
			} else {
				rc = bed_state(out, b, grains);
			}
		} else {
			rc = bed_answer(out, "error unknown request (bed, advance or quit)\n");
		}
	}
	dem_bed_free(b);
	return rc ? 1 : 0;
}

int main(int argc, char **argv)
{
	int serve = 0;
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--serve")) {
			serve = 1;
		} else if (!strcmp(argv[i], "--nice") && i + 1 < argc) {
			int n = atoi(argv[++i]);
			if (n > 0 && n <= 19 && setpriority(PRIO_PROCESS, 0, n) != 0)
				perror("convsim-bed: setpriority");
		} else {
			fputs(usage, !strcmp(argv[i], "--help") ? stdout : stderr);
			return !strcmp(argv[i], "--help") ? 0 : 2;
		}
	}
	if (!serve) {
		fputs(usage, stderr);
		return 2;
	}
	/* OpenMPI's singleton start (LIGGGHTS initialises MPI) would fork an
	 * orted helper that outlives a killed bed: none, isolated */
	setenv("OMPI_MCA_ess_singleton_isolated", "1", 0);
	/* the answers keep the stdout we were given; 1 goes to stderr */
	int fd = dup(1);
	FILE *out = fd >= 0 ? fdopen(fd, "w") : NULL;
	if (!out || dup2(2, 1) < 0) {
		perror("convsim-bed");
		return 1;
	}
	return bed_serve(stdin, out);
}
