/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_cmd.c - convsim sweep: a study of v over any number settings (--vary
 * NAME=FROM:TO:STEP or NAME=V1,V2,..., --beta as the shorthand for --vary
 * beta=..., a grid or a --lhs sample; core/study.h) per rotation sense, one
 * fresh sim_measure per point and sense on the library's parallel map
 * (pmap.h), the mirror reduction's images taken from their sources. The
 * table has the varied settings' columns, then the daemon's point columns
 * (core/table.h); with --band-from a band per point (band_from.h). Under
 * mpirun the points to measure are spread over the ranks (spread.h) and
 * rank 0 writes the table, the same bytes as one process writes. The
 * options' study is study_opts.c's. */
#include <fcntl.h>
#include <math.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "band_from.h"
#include "cli.h"
#include "pmap.h"
#include "sim.h"
#include "sim_mirror.h"
#include "spread.h"
#include "study.h"
#include "table.h"

typedef struct task {
	long source; /* -1: measured; else the task it mirrors (sim_study_mirror_plan) */
	sim_measurement r;
	double band[2]; /* --band-from: the 95 % band's lower and upper ends, m/s */
	int err;
	int cancelled; /* not measured: the sweep was interrupted first */
	char msg[160];
} task;

typedef struct pool {
	const cli_opts *o;
	const sim_study *st;
	const cli_spread *sp;
	const fit_band_source *band; /* NULL: no bands */
	const int *skip;             /* the band's parameters the study varies */
	task *tasks;
	int *run;    /* the tasks to measure, in order */
	int n, measured; /* measured: of this rank's share (not cancelled) */
	cli_progress progress;
} pool;

/* Task k's settings and sense as the messages name them: "mu=0.5, beta=30
 * deg, cw" into buf. */
static const char *describe_task(const sim_study *st, size_t k, char *buf, size_t len)
{
	size_t at = 0;
	buf[0] = '\0';
	for (size_t a = 0; a < st->naxes && at < len; a++) {
		const sim_setting *t = st->axis[a].setting;
		at += (size_t)snprintf(buf + at, len - at, "%s=%g%s%s, ", t->name,
				       sim_study_value(st, k % st->npoints, a),
				       *sim_unit_shown(t) ? " " : "", sim_unit_shown(t));
	}
	if (at < len)
		snprintf(buf + at, len - at, "%s",
			 st->rotation[k / st->npoints] == SIM_CW ? "cw" : "ccw");
	return buf;
}

/* The task of this rank's j-th job: the (rank + j ranks)-th to run. */
static size_t share_task(const pool *pl, size_t j)
{
	return (size_t)pl->run[(size_t)pl->sp->rank + j * (size_t)pl->sp->ranks];
}

/* Measure this rank's j-th task (a job of the map). */
static void measure_task(void *arg, size_t j)
{
	pool *pl = arg;
	size_t i = share_task(pl, j);
	task *t = &pl->tasks[i];
	sim_params p = pl->o->p;
	sim_scene sc = pl->o->sc;
	sim_method m = pl->o->m;
	t->band[0] = t->band[1] = NAN;
	if (cli_interrupted()) { /* the rest of the share is skipped */
		t->cancelled = 1;
		t->r = (sim_measurement){.transport_velocity = NAN, .uncertainty = NAN,
					 .step_error = NAN, .dt = NAN};
		return;
	}
	t->err = sim_study_apply(pl->st, i, &p, &sc, &m, t->msg, sizeof t->msg);
	/* a point stops once its bar is met; with a band its v is the
	 * centre of the band's finite differences, which run the whole window */
	if (t->err == SIM_OK)
		t->err = (pl->band ? sim_measure : sim_measure_point)(&p, &sc, &m, pl->o->duration,
								       &t->r, t->msg, sizeof t->msg);
	if (t->err == SIM_OK && pl->band)
		t->err = fit_band_point(pl->band, pl->skip, &p, &sc, &m, pl->o->duration, &t->r,
					&t->band[0], &t->band[1], t->msg, sizeof t->msg);
}

/* The progress line after each task (the map calls it one at a time). */
static void task_done(void *arg, size_t j, size_t done)
{
	pool *pl = arg;
	char what[200], detail[220];
	(void)done;
	if (pl->tasks[share_task(pl, j)].cancelled)
		return;
	pl->measured++;
	snprintf(detail, sizeof detail, " (last: %s)",
		 describe_task(pl->st, share_task(pl, j), what, sizeof what));
	cli_progress_update(&pl->progress, pl->measured,
			    (double)cli_spread_share(pl->sp, (size_t)pl->n),
			    pl->sp->ranks > 1 ? "points of rank 0's share" : "points", detail);
}

/* Task k's beta in degrees: its axis value, else the model's. */
static double task_beta(const pool *pl, size_t k)
{
	const sim_study *st = pl->st;
	for (size_t a = 0; a < st->naxes; a++)
		if (strcmp(st->axis[a].setting->name, "beta") == 0)
			return sim_study_value(st, k % st->npoints, a);
	return sim_table_user("beta", pl->o->p.beta);
}

/* Fill every mirrored task from the task it mirrors (after the runs), then
 * judge tol_met again with a curve's own peak (core/study.h). */
static void mirror_tasks(const pool *pl, int ntasks)
{
	double peak = 0.0;
	int curve = sim_study_curve(pl->st);
	for (int k = 0; k < ntasks; k++) {
		task *t = &pl->tasks[k];
		if (t->source < 0)
			continue;
		const task *src = &pl->tasks[t->source];
		sim_mirror_measurement(&src->r, &t->r);
		t->band[0] = -src->band[1]; /* the band's image: v -> -v */
		t->band[1] = -src->band[0];
		t->err = src->err;
		t->cancelled = src->cancelled;
		if (src->err != SIM_OK)
			sim_mirror_failure(t->msg, sizeof t->msg, task_beta(pl, (size_t)t->source),
					   pl->st->rotation[(size_t)t->source / pl->st->npoints],
					   src->msg);
	}
	for (int k = 0; curve && k < ntasks; k++)
		if (pl->tasks[k].err == SIM_OK && !pl->tasks[k].cancelled)
			peak = fmax(peak, fabs(pl->tasks[k].r.transport_velocity));
	for (int k = 0; curve && k < ntasks; k++)
		pl->tasks[k].r.tol_met = sim_tol_met_at_peak(&pl->tasks[k].r, pl->o->m.tol, peak);
}

/* The JSON table's head: the run's settings, the varied settings (name,
 * unit, range or list), the sample, the reductions. */
static void print_json_head(FILE *f, const cli_opts *o, const pool *pl, int ntasks)
{
	const sim_study *st = pl->st;
	cli_put_json_num(f, "{\"duration\":", o->duration);
	cli_put_json_num(f, ",\"transient\":", o->sc.transient);
	fprintf(f, ",\"method\":\"%s\",\"vary\":[", o->m.name);
	for (size_t a = 0; a < st->naxes; a++) {
		const sim_study_axis *ax = &st->axis[a];
		fprintf(f, "%s{\"name\":\"%s\",\"unit\":\"%s\",", a ? "," : "", ax->setting->name,
			ax->setting->unit);
		if (ax->step > 0) {
			cli_put_json_num(f, "\"from\":", ax->from);
			cli_put_json_num(f, ",\"to\":", ax->to);
			cli_put_json_num(f, ",\"step\":", ax->step);
		} else {
			fputs("\"values\":[", f);
			for (size_t k = 0; k < ax->n; k++)
				cli_put_json_num(f, k ? "," : "", ax->values[k]);
			fputc(']', f);
		}
		fputc('}', f);
	}
	fputc(']', f);
	if (st->lhs)
		fprintf(f, ",\"lhs\":%zu,\"seed\":%.0f", st->lhs, (double)st->seed);
	if (pl->band) { /* the band's parameters, and those the study varies */
		fputs(",\"band\":{\"level\":0.95,\"parameters\":[", f);
		for (int j = 0, n = 0; j < pl->band->nfree; j++)
			if (!pl->skip[j])
				fprintf(f, "%s\"%s\"", n++ ? "," : "", pl->band->free[j].name);
		fputs("],\"varied\":[", f);
		for (int j = 0, n = 0; j < pl->band->nfree; j++)
			if (pl->skip[j])
				fprintf(f, "%s\"%s\"", n++ ? "," : "", pl->band->free[j].name);
		fputs("]}", f);
	}
	fprintf(f, ",\"reductions\":[%s],\"points\":[\n", pl->n < ntasks ? "\"mirror\"" : "");
}

/* Point i's model error (docs/dem.md "Model error"): its JSON members,
 * or its CSV cells (SIM_MODEL_ERROR_COLUMNS, each after a comma; empty
 * where the point's settings do not apply). */
static void put_model(FILE *f, const cli_opts *o, const sim_study *st, size_t i, int json)
{
	sim_params p = o->p;
	sim_scene sc = o->sc;
	sim_method m = o->m;
	sim_model_error me;
	if (sim_study_apply(st, i, &p, &sc, &m, NULL, 0) != SIM_OK) {
		fputs(json ? "" : ",,,", f);
		return;
	}
	sim_model_check(&p, &sc, &me);
	if (json) {
		cli_put_json_num(f, ",\"model_error\":", me.checked ? me.error : NAN);
		cli_put_json_num(f, ",\"model_error_uncertainty\":",
				 me.checked ? me.error_uncertainty : NAN);
		fprintf(f, ",\"model_checked\":%s,\"model_check_note\":\"%s\"",
			me.checked ? "true" : "false", me.note);
		return;
	}
	fputc(',', f);
	cli_put_num(f, me.checked ? me.error : NAN, "");
	fputc(',', f);
	cli_put_num(f, me.checked ? me.error_uncertainty : NAN, "");
	fputs(me.checked ? ",true" : ",false", f);
}

/* The sweep's table (CSV: the varied settings, then the daemon's point
 * columns, the model error's among them; or JSON with the daemon's point members, the varied settings
 * first) on f; failures on stderr. Returns the number of failed points. */
static int print_sweep(FILE *f, const cli_opts *o, const pool *pl, int ntasks)
{
	const sim_study *st = pl->st;
	int json = o->format && strcmp(o->format, "json") == 0, failed = 0;
	if (json) {
		print_json_head(f, o, pl, ntasks);
	} else {
		for (size_t a = 0; a < st->naxes; a++)
			fprintf(f, "%s,", st->axis[a].setting->name);
		fputs(SIM_SWEEP_POINT_COLUMNS, f);
		fputs(pl->band ? ",band_lower,band_upper\n" : "\n", f);
	}
	for (int i = 0; i < ntasks; i++) {
		const task *t = &pl->tasks[i];
		const char *rot = st->rotation[(size_t)i / st->npoints] == SIM_CW ? "cw" : "ccw";
		const char *state = t->cancelled ? "cancelled" : t->err == SIM_OK ? "done" : "failed";
		const char *steady = t->r.steady ? "true" : "false";
		if (t->err != SIM_OK && !t->cancelled) {
			char what[200];
			failed++;
			fprintf(stderr, "convsim sweep: %s: %s\n",
				describe_task(st, (size_t)i, what, sizeof what), t->msg);
		}
		const char *nf = json ? "null" : "";
		fputs(json ? "{" : "", f);
		for (size_t a = 0; a < st->naxes; a++) {
			if (json)
				fprintf(f, "\"%s\":", st->axis[a].setting->name);
			cli_put_num(f, sim_study_value(st, (size_t)i % st->npoints, a), nf);
			fputc(',', f);
		}
		fprintf(f, json ? "\"rotation\":\"%s\",\"velocity\":" : "%s,", rot);
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
		fprintf(f, json ? ",\"tol_met\":%s" : ",%s", t->r.tol_met ? "true" : "false");
		put_model(f, o, st, (size_t)i, json);
		if (pl->band) {
			fputs(json ? ",\"band\":{\"lower\":" : ",", f);
			cli_put_num(f, t->band[0], nf);
			fputs(json ? ",\"upper\":" : ",", f);
			cli_put_num(f, t->band[1], nf);
			fputs(json ? "}" : "", f);
		}
		fprintf(f, "%s%s\n", json ? "}" : "", json && i + 1 < ntasks ? "," : "");
	}
	if (json)
		fputs("]}\n", f);
	return failed;
}

/* Measure this rank's share of the study's tasks on o->threads threads,
 * gather every rank's into point order on rank 0 (which derives the
 * mirror images and closes the progress: rank 0 reports its own share
 * while it runs, then the whole). 0, or 1 out of memory (before the
 * measuring: every rank stops with it); an error in the gathering ends
 * every rank (cli_spread_abort). */
static int measure_study(const cli_opts *o, pool *pl, int ntasks)
{
	long *source = calloc((size_t)ntasks, sizeof(long));
	int rc = !source || sim_study_mirror_plan(pl->st, &o->p, &o->sc, &o->m, source) ==
				    (size_t)-1;
	if (rc)
		fprintf(stderr, "convsim sweep: out of memory\n");
	if (cli_spread_agree(pl->sp, rc)) {
		free(source);
		return 1;
	}
	for (int k = 0; k < ntasks; k++) {
		pl->tasks[k].source = source[k];
		if (source[k] < 0)
			pl->run[pl->n++] = k;
	}
	free(source);
	const cli_spread *sp = pl->sp;
	cli_progress_start(&pl->progress, "sweep", o->quiet || sp->rank > 0, 0);
	cli_catch_interrupts();
	pmap_run(o->threads, cli_spread_share(sp, (size_t)pl->n), measure_task, pl, task_done);
	if (cli_spread_gather(sp, pl->tasks, sizeof(task), pl->run, (size_t)pl->n))
		cli_spread_abort(sp, 1);
	if (sp->rank > 0)
		return 0;
	mirror_tasks(pl, ntasks);
	int measured = 0, cancelled = 0;
	for (int k = 0; k < ntasks; k++) {
		cancelled += pl->tasks[k].cancelled;
		measured += pl->tasks[k].source < 0 && !pl->tasks[k].cancelled;
	}
	char done[200];
	snprintf(done, sizeof done, "%d/%d points in %.1f s", measured, pl->n,
		 cli_now() - pl->progress.t0);
	if (sp->ranks > 1)
		snprintf(done + strlen(done), sizeof done - strlen(done),
			 " on %d ranks (%d on rank 0)", sp->ranks, pl->measured);
	if (pl->n < ntasks)
		snprintf(done + strlen(done), sizeof done - strlen(done),
			 "; %d more as their mirror images (mirror reduction)", ntasks - pl->n);
	if (cancelled)
		snprintf(done + strlen(done), sizeof done - strlen(done),
			 "; interrupted: %d points not measured, written as cancelled", cancelled);
	cli_progress_end(&pl->progress, done, 1);
	return 0;
}

/* What a rank but rank 0 says while it parses and plans: stdout to
 * /dev/null, stderr into a scratch file, since every rank finds the same
 * usage errors and rank 0 reports them; said after all only when this
 * rank's outcome differs from rank 0's (quiet_end). */
typedef struct quiet {
	int saved[2]; /* the original fds 1 and 2, or -1 */
	FILE *said;   /* stderr meanwhile, or NULL */
} quiet;

static void quiet_start(quiet *q)
{
	int null = open("/dev/null", O_WRONLY);
	q->said = tmpfile();
	fflush(stdout);
	for (int fd = 1; fd <= 2; fd++) {
		int to = fd == 2 && q->said ? fileno(q->said) : null;
		q->saved[fd - 1] = to >= 0 ? dup(fd) : -1;
		if (q->saved[fd - 1] >= 0)
			dup2(to, fd);
	}
	if (null >= 0)
		close(null);
}

/* Back to the original fds; with tell, what the rank said goes to stderr,
 * each line with the rank's number. */
static void quiet_end(quiet *q, int rank, int tell)
{
	fflush(stdout);
	for (int fd = 1; fd <= 2; fd++)
		if (q->saved[fd - 1] >= 0) {
			dup2(q->saved[fd - 1], fd);
			close(q->saved[fd - 1]);
		}
	if (!q->said)
		return;
	char line[512];
	rewind(q->said);
	while (tell && fgets(line, sizeof line, q->said))
		fprintf(stderr, "(rank %d) %s", rank, line);
	fclose(q->said);
}

/* The options parsed and checked, the study planned, --band-from read
 * into band (with skip): 0, 2 (usage, reported) or -1 (help shown). */
static int prepare(int argc, char **argv, cli_opts *o, sim_study *st, fit_band_source *band,
		   int *skip)
{
	int rc = cli_parse(argc, argv, CMD_SWEEP, o);
	if (rc)
		return rc;
	if (!(o->duration > o->sc.transient)) {
		fprintf(stderr, "convsim sweep: --duration (%g s) must exceed the scene's transient "
				"(%g s): v is measured over [transient, duration]\n",
			o->duration, o->sc.transient);
		return 2;
	}
	if ((rc = cli_plan_study(o, st)) != 0)
		return rc;
	double transient = sim_study_largest(st, "transient", o->sc.transient);
	if (!(o->duration > transient)) { /* each point measures after its own */
		fprintf(stderr, "convsim sweep: --duration (%g s) must exceed the largest "
				"transient the study varies (%g s): v is measured over "
				"[transient, duration]\n",
			o->duration, transient);
		return 2;
	}
	return o->band_from ? cli_band_from(o, st, band, skip) : 0;
}

/* FNV-1a over the arguments: the ranks compare their command lines. */
static unsigned long long argv_hash(int argc, char **argv)
{
	unsigned long long h = 14695981039346656037ULL;
	for (int i = 0; i < argc; i++)
		for (const char *c = argv[i];; c++) {
			h = (h ^ (unsigned char)*c) * 1099511628211ULL;
			if (!*c)
				break;
		}
	return h;
}

/* The sweep on this rank (spread.h): every rank parses, plans and
 * measures its share; rank 0 alone opens --out and writes the table.
 * The ranks check that they have the same options and agree on every
 * early stop, so none waits for another. */
static int sweep_on_rank(int argc, char **argv, const cli_spread *sp)
{
	cli_opts o = {0};
	sim_study st = {0};
	fit_band_source band;
	int skip[FIT_MAX_FREE] = {0}, rc;
	quiet q = {{-1, -1}, NULL};
	if (!cli_spread_same(sp, argv_hash(argc, argv))) {
		if (sp->rank == 0)
			fprintf(stderr, "convsim sweep: the %d ranks were started with different "
					"options; every rank must have the same command line\n",
				sp->ranks);
		return 2;
	}
	if (sp->rank > 0)
		quiet_start(&q);
	rc = prepare(argc, argv, &o, &st, &band, skip);
	/* a rank that fares otherwise than rank 0 (a file only rank 0 can
	 * read, say) says why */
	int other = cli_spread_rank0(sp, rc) != rc;
	if (sp->rank > 0)
		quiet_end(&q, sp->rank, other);
	FILE *out = stdout;
	cli_out file = {0};
	if (rc == 0 && sp->rank == 0 && o.out && !(out = cli_out_open(&file, "sweep", o.out))) {
		out = stdout;
		rc = 1;
	}
	int ntasks = rc ? 0 : (int)sim_study_tasks(&st);
	pool pl = {.o = &o, .st = &st, .sp = sp, .band = o.band_from ? &band : NULL, .skip = skip};
	pl.tasks = calloc(ntasks ? (size_t)ntasks : 1, sizeof(task));
	pl.run = calloc(ntasks ? (size_t)ntasks : 1, sizeof(int));
	if (rc == 0 && (!pl.tasks || !pl.run)) {
		fprintf(stderr, "convsim sweep: rank %d: out of memory\n", sp->rank);
		rc = 1;
	}
	int mine = rc;
	if ((rc = cli_spread_agree(sp, rc)) > 0 && mine == 0 && sp->rank == 0)
		fprintf(stderr, "convsim sweep: another rank could not start the study (its reason "
				"is marked with its rank); every rank stops\n");
	if (rc != 0 || (rc = measure_study(&o, &pl, ntasks)) != 0 || sp->rank > 0) {
		rc = rc < 0 ? 0 : rc; /* -1: help shown */
		goto done;
	}
	rc = print_sweep(out, &o, &pl, ntasks) ? 1 : 0;
	if (cli_interrupted()) {
		fprintf(stderr, "convsim sweep: interrupted (%s): the table has the points measured "
				"before it, the others with state cancelled\n",
			cli_interrupted() == SIGINT ? "SIGINT, Ctrl-C" : "SIGTERM");
		rc = 128 + cli_interrupted();
	}
	if (out != stdout && cli_out_close(&file, 1)) {
		fprintf(stderr, "convsim sweep: --out: writing '%s' failed\n", o.out);
		rc = 1;
	}
done:
	cli_out_close(&file, 0); /* what a study that did not run wrote */
	free(pl.tasks);
	free(pl.run);
	sim_study_free(&st);
	return rc;
}

int cli_cmd_sweep(int argc, char **argv)
{
	cli_spread sp;
	cli_spread_start(&sp);
	int rc = sweep_on_rank(argc, argv, &sp);
	cli_spread_end(&sp);
	return rc;
}
