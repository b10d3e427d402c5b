/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * workprec_report.c - the benchmark's report: reads the scenes' TSV rows
 * back and writes workprec.md (a table a scene, the references and their
 * uncertainty, the fastest setting within 1 %, the model reductions); the
 * plot of the same rows is workprec_svg.c's.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "workprec.h"

static void read_tsv(const char *path, wp_records *t)
{
	FILE *f = fopen(path, "r");
	if (!f)
		return;
	char line[1024];
	while (fgets(line, sizeof line, f)) {
		line[strcspn(line, "\n")] = 0;
		char *fld[20];
		int nf = 0;
		for (char *p = line; nf < 20;) {
			fld[nf++] = p;
			char *tab = strchr(p, '\t');
			if (!tab)
				break;
			*tab = 0;
			p = tab + 1;
		}
		if (strcmp(fld[0], "richardson") == 0 && nf >= 9 && t->nrich < 4) {
			for (int i = 0; i < 8; i++)
				snprintf(t->rich[t->nrich][i], sizeof t->rich[0][0], "%s", fld[i + 1]);
			t->nrich++;
			continue;
		}
		if (nf < 16 || t->nrec >= 512)
			continue;
		wp_rec *r = &t->recs[t->nrec++];
		snprintf(r->kind, sizeof r->kind, "%s", fld[0]);
		snprintf(r->scene, sizeof r->scene, "%s", fld[1]);
		snprintf(r->variant, sizeof r->variant, "%s", fld[2]);
		snprintf(r->method, sizeof r->method, "%s", fld[3]);
		snprintf(r->setting, sizeof r->setting, "%s", fld[4]);
		r->horizon = strtod(fld[5], NULL);
		r->cps = strtod(fld[6], NULL);
		r->rtf = strtod(fld[7], NULL);
		r->tr = strtod(fld[8], NULL);
		r->trel = strtod(fld[9], NULL);
		r->v = strtod(fld[10], NULL);
		r->vrel = strtod(fld[11], NULL);
		r->eres = strtod(fld[12], NULL);
		r->erel = strtod(fld[13], NULL);
		r->steps = strtoull(fld[14], NULL, 10);
		snprintf(r->err, sizeof r->err, "%s", fld[15]);
	}
	fclose(f);
}

static const char *fmt_g(double v, char *buf, size_t n, const char *f)
{
	if (isnan(v))
		snprintf(buf, n, "n/a");
	else
		snprintf(buf, n, f, v);
	return buf;
}

static const char *scene_title(const char *s)
{
	if (strcmp(s, "nofeed") == 0)
		return "(1) machine without feed, motor start";
	if (strcmp(s, "full") == 0)
		return "(2) full czubak2016 scene (5 x 8 feed, motor start)";
	if (strcmp(s, "reduced") == 0)
		return "(3) reduced scene (trough_rotation=false: alpha dropped, 1 column x 5)";
	return s;
}

const wp_rec *wp_find_ref(const wp_records *t, const char *scene, const char *kind)
{
	for (int i = 0; i < t->nrec; i++)
		if (strcmp(t->recs[i].scene, scene) == 0 && strcmp(t->recs[i].kind, kind) == 0)
			return &t->recs[i];
	return NULL;
}

/* The fastest run of a scene within tolerance (relative v error for the
 * feed scenes, relative trajectory error for the machine alone). */
static const wp_rec *fastest_within(const wp_records *t, const char *scene, double tol)
{
	const wp_rec *best = NULL;
	int feed = strcmp(scene, "nofeed") != 0;
	for (int i = 0; i < t->nrec; i++) {
		const wp_rec *r = &t->recs[i];
		if (strcmp(r->kind, "run") || strcmp(r->scene, scene) || strcmp(r->err, "ok"))
			continue;
		double e = feed ? r->vrel : r->trel;
		if (!(e <= tol))
			continue;
		if (!best || r->cps < best->cps)
			best = r;
	}
	return best;
}

/* The reference paragraph of a scene: the trajectory reference and its
 * check for the machine alone, the dem reference and the rk4 Richardson
 * check for the feed scenes. */
static void md_reference(FILE *f, const wp_records *t, const char *sc, int feed,
			 const wp_rec *ref)
{
	char b[2][32];
	if (!feed) {
		const wp_rec *chk = wp_find_ref(t, sc, "refcheck");
		fprintf(f,
			"Reference: %s %s. Confirmed by %s %s: trajectories agree to "
			"%s m RMS (%s relative).\n\n",
			ref->method, ref->setting, chk ? chk->method : "?",
			chk ? chk->setting : "?", fmt_g(chk ? chk->tr : NAN, b[0], 32, "%.2e"),
			fmt_g(chk ? chk->trel : NAN, b[1], 32, "%.2e"));
		return;
	}
	for (int k = 0; k < t->nrich; k++) {
		if (strcmp(t->rich[k][0], sc))
			continue;
		fprintf(f,
			"Reference: %s %s (feed sub-step 1e-6 s), v = %.6f m/s. "
			"Confirmed by rk4 (a different method: smooth RK4 on the "
			"switching law): finest run v = %s m/s, observed order %s, "
			"Richardson limit %s m/s; the two references differ by "
			"%.2e relative in v. Trajectory: the rk4 runs' Richardson "
			"extrapolation (observed order %s) lies %.2e (relative RMS) "
			"from the reference. Errors below these are not resolved "
			"(shaded in the plot).\n\n",
			ref->method, ref->setting, ref->v, t->rich[k][2], t->rich[k][3],
			t->rich[k][4], strtod(t->rich[k][5], NULL), t->rich[k][7],
			strtod(t->rich[k][6], NULL));
	}
}

/* One scene's section: title, references, the table of its runs and the
 * fastest run within 1 % of the reference. */
static void md_scene(FILE *f, const wp_records *t, const char *sc, int feed)
{
	char b[9][32];
	const wp_rec *ref = wp_find_ref(t, sc, "ref");
	if (!ref)
		return;
	fprintf(f, "## %s\n\n", scene_title(sc));
	md_reference(f, t, sc, feed, ref);
	fprintf(f,
		"| method | setting | horizon s | CPU s/sim s | real-time x | traj RMS m | "
		"traj rel | v m/s | v rel err | energy res J | res/input | steps |\n"
		"|---|---|---|---|---|---|---|---|---|---|---|---|\n");
	for (int i = 0; i < t->nrec; i++) {
		const wp_rec *r = &t->recs[i];
		if (strcmp(r->scene, sc) || strcmp(r->kind, "run"))
			continue;
		fprintf(f, "| %s | %s | %g | %s | %s | %s | %s | %s | %s | %s | %s | %llu |%s%s\n",
			r->method, r->setting, r->horizon, fmt_g(r->cps, b[0], 32, "%.3g"),
			fmt_g(r->rtf, b[1], 32, "%.3g"), fmt_g(r->tr, b[2], 32, "%.2e"),
			fmt_g(r->trel, b[3], 32, "%.2e"), fmt_g(r->v, b[4], 32, "%.5f"),
			fmt_g(r->vrel, b[5], 32, "%.2e"), fmt_g(r->eres, b[6], 32, "%.3g"),
			fmt_g(r->erel, b[7], 32, "%.2e"), r->steps,
			strcmp(r->err, "ok") ? " " : "", strcmp(r->err, "ok") ? r->err : "");
	}
	const wp_rec *best = fastest_within(t, sc, feed ? 0.01 : 0.01);
	if (best)
		fprintf(f,
			"\n**Fastest within 1 %% of the reference %s:** %s %s, %.3g CPU s "
			"per simulated s (%.0fx real time), %s error %.2e.\n\n",
			feed ? "transport velocity" : "trajectory", best->method,
			best->setting, best->cps, best->rtf, feed ? "v" : "trajectory",
			feed ? best->vrel : best->trel);
}

/* The reductions' section (none without reduction rows). */
static void md_reductions(FILE *f, const wp_records *t)
{
	char b[9][32];
	int any = 0;
	for (int i = 0; i < t->nrec; i++)
		any |= strcmp(t->recs[i].kind, "reduction") == 0;
	if (!any)
		return;
	fprintf(f,
		"## Model reductions against the full model\n\n"
		"Same integrator and settings for both (dem as given), horizon as given; "
		"CPU time the best of three runs. Trajectory compared over the first 20 "
		"periods where the start-up is the same (not with the ideal drive, which "
		"ramps the speed instead of starting the motor).\n\n"
		"| reduction | integrator | CPU s/sim s | speed-up | real-time x | traj RMS m "
		"| traj rel | v m/s | v diff rel |\n|---|---|---|---|---|---|---|---|---|\n");
	double full_cps = NAN;
	for (int i = 0; i < t->nrec; i++) {
		const wp_rec *r = &t->recs[i];
		if (strcmp(r->kind, "reduction"))
			continue;
		if (strcmp(r->variant, "full") == 0)
			full_cps = r->cps;
		fprintf(f, "| %s | %s %s | %s | %s | %s | %s | %s | %s | %s |\n", r->variant,
			r->method, r->setting, fmt_g(r->cps, b[0], 32, "%.3g"),
			fmt_g(full_cps / r->cps, b[1], 32, "%.2f"),
			fmt_g(r->rtf, b[2], 32, "%.0f"), fmt_g(r->tr, b[3], 32, "%.2e"),
			fmt_g(r->trel, b[4], 32, "%.2e"), fmt_g(r->v, b[5], 32, "%.5f"),
			fmt_g(r->vrel, b[6], 32, "%.2e"));
	}
	fprintf(f, "\n");
}

FILE *wp_create(const char *dir, const char *name)
{
	char path[512];
	snprintf(path, sizeof path, "%s/%s", dir, name);
	FILE *f = fopen(path, "w");
	if (!f) {
		perror(path);
		exit(1);
	}
	return f;
}

static void write_md(const char *dir, const char *cmd, const wp_records *t)
{
	FILE *f = wp_create(dir, "workprec.md");
	fprintf(f, "# Work-precision benchmark\n\nMade by `%s`\n\n", cmd);
	fprintf(f,
		"One process per scene, one thread each (at most two in parallel). CPU s/sim s: "
		"CPU seconds per simulated second over the whole run (real-time factor = its "
		"inverse). Trajectory: RMS distance of the trough's (x, y) from the reference over "
		"the first 20 excitation periods (0.8 s, samples every 2 ms), in m and relative to "
		"the reference's RMS displacement. v: transport velocity over [2 s, horizon]; v "
		"error relative to the reference. Energy: the balance residual (stored change + "
		"dissipated - input) at the end, in J and relative to the input work. dopri5 on "
		"the feed scenes runs 0.8 s only (trajectory and cost; no v): in the feed's "
		"sliding modes it accepts millions of floor steps (1e-7 s) per simulated second, "
		"so rtol is capped at 1e-5.\n\n");
	const char *scenes[] = {"nofeed", "full", "reduced"};
	for (int si = 0; si < 3; si++)
		md_scene(f, t, scenes[si], si > 0);
	md_reductions(f, t);
	fprintf(f, "Plot: `workprec.svg` (error on log x, CPU s per simulated s on log y).\n");
	fclose(f);
}

void wp_report(const char *dir, const char *cmd)
{
	wp_records *t = calloc(1, sizeof *t);
	if (!t) {
		fprintf(stderr, "workprec: out of memory\n");
		exit(1);
	}
	/* gate.tsv: the peers at the 1 % gate (peers_report.c), if run */
	const char *names[] = {"nofeed", "full", "reduced", "reductions", "gate"};
	for (int i = 0; i < 5; i++) {
		char path[512];
		snprintf(path, sizeof path, "%s/%s.tsv", dir, names[i]);
		read_tsv(path, t);
	}
	write_md(dir, cmd, t);
	wp_write_svg(dir, t);
	free(t);
}
