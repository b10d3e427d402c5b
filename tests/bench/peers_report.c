/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers_report.c - the peers' table (peers.h): reads the harness's rows
 * (peers.c: one per setting and point) back, sums each setting over its
 * points, and writes DIR/peers.md (one line a peer: the loosest tolerance
 * that meets 1 % at every point, or the best it reached, with its CPU time
 * as a ratio to the core's dem defaults over the same points) and
 * DIR/peers_summary.tsv (every setting, for the plot: workprec_svg.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "peer.h"
#include "peers.h"

typedef struct setting_sum {
	char kind[8], name[24], setting[40], worst_at[32], status[200];
	int n, beyond;
	double worst, cpu;
	double done[74]; /* the errors of the points finished, in order */
	unsigned long long steps, rejected, rhs;
} setting_sum;

enum { MAX_SETTINGS = 128 };

/* simulated seconds a point: the settling's 1.5 and the window's 4 */
#define SIM_S_PER_POINT 5.5

/* Adds one row to its setting's sum (a new one when first seen). */
static void add_row(setting_sum *S, int *ns, const char *line)
{
	char kind[8], name[24], setting[40], rot[8], status[200] = "";
	double beta, v, vref, e, cpu;
	unsigned long long steps, rej, rhs;
	if (sscanf(line, "%7s %23s %39s %lf %7s %lf %lf %lf %lf %llu %llu %llu %199[^\n]", kind,
		   name, setting, &beta, rot, &v, &vref, &e, &cpu, &steps, &rej, &rhs,
		   status) < 12)
		return;
	int i = 0;
	while (i < *ns && (strcmp(S[i].name, name) || strcmp(S[i].setting, setting)))
		i++;
	if (i == *ns) {
		if (*ns == MAX_SETTINGS)
			return;
		memset(&S[i], 0, sizeof S[i]);
		snprintf(S[i].kind, sizeof S[i].kind, "%s", kind);
		snprintf(S[i].name, sizeof S[i].name, "%s", name);
		snprintf(S[i].setting, sizeof S[i].setting, "%s", setting);
		snprintf(S[i].status, sizeof S[i].status, "ok");
		(*ns)++;
	}
	setting_sum *s = &S[i];
	if (isfinite(e) && s->n < 74)
		s->done[s->n] = e;
	s->n += isfinite(e);
	s->cpu += cpu;
	s->steps += steps;
	s->rejected += rej;
	s->rhs += rhs;
	s->beyond += !(e <= 0.01);
	if (!isfinite(e) || e > s->worst) {
		if (isfinite(s->worst))
			snprintf(s->worst_at, sizeof s->worst_at, "%g %s", beta, rot);
		s->worst = isfinite(e) ? e : INFINITY;
	}
	if (strcmp(status, "ok") && !strcmp(s->status, "ok"))
		snprintf(s->status, sizeof s->status, "%s", status);
}

/* One peer's line: the loosest passing setting, else the best reached. */
static void peer_line(FILE *f, const setting_sum *S, int ns, const char *name, int npts,
		      const setting_sum *ours)
{
	const setting_sum *pass = NULL, *best = NULL, *fail = NULL;
	for (int i = 0; i < ns; i++) {
		const setting_sum *s = &S[i];
		if (strcmp(s->name, name))
			continue;
		if (s->n == npts && s->worst <= 0.01 && !pass)
			pass = s;
		if (s->n == npts && (!best || s->worst < best->worst))
			best = s;
		if (s->n < npts && !fail)
			fail = s;
	}
	const setting_sum *s = pass ? pass : best;
	if (!s) {
		/* no setting covered every point: the one that went furthest */
		const setting_sum *far = NULL;
		for (int i = 0; i < ns; i++)
			if (!strcmp(S[i].name, name) && (!far || S[i].n > far->n))
				far = &S[i];
		if (!far) {
			fprintf(f, "| %s | not run |  |  |  |  |  |\n", name);
			return;
		}
		double worst = 0.0; /* over the points it finished */
		for (int i = 0; i < far->n; i++)
			worst = fmax(worst, far->done[i]);
		fprintf(f, "| %s | %s: %d of %d points, then stopped | %.3g %% over those | %.4g | "
			   "n/a | %llu / %llu in all | %s: %s |\n",
			name, far->setting, far->n, npts, 100 * worst, far->cpu, far->steps,
			far->rejected, far->setting, far->status);
		return;
	}
	double per_s = SIM_S_PER_POINT * npts;
	fprintf(f, "| %s | %s%s | %.2f %% (%s) | %.4g | %s%.0f×%s | %.3g / %.3g | %s |\n", name,
		s->setting, pass ? "" : " (best; 1 % not reached)", 100 * s->worst, s->worst_at,
		s->cpu, pass ? "**" : "", ours ? s->cpu / ours->cpu : NAN, pass ? "**" : "",
		(double)s->steps / per_s,
		(double)s->rejected / per_s,
		fail ? fail->setting : (pass ? "" : "-"));
	if (fail)
		fprintf(f, "|  | %s: %s |  |  |  |  |  |\n", fail->setting, fail->status);
}

int peers_report(const char *dir, const char *cmd, int npts, const char *points)
{
	char path[512];
	snprintf(path, sizeof path, "%s/peers.tsv", dir);
	FILE *in = fopen(path, "r");
	if (!in) {
		fprintf(stderr, "peers report: cannot read %s\n", path);
		return 1;
	}
	static setting_sum S[MAX_SETTINGS];
	int ns = 0;
	char line[512];
	while (fgets(line, sizeof line, in))
		add_row(S, &ns, line);
	fclose(in);
	const setting_sum *ours = NULL;
	for (int i = 0; i < ns; i++)
		if (!strcmp(S[i].kind, "ours") && !strcmp(S[i].setting, "default"))
			ours = &S[i];
	snprintf(path, sizeof path, "%s/gate.tsv", dir);
	FILE *sum = fopen(path, "w");
	snprintf(path, sizeof path, "%s/peers.md", dir);
	FILE *f = sum ? fopen(path, "w") : NULL;
	if (!f) {
		fprintf(stderr, "peers report: cannot write %s\n", path);
		return 1;
	}
	/* wp_row's columns (workprec_run.c): CPU per simulated second, the
	 * worst error in the v column */
	for (int i = 0; i < ns; i++) {
		double cps = S[i].cpu / (SIM_S_PER_POINT * npts);
		if (S[i].n == npts)
			fprintf(sum, "run\tgate\t-\t%s\t%s\t%g\t%.6g\t%.6g\tnan\tnan\tnan\t%.6g\t"
				     "nan\tnan\t%llu\tok\n",
				S[i].name, S[i].setting, SIM_S_PER_POINT, cps, 1 / cps, S[i].worst,
				S[i].steps);
	}
	fclose(sum);
	fprintf(f, "# Peers at the 1 %% gate\n\nCommand: `%s` (tests/bench/peers.sh). Points (%d): "
		   "%s. The czubak2016 defaults (steady start, v over [0, 4] s) against "
		   "tests/bench/results/vref.tsv; CPU: seconds on one core for all the points "
		   "(shooting, settling and window; the least of up to three repeats for points "
		   "under 1 s).\n\n",
		cmd, npts, points);
	fprintf(f, "Ours, dem defaults: worst %.2f %% (%s), %.4g CPU s.\n\n",
		ours ? 100 * ours->worst : NAN, ours ? ours->worst_at : "n/a",
		ours ? ours->cpu : NAN);
	fprintf(f, "| peer | tolerance | worst error | CPU s | CPU / ours | steps / rejected per "
		   "simulated s | failed setting |\n|---|---|---|---|---|---|---|\n");
	for (const char *const *name = peer_names; *name; name++)
		peer_line(f, S, ns, *name, npts, ours);
	fprintf(f, "\nEvery setting run (loosest first; a setting stops at its first failed "
		   "point):\n\n| who | setting | points done | worst | CPU s | steps | rejected | "
		   "rhs evals | status |\n|---|---|---|---|---|---|---|---|---|\n");
	for (int i = 0; i < ns; i++)
		fprintf(f, "| %s | %s | %d | %.3g %% | %.4g | %llu | %llu | %llu | %s |\n",
			S[i].name, S[i].setting, S[i].n, 100 * S[i].worst, S[i].cpu, S[i].steps,
			S[i].rejected, S[i].rhs, S[i].status);
	fclose(f);
	return 0;
}
