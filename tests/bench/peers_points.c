/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers_points.c - the gate's points for the peers harness (peers.h): the
 * converged reference tests/bench/results/vref.tsv, a chosen subset, and
 * the accuracy convention of docs/accuracy.md "Accuracy and speed".
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "peers.h"

/* Is (beta, rot) in list? */
static int listed(const char *list, double beta, const char *rot)
{
	if (!list || !strcmp(list, "all"))
		return 1;
	if (!strcmp(list, "cw") || !strcmp(list, "ccw"))
		return !strcmp(list, rot);
	char item[32];
	snprintf(item, sizeof item, "%g:%s", beta, rot);
	size_t len = strlen(item);
	for (const char *s = list; (s = strstr(s, item)) != NULL; s += len)
		if ((s == list || s[-1] == ',') && (s[len] == ',' || s[len] == '\0'))
			return 1;
	return 0;
}

int pset_load(pset *ps, const char *path, const char *list)
{
	FILE *f = fopen(path, "r");
	if (!f) {
		fprintf(stderr, "peers: cannot read %s\n", path);
		return -1;
	}
	char line[256];
	ps->n = 0;
	ps->peak = 0.0;
	int total = 0;
	while (fgets(line, sizeof line, f)) {
		pt p;
		if (sscanf(line, "%lf %3s %lf", &p.beta, p.rot, &p.vref) != 3)
			continue; /* the header */
		total++;
		ps->peak = fmax(ps->peak, fabs(p.vref));
		if (listed(list, p.beta, p.rot) && ps->n < 74)
			ps->p[ps->n++] = p;
	}
	fclose(f);
	if (total != 74 || ps->n == 0) {
		fprintf(stderr, "peers: %s: %d points (74 expected), %d selected by '%s'\n", path,
			total, ps->n, list ? list : "all");
		return -1;
	}
	return 0;
}

double pset_error(const pset *ps, const pt *p, double v)
{
	double a = fabs(p->vref);
	return fabs(v - p->vref) / (a >= 0.3 * ps->peak ? a : ps->peak);
}
