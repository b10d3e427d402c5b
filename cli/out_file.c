/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * out_file.c - --out written whole or not at all (see cli.h): a regular
 * file is written as PATH.partial and renamed over PATH once all of it
 * is written, so a command that fails, or is killed, leaves an earlier
 * table at PATH as it was; and the bound a run checks its trajectory
 * against before it starts (--max-output).
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"
#include "table.h"

FILE *cli_out_open(cli_out *w, const char *cmd, const char *path)
{
	struct stat sb;
	*w = (cli_out){.path = path};
	/* a device, a FIFO or a link is written where it is (/dev/stdout,
	 * a pipe's end, a file the link names) */
	int in_place = lstat(path, &sb) == 0 && !S_ISREG(sb.st_mode);
	size_t n = strlen(path) + sizeof ".partial";
	if (!in_place && !(w->partial = malloc(n))) {
		fprintf(stderr, "convsim %s: --out: out of memory\n", cmd);
		return NULL;
	}
	if (w->partial)
		snprintf(w->partial, n, "%s.partial", path);
	w->f = fopen(w->partial ? w->partial : path, "w");
	if (!w->f) {
		/* the reason names the file asked for: its directory is the
		 * partial file's */
		fprintf(stderr, "convsim %s: --out: cannot write '%s': %s\n", cmd, path,
			strerror(errno));
		free(w->partial);
		w->partial = NULL;
	}
	return w->f;
}

int cli_out_close(cli_out *w, int keep)
{
	if (!w->f)
		return 0;
	int failed = ferror(w->f) | (fclose(w->f) != 0);
	w->f = NULL;
	if (w->partial) {
		if (keep && !failed && rename(w->partial, w->path) != 0)
			failed = 1;
		if (!keep || failed)
			unlink(w->partial);
		free(w->partial);
		w->partial = NULL;
	}
	return keep && failed;
}

double cli_out_bound(double rows, int width)
{
	return rows * (width * (SIM_FMT_DOUBLE_MAX + 1.0) + 3) + 4096;
}

/* bytes in the largest SI unit it reaches, 3 digits: "62.8 GB" */
static void out_human(char *buf, size_t len, double bytes)
{
	static const struct { const char *unit; double size; } u[] = {
		{"TB", 1e12}, {"GB", 1e9}, {"MB", 1e6}, {"kB", 1e3}};
	for (size_t i = 0; i < sizeof u / sizeof *u; i++)
		if (bytes >= u[i].size) {
			snprintf(buf, len, "%.3g %s", bytes / u[i].size, u[i].unit);
			return;
		}
	snprintf(buf, len, "%.0f bytes", bytes);
}

int cli_out_fits(const char *cmd, double rows, int width, double max_bytes)
{
	double bytes = cli_out_bound(rows, width);
	if (bytes <= max_bytes)
		return 0;
	char est[32], lim[32];
	out_human(est, sizeof est, bytes);
	out_human(lim, sizeof lim, max_bytes);
	fprintf(stderr, "convsim %s: --out would write %.0f rows of %d values, up to %.0f bytes (%s), "
		"more than --max-output %.0f bytes (%s); give --max-output %.0f to write it, or a "
		"shorter --duration or a lower --sample-rate\n", cmd, rows, width, bytes, est,
		max_bytes, lim, bytes);
	return 2;
}
