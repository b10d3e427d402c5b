/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_cmd.c - convsim sweep: v(beta) per rotation sense, one fresh
 * sim_measure per angle and sense on the library's parallel map (pmap.h),
 * the mirror reduction's images taken from their sources; the table has
 * the daemon's columns (core/table.h).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "pmap.h"
#include "sim.h"
#include "suggest.h"
#include "table.h"
#include "units.h"

/* ---- sweep ---- */

typedef struct task {
	double beta;
	int rotation;
	long source; /* -1: measured; else the task it mirrors (sim_mirror_plan) */
	sim_measurement r;
	int err;
	char msg[160];
} task;

typedef struct pool {
	const cli_opts *o;
	task *tasks;
	int *run;    /* the tasks to measure, in order */
	int n, done;
	cli_progress progress;
} pool;

/* Measure the k-th task to run (a job of the map). */
static void measure_task(void *arg, size_t k)
{
	pool *pl = arg;
	task *t = &pl->tasks[pl->run[k]];
	sim_params p = pl->o->p;
	p.beta = t->beta * RAD_PER_DEG;
	p.rotation = t->rotation;
	t->err = sim_measure(&p, &pl->o->sc, &pl->o->m, pl->o->duration, &t->r, t->msg,
			     sizeof t->msg);
}

/* The progress line after each task (the map calls it one at a time). */
static void task_done(void *arg, size_t k, size_t done)
{
	pool *pl = arg;
	const task *t = &pl->tasks[pl->run[k]];
	pl->done = (int)done;
	char detail[48];
	snprintf(detail, sizeof detail, " (last: %g deg %s)", t->beta,
		 t->rotation == SIM_CW ? "cw" : "ccw");
	cli_progress_update(&pl->progress, pl->done, pl->n, "points", detail);
}

/* The grid (rotation-major, like the daemon's) and its plan: which tasks
 * to measure (pl->run, pl->n) and which to take as mirror images of
 * another (sim_mirror_plan). -1 when out of memory. */
static int plan_sweep(const cli_opts *o, task *tasks, int ntasks, double from, double step, int nb,
		      const int *rots, pool *pl)
{
	double *beta = calloc((size_t)ntasks, sizeof(double));
	int *rot = calloc((size_t)ntasks, sizeof(int));
	long *source = calloc((size_t)ntasks, sizeof(long));
	int rc = beta && rot && source ? 0 : -1;
	for (int k = 0; rc == 0 && k < ntasks; k++) {
		tasks[k].beta = from + step * (k % nb);
		tasks[k].rotation = rots[k / nb];
		beta[k] = tasks[k].beta * RAD_PER_DEG;
		rot[k] = tasks[k].rotation;
	}
	if (rc == 0) {
		sim_mirror_plan(&o->p, &o->sc, (size_t)ntasks, beta, rot, source);
		for (int k = 0; k < ntasks; k++) {
			tasks[k].source = source[k];
			if (source[k] < 0)
				pl->run[pl->n++] = k;
		}
	}
	free(beta);
	free(rot);
	free(source);
	return rc;
}

/* Fill every mirrored task from the task it mirrors (after the runs). */
static void mirror_tasks(task *tasks, int ntasks)
{
	for (int k = 0; k < ntasks; k++) {
		task *t = &tasks[k];
		if (t->source < 0)
			continue;
		const task *src = &tasks[t->source];
		sim_mirror_measurement(&src->r, &t->r);
		t->err = src->err;
		if (src->err != SIM_OK)
			sim_mirror_failure(t->msg, sizeof t->msg, src->beta, src->rotation, src->msg);
	}
}

/* The sweep's table (CSV with the daemon's header, or JSON with the
 * daemon's point members) on f; failures on stderr. Returns the number of
 * failed points. */
static int print_sweep(FILE *f, const cli_opts *o, const pool *pl, int ntasks)
{
	int json = o->format && strcmp(o->format, "json") == 0, failed = 0;
	if (json) {
		fputs("{\"duration\":", f);
		cli_put_num(f, o->duration, "null");
		fputs(",\"transient\":", f);
		cli_put_num(f, o->sc.transient, "null");
		fprintf(f, ",\"method\":\"%s\",\"reductions\":[%s],\"points\":[\n", o->m.name,
			pl->n < ntasks ? "\"mirror\"" : "");
	} else {
		fputs(SIM_SWEEP_CSV_HEADER "\n", f);
	}
	for (int i = 0; i < ntasks; i++) {
		const task *t = &pl->tasks[i];
		const char *rot = t->rotation == SIM_CW ? "cw" : "ccw";
		const char *state = t->err == SIM_OK ? "done" : "failed";
		const char *steady = t->r.steady ? "true" : "false";
		if (t->err != SIM_OK) {
			failed++;
			fprintf(stderr, "convsim sweep: beta %g %s: %s\n", t->beta, rot, t->msg);
		}
		const char *nf = json ? "null" : "";
		fputs(json ? "{\"beta\":" : "", f);
		cli_put_num(f, t->beta, nf);
		fprintf(f, json ? ",\"rotation\":\"%s\",\"velocity\":" : ",%s,", rot);
		cli_put_num(f, t->r.transport_velocity, nf);
		fputs(json ? ",\"uncertainty\":" : ",", f);
		cli_put_num(f, t->r.uncertainty, nf);
		if (json)
			fprintf(f, ",\"steady\":%s,\"state\":\"%s\",\"mirrored\":%s", steady, state,
				t->source >= 0 ? "true" : "false");
		else
			fprintf(f, ",%s,%s", steady, state);
		fputs(json ? ",\"dt\":" : ",", f);
		cli_put_num(f, t->r.dt, nf);
		fprintf(f, json ? ",\"substeps\":%d,\"step_error\":" : ",%d,", t->r.substeps);
		cli_put_num(f, t->r.step_error, nf);
		fprintf(f, json ? ",\"tol_met\":%s}%s\n" : ",%s%s\n", t->r.tol_met ? "true" : "false",
			json && i + 1 < ntasks ? "," : "");
	}
	if (json)
		fputs("]}\n", f);
	return failed;
}

/* --beta FROM:TO:STEP or one angle into *from, *to, *step. */
static int parse_beta(const char *text, double *from, double *to, double *step)
{
	char tail;
	int n = sscanf(text, "%lf:%lf:%lf%c", from, to, step, &tail);
	if (n == 1 && sscanf(text, "%lf%c", from, &tail) == 1) {
		*to = *from;
		*step = 1;
		n = 3;
	}
	if (n != 3 || !(*step > 0) || !(*from >= 0) || !(*to <= 180) || !(*to >= *from)) {
		fprintf(stderr, "convsim sweep: --beta must be FROM:TO:STEP in degrees with 0 <= FROM "
				"<= TO <= 180 and STEP > 0 (or one angle), got '%s'\n",
			text);
		return -1;
	}
	return 0;
}

/* --rotation cw, ccw, cw,ccw (or ccw,cw) into rots; the count or -1. */
static int parse_rotation(const char *text, int rots[2])
{
	static const char *const senses[] = {"cw", "ccw"};
	int n = 0;
	char buf[64];
	snprintf(buf, sizeof buf, "%s", text);
	for (char *save, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		int known = strcmp(tok, "cw") == 0 || strcmp(tok, "ccw") == 0;
		int r = strcmp(tok, "cw") == 0 ? SIM_CW : SIM_CCW;
		if (!known || n == 2 || (n == 1 && rots[0] == r)) {
			char hint[96];
			fprintf(stderr, "convsim sweep: --rotation takes cw, ccw or cw,ccw; '%s' is not "
					"one%s\n",
				tok,
				cli_did_you_mean(hint, sizeof hint,
						 !known ? sim_suggest(tok, senses, 2, sizeof *senses)
						       : NULL));
			return -1;
		}
		rots[n++] = r;
	}
	if (!n)
		fprintf(stderr, "convsim sweep: --rotation takes cw, ccw or cw,ccw\n");
	return n ? n : -1;
}

int cli_cmd_sweep(int argc, char **argv)
{
	cli_opts o = {0};
	int rc = cli_parse(argc, argv, CMD_SWEEP, &o);
	if (rc)
		return rc < 0 ? 0 : rc;
	if (!(o.duration > o.sc.transient)) {
		fprintf(stderr, "convsim sweep: --duration (%g s) must exceed the scene's transient "
				"(%g s): v is measured over [transient, duration]\n",
			o.duration, o.sc.transient);
		return 2;
	}
	double from, to, step;
	int rots[2], nrot;
	if (parse_beta(o.beta, &from, &to, &step) || (nrot = parse_rotation(o.rotation, rots)) < 0)
		return 2;
	int nb = (int)floor((to - from) / step + 1e-9) + 1;
	if (nb > 10000) {
		fprintf(stderr, "convsim sweep: --beta %s gives %d angles; at most 10000\n", o.beta,
			nb);
		return 2;
	}
	FILE *out = stdout;
	if (o.out && !(out = cli_open_out(&o)))
		return 1;
	int ntasks = nb * nrot;
	pool pl = {.o = &o};
	pl.tasks = calloc((size_t)ntasks, sizeof(task));
	pl.run = calloc((size_t)ntasks, sizeof(int));
	if (!pl.tasks || !pl.run || plan_sweep(&o, pl.tasks, ntasks, from, step, nb, rots, &pl)) {
		free(pl.tasks);
		free(pl.run);
		return 1;
	}
	cli_progress_start(&pl.progress, "sweep", o.quiet, 0);
	pmap_run(o.threads, (size_t)pl.n, measure_task, &pl, task_done);
	mirror_tasks(pl.tasks, ntasks);
	char done[128];
	snprintf(done, sizeof done, "%d/%d points in %.1f s", pl.done, pl.n,
		 cli_now() - pl.progress.t0);
	if (pl.n < ntasks)
		snprintf(done + strlen(done), sizeof done - strlen(done),
			 "; %d more as their mirror images (mirror reduction)", ntasks - pl.n);
	cli_progress_end(&pl.progress, done, 1);
	int failed = print_sweep(out, &o, &pl, ntasks);
	int write_failed = 0;
	if (out != stdout) {
		write_failed = ferror(out) | (fclose(out) != 0);
		if (write_failed)
			fprintf(stderr, "convsim sweep: --out: writing '%s' failed\n", o.out);
	}
	free(pl.tasks);
	free(pl.run);
	return failed || write_failed ? 1 : 0;
}
