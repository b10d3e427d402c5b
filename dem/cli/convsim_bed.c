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
 *
 * Under `mpirun -n N` (the daemon's --dem-ranks) rank 0 reads the requests
 * and hands each to every rank (MPI_Bcast); LIGGGHTS splits the bed over
 * the ranks, the bed's totals are its global reductions, and rank 0 alone
 * answers, with the CPU time of all ranks.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <unistd.h>

#include <mpi.h>

#include "bed_proto.h"
#include "decimal.h"
#include "dem.h"
#include "tether.h"

/* The ranks (1 without mpirun: MPI is then left to LIGGGHTS). */
static int bed_rank, bed_ranks = 1;

static const char usage[] =
	"usage: convsim-bed --serve [--nice N]\n"
	"  A LIGGGHTS bed driven over stdin, answering on stdout, one line each way\n"
	"  (the bed protocol, docs/dem.md). The daemon convsimd starts it for each\n"
	"  session with feed_model liggghts (under mpirun -n N with --dem-ranks N);\n"
	"  --nice N (a whole number, 0 to 19) lowers its priority by N.\n";

/* --nice's value, a whole number in [0, 19] as decimal.h reads one (not
 * 0x5, ' 5' or 5abc, which atoi would take), or -1 after a message. */
static int bed_nice(const char *text)
{
	double v;
	if (!sim_decimal(text, &v) || v < 0 || v > 19) {
		fprintf(stderr, "convsim-bed: --nice must be a number in [0, 19], got '%s'\n", text);
		return -1;
	}
	if (v != (int)v) {
		fprintf(stderr, "convsim-bed: --nice must be a whole number, got '%s'\n", text);
		return -1;
	}
	return (int)v;
}

/* Write one answer line and flush it; 0 or -1. */
static int bed_answer(FILE *out, const char *line)
{
	return fputs(line, out) < 0 || fflush(out) ? -1 : 0;
}

/* The state answer of bed b (every rank computes it: the totals are
 * reductions; rank 0 writes it). */
static int bed_state(FILE *out, dem_bed *b, int grains)
{
	char line[DEM_PROTO_LINE];
	dem_bed_state st;
	double cpu = dem_cpu_now(), all = cpu;
	dem_bed_get(b, &st);
	if (bed_ranks > 1)
		MPI_Allreduce(&cpu, &all, 1, MPI_DOUBLE, MPI_SUM, MPI_COMM_WORLD);
	if (bed_rank > 0)
		return 0;
	if (dem_proto_state_line(line, sizeof line, &st, all, grains) < 0)
		return bed_answer(out, "error the state does not fit a line\n");
	return bed_answer(out, line);
}

/* An error answer (rank 0). */
static int bed_error(FILE *out, const char *what)
{
	char err[400];
	if (bed_rank > 0)
		return 0;
	snprintf(err, sizeof err, "error %s\n", what);
	return bed_answer(out, err);
}

/* The next request into line, the same on every rank: rank 0 reads it,
 * the others receive it. 0, or -1 at the end of the requests. */
static int bed_request(FILE *in, char *line, size_t len)
{
	int more = 1;
	if (bed_rank == 0)
		more = fgets(line, (int)len, in) != NULL;
	if (bed_ranks > 1) {
		MPI_Bcast(&more, 1, MPI_INT, 0, MPI_COMM_WORLD);
		if (more)
			MPI_Bcast(line, (int)len, MPI_CHAR, 0, MPI_COMM_WORLD);
	}
	return more ? 0 : -1;
}

/* Serve requests from in until quit or its end. 0 or 1 (the answers
 * cannot be written). */
static int bed_serve(FILE *in, FILE *out)
{
	char line[DEM_PROTO_LINE], msg[300];
	dem_bed *b = NULL;
	int grains = 0, rc = 0;
	MPI_Comm world = MPI_COMM_WORLD;
	while (!rc && bed_request(in, line, sizeof line) == 0) {
		dem_bed_spec spec;
		double ax, ay, h;
		if (!strncmp(line, "quit", 4))
			break;
		if (!strncmp(line, "bed ", 4)) {
			if (b) {
				rc = bed_error(out, "a bed is built already");
			} else if (dem_proto_bed_parse(line + 4, &spec)) {
				rc = bed_error(out, "the bed request's numbers do not read");
			} else if (!(b = dem_bed_new(&spec, bed_ranks > 1 ? &world : NULL, msg,
						     sizeof msg))) {
				rc = bed_error(out, msg);
			} else {
				grains = spec.grains;
				rc = bed_state(out, b, grains);
			}
		} else if (!strncmp(line, "advance ", 8)) {
			if (!b) {
				rc = bed_error(out, "no bed yet");
			} else if (dem_proto_advance_parse(line + 8, &ax, &ay, &h)) {
				rc = bed_error(out, "the advance request's numbers do not read");
			} else if (dem_bed_advance(b, ax, ay, h, msg, sizeof msg)) {
				rc = bed_error(out, msg);
			} else {
				rc = bed_state(out, b, grains);
			}
		} else {
			rc = bed_error(out, "unknown request (bed, advance or quit)");
		}
	}
	dem_bed_free(b);
	return rc ? 1 : 0;
}

int main(int argc, char **argv)
{
	sim_tether_from_env(); /* the test suite's: end with the test */
	int serve = 0;
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--serve")) {
			serve = 1;
		} else if (!strcmp(argv[i], "--nice") && i + 1 < argc) {
			int n = bed_nice(argv[++i]);
			if (n < 0)
				return 2;
			if (n > 0 && setpriority(PRIO_PROCESS, 0, n) != 0)
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
	const char *size = getenv("OMPI_COMM_WORLD_SIZE");
	if (size && atoi(size) > 1) { /* under mpirun */
		MPI_Init(&argc, &argv);
		MPI_Comm_rank(MPI_COMM_WORLD, &bed_rank);
		MPI_Comm_size(MPI_COMM_WORLD, &bed_ranks);
	}
	/* the answers keep the stdout we were given; 1 goes to stderr */
	int fd = dup(1);
	FILE *out = fd >= 0 ? fdopen(fd, "w") : NULL;
	if (!out || dup2(2, 1) < 0) {
		perror("convsim-bed");
		return 1;
	}
	int rc = bed_serve(stdin, out);
	if (bed_ranks > 1)
		MPI_Finalize();
	return rc;
}
