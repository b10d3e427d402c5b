/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * out_file.c - --out written whole or not at all (see cli.h): a regular
 * file is written as PATH.partial and renamed over PATH once all of it
 * is written, so a command that fails, or is killed, leaves an earlier
 * table at PATH as it was.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "cli.h"

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
