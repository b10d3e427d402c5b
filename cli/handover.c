/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * handover.c - handover.h: convsim-mpi is found beside the running
 * binary (/proc/self/exe, so a symbolic link to convsim still finds it)
 * and started by execv with main's arguments. The Makefile says what the
 * build has (CLI_MPI_BUILD: the bits of CLI_HAS_*, 0 when Open MPI was
 * not found or with `make NO_MPI=1`, and then nothing is handed over).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "handover.h"

#ifndef CLI_MPI_BUILD
#define CLI_MPI_BUILD 0
#endif

#define MPI_BINARY "convsim-mpi"

static char **main_argv;

void cli_handover_init(char **argv)
{
	main_argv = argv;
}

int cli_handover_has(unsigned what)
{
	return what && (CLI_MPI_BUILD & what) == what;
}

int cli_mpi_launched(void)
{
	return getenv("OMPI_COMM_WORLD_SIZE") || getenv("PMIX_RANK") || getenv("PMI_RANK");
}

int cli_handover(const char *cmd, const char *why)
{
	char path[4096];
	ssize_t n = readlink("/proc/self/exe", path, sizeof path - sizeof MPI_BINARY - 1);
	int err = errno;
	if (n > 0 && main_argv) {
		path[n] = '\0';
		char *slash = strrchr(path, '/');
		strcpy(slash ? slash + 1 : path, MPI_BINARY);
		fflush(stdout);
		fflush(stderr);
		execv(path, main_argv);
		err = errno;
	} else {
		snprintf(path, sizeof path, "%s", MPI_BINARY);
		err = main_argv ? err : EINVAL;
	}
	fprintf(stderr, "convsim %s: %s needs %s (this command line built with MPI and "
			"LIGGGHTS, beside convsim; `make` builds it where Open MPI is installed): "
			"cannot run '%s': %s\n",
		cmd, why, MPI_BINARY, path, strerror(err));
	return 1;
}
