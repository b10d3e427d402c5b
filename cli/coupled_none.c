/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * coupled_none.c - `convsim run --set feed_model=liggghts` where convsim
 * was built without LIGGGHTS: says so and how to get it. Where LIGGGHTS
 * is installed the Makefile links dem/cli/run_coupled.c instead.
 */
#include <stdio.h>

#include "cli.h"

int cli_run_coupled(const cli_opts *o)
{
	(void)o;
	fprintf(stderr, "convsim run: --set feed_model=liggghts: this convsim was built without "
			"LIGGGHTS; `make deps` installs it (Debian libliggghts-dev) and `make` then "
			"builds the coupling (docs/dem.md)\n");
	return 2;
}
