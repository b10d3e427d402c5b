/*
 * convsim.c - command-line runner of the simulation core.
 *
 *   convsim run   [--preset NAME] [--set NAME=VALUE ...] [--duration S]
 *                 [--out FILE] [--format csv|json] [--sample-rate HZ]
 *   convsim sweep [--preset NAME] [--beta FROM:TO:STEP] [--rotation cw,ccw]
 *                 [--set NAME=VALUE ...] [--duration S] [--threads N]
 *                 [--out FILE] [--format csv|json]
 *   convsim fit   (--data FILE | --peaks ROT:DEG,...) --free NAME,... (fit_cmd.c)
 *   convsim list | help [COMMAND] | --version
 *
 * `run` prints a JSON summary on stdout; `sweep` prints v(beta) per
 * rotation sense. Options come from one table (options.c); numbers are
 * printed as the daemon prints them, and the trajectory and sweep tables
 * have the daemon's columns (core/table.h). Uses the core only.
 */
#include <errno.h>
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "sim.h"
#include "suggest.h"
#include "table.h"
#include "units.h"

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* Print a number as the daemon does (shortest round trip); non-finite as
 * `nonfinite`. */
static void put_num(FILE *f, double v, const char *nonfinite)
{
	char num[40];
	sim_fmt_double(num, sizeof num, v, nonfinite);
	fputs(num, f);
}

/* ---- run ---- */

/* The trajectory file: the daemon's columns (core/table.h), as CSV with a
 * header line or as the daemon's JSON {"fields","units","stride","rows",
 * "count"}. */
typedef struct traj_file {
	FILE *f;
	int json, columns;
	long rows;
	double *colbuf;
} traj_file;

static void traj_begin(traj_file *tf, double stride)
{
	FILE *f = tf->f;
	int width = SIM_TRAJECTORY_NAMED + tf->columns;
	fputs(tf->json ? "{\"fields\":[" : "", f);
	for (int c = 0; c < width; c++) {
		const char *q = tf->json ? "\"" : "";
		fputs(c ? "," : "", f);
		if (c < SIM_TRAJECTORY_NAMED)
			fprintf(f, "%s%s%s", q, sim_trajectory_name(c), q);
		else
			fprintf(f, "%scolumn_%d%s", q, c - SIM_TRAJECTORY_NAMED + 1, q);
	}
	if (!tf->json) {
		fputc('\n', f);
		return;
	}
	fputs("],\"units\":[", f);
	for (int c = 0; c < width; c++)
		fprintf(f, "%s\"%s\"", c ? "," : "",
			c < SIM_TRAJECTORY_NAMED ? sim_trajectory_unit(c) : "m");
	fputs("],\"stride\":", f);
	put_num(f, stride, "null");
	fputs(",\"rows\":[", f);
}

static void traj_row(traj_file *tf, const sim *s, const sim_status *st)
{
	double row[SIM_TRAJECTORY_NAMED];
	sim_trajectory_row(st, row);
	sim_column_displacement(s, tf->colbuf);
	const char *nonfinite = tf->json ? "null" : "";
	if (tf->json)
		fputs(tf->rows ? ",\n[" : "\n[", tf->f);
	for (int c = 0; c < SIM_TRAJECTORY_NAMED + tf->columns; c++) {
		fputs(c ? "," : "", tf->f);
		put_num(tf->f, c < SIM_TRAJECTORY_NAMED ? row[c] : tf->colbuf[c - SIM_TRAJECTORY_NAMED],
			nonfinite);
	}
	fputs(tf->json ? "]" : "\n", tf->f);
	tf->rows++;
}

/* The run's JSON summary on stdout: final status, cost (cpu, wall in s)
 * and the error, if any. */
static void print_summary(const cli_opts *o, const sim *s, const sim_status *st, int err, double cpu,
			  double wall)
{
	FILE *f = stdout;
#define NUM(name, v)                                   \
	do {                                           \
		fputs(",\n  \"" name "\": ", f);       \
		put_num(f, (v), "null");               \
	} while (0)
	fprintf(f, "{\n  \"preset\": \"%s\"", o->preset);
	NUM("duration", st->t);
	fprintf(f, ",\n  \"integrator\": {\"method\": \"%s\", \"dt\": ", o->m.name);
	put_num(f, st->dt, "null");
	fputs(", \"rtol\": ", f);
	put_num(f, o->m.rtol, "null");
	fputs(", \"atol\": ", f);
	put_num(f, o->m.atol, "null");
	fprintf(f, ", \"substeps\": %d},\n  \"reductions\": [", st->substeps);
	for (int b = 0, first = 1; sim_reduction_name(b); b++)
		if (st->reductions & (1u << b)) {
			fprintf(f, "%s\"%s\"", first ? "" : ", ", sim_reduction_name(b));
			first = 0;
		}
	fputc(']', f);
	/* the column model outside the domain checked against a DEM bed */
	char why[400];
	fputs(",\n  \"feed_warning\": ", f);
	if (sim_feed_validated(&o->p, &o->sc, why, sizeof why) == 0)
		fprintf(f, "\"%s\"", why);
	else
		fputs("null", f);
	NUM("transport_velocity", st->transport_velocity);
	NUM("transport_velocity_uncertainty", st->transport_velocity_uncertainty);
	fprintf(f, ",\n  \"steady\": %s", st->steady ? "true" : "false");
	NUM("transport_periods", st->transport_periods);
	NUM("rotor_speed", st->rotor_speed_mean);
	NUM("motor_torque", st->motor_torque_mean);
	NUM("power", st->power_mean);
	NUM("beta", sim_table_user("beta", st->beta));
	NUM("feed_displacement", st->feed_displacement);
	fprintf(f, ",\n  \"steps\": %llu,\n  \"rhs_evals\": %llu,\n  \"n_dof\": %d",
		(unsigned long long)st->steps, (unsigned long long)st->rhs_evals, st->n_dof);
	NUM("cpu_seconds", cpu);
	NUM("wall_seconds", wall);
	NUM("real_time_factor", cpu > 0 ? st->t / cpu : NAN);
	fputs(",\n  \"energy\": {\"input\": ", f);
	put_num(f, st->e_input, "null");
	fputs(", \"kinetic\": ", f);
	put_num(f, st->e_kinetic, "null");
	fputs(", \"potential\": ", f);
	put_num(f, st->e_potential, "null");
	fputs(", \"dissipated\": ", f);
	put_num(f, st->e_dissipated, "null");
	fputs(", \"residual\": ", f);
	put_num(f, st->e_residual, "null");
	fputs("},\n  \"error\": ", f);
	if (err != SIM_OK)
		fprintf(f, "\"%s\"\n}\n", sim_last_error(s));
	else
		fputs("null\n}\n", f);
#undef NUM
}

/* The file's format: --format, else by the name's extension. */
static int wants_json(const char *format, const char *file)
{
	if (format)
		return strcmp(format, "json") == 0;
	size_t n = file ? strlen(file) : 0;
	return n > 5 && strcmp(file + n - 5, ".json") == 0;
}

static FILE *open_out(const cli_opts *o)
{
	FILE *f = fopen(o->out, "w");
	if (!f) {
		fprintf(stderr, "convsim %s: --out: cannot write '%s': %s\n", o->cmd, o->out,
			strerror(errno));
	}
	return f;
}

static int cmd_run(int argc, char **argv)
{
	cli_opts o = {0};
	int rc = cli_parse(argc, argv, CMD_RUN, &o);
	if (rc)
		return rc < 0 ? 0 : rc;
	if (o.sc.feed_model == SIM_FEED_EXTERNAL)
		return cli_run_coupled(&o);
	char msg[200];
	int err;
	double w0 = cli_now(), c0 = cpu_now(); /* the steady start's settling included */
	sim *s = sim_new(&o.p, &o.sc, &o.m, &err, msg, sizeof msg);
	if (!s) {
		fprintf(stderr, "convsim run: %s\n", msg);
		return 2;
	}
	traj_file tf = {.json = wants_json(o.format, o.out), .columns = sim_columns(s)};
	if (o.out) {
		tf.f = open_out(&o);
		tf.colbuf = calloc(SIM_MAX_COLUMNS, sizeof(double));
		if (!tf.f || !tf.colbuf) {
			if (tf.f)
				fclose(tf.f);
			free(tf.colbuf);
			sim_free(s);
			return 1;
		}
	}
	sim_status st;
	long nsamples = (long)ceil(o.duration * o.rate - 1e-9);
	if (tf.f) {
		sim_get_status(s, &st);
		traj_begin(&tf, 1.0 / o.rate);
		traj_row(&tf, s, &st);
	}
	cli_progress pr;
	cli_progress_start(&pr, "run", o.quiet, 1.0);
	err = SIM_OK;
	/* without a trajectory no sample is read but the last: observe
	 * every 50 ms of simulated time only (for the progress line). The
	 * simulation does not depend on when it is observed (sim_advance), so
	 * the summary is the same to the last bit. */
	long stride = tf.f ? 1 : (long)fmax(1.0, floor(0.05 * o.rate));
	for (long i = stride < nsamples ? stride : nsamples; err == SIM_OK;
	     i = i < nsamples && i + stride > nsamples ? nsamples : i + stride) {
		if (i > nsamples)
			break;
		double t = i == nsamples ? o.duration : (double)i / o.rate;
		err = sim_advance(s, t);
		if (tf.f && err == SIM_OK) {
			sim_get_status(s, &st);
			traj_row(&tf, s, &st);
		}
		cli_progress_update(&pr, t, o.duration, "s simulated", "");
	}
	double wall = cli_now() - w0, cpu = cpu_now() - c0;
	char done[96];
	snprintf(done, sizeof done, "%g s simulated in %.1f s", o.duration, wall);
	cli_progress_end(&pr, done, 0);
	int write_failed = 0;
	if (tf.f) {
		if (tf.json)
			fprintf(tf.f, "],\"count\":%ld}\n", tf.rows);
		write_failed = ferror(tf.f) | (fclose(tf.f) != 0);
		free(tf.colbuf);
		if (write_failed)
			fprintf(stderr, "convsim run: --out: writing '%s' failed\n", o.out);
	}
	sim_get_status(s, &st);
	print_summary(&o, s, &st, err, cpu, wall);
	if (err != SIM_OK)
		fprintf(stderr, "convsim run: %s\n", sim_last_error(s));
	sim_free(s);
	return err == SIM_OK && !write_failed ? 0 : 1;
}

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
	int n, next, done;
	cli_progress progress;
	pthread_mutex_t lock;
} pool;

static void *worker(void *arg)
{
	pool *pl = arg;
	for (;;) {
		pthread_mutex_lock(&pl->lock);
		int i = pl->next < pl->n ? pl->run[pl->next++] : -1;
		pthread_mutex_unlock(&pl->lock);
		if (i < 0)
			return NULL;
		task *t = &pl->tasks[i];
		sim_params p = pl->o->p;
		p.beta = t->beta * RAD_PER_DEG;
		p.rotation = t->rotation;
		t->err = sim_measure(&p, &pl->o->sc, &pl->o->m, pl->o->duration, &t->r, t->msg,
				     sizeof t->msg);
		pthread_mutex_lock(&pl->lock);
		pl->done++;
		char detail[48];
		snprintf(detail, sizeof detail, " (last: %g deg %s)", t->beta,
			 t->rotation == SIM_CW ? "cw" : "ccw");
		cli_progress_update(&pl->progress, pl->done, pl->n, "points", detail);
		pthread_mutex_unlock(&pl->lock);
	}
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
		put_num(f, o->duration, "null");
		fputs(",\"transient\":", f);
		put_num(f, o->sc.transient, "null");
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
		put_num(f, t->beta, nf);
		fprintf(f, json ? ",\"rotation\":\"%s\",\"velocity\":" : ",%s,", rot);
		put_num(f, t->r.transport_velocity, nf);
		fputs(json ? ",\"uncertainty\":" : ",", f);
		put_num(f, t->r.uncertainty, nf);
		if (json)
			fprintf(f, ",\"steady\":%s,\"state\":\"%s\",\"mirrored\":%s}%s\n", steady,
				state, t->source >= 0 ? "true" : "false", i + 1 < ntasks ? "," : "");
		else
			fprintf(f, ",%s,%s\n", steady, state);
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

static int cmd_sweep(int argc, char **argv)
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
	if (o.out && !(out = open_out(&o)))
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
	pthread_mutex_init(&pl.lock, NULL);
	cli_progress_start(&pl.progress, "sweep", o.quiet, 0);
	pthread_t th[64];
	int nth = o.threads < pl.n ? o.threads : pl.n;
	for (int i = 0; i < nth; i++)
		pthread_create(&th[i], NULL, worker, &pl);
	for (int i = 0; i < nth; i++)
		pthread_join(th[i], NULL);
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
	pthread_mutex_destroy(&pl.lock);
	free(pl.tasks);
	free(pl.run);
	return failed || write_failed ? 1 : 0;
}

/* ---- list ---- */

static int cmd_list(int argc, char **argv)
{
	int rc = cli_first_pass(argc, argv, CMD_LIST, NULL);
	if (rc)
		return rc < 0 ? 0 : rc;
	size_t n;
	const sim_setting *t = sim_settings(&n);
	printf("%-16s %-11s %-9s %-24s %s\n", "name", "group", "unit", "range", "meaning");
	for (size_t i = 0; i < n; i++) {
		char range[96], lo[40], hi[40];
		if (t[i].kind == SIM_KIND_ENUM) {
			snprintf(range, sizeof range, "%s", t[i].choices);
		} else if (t[i].kind == SIM_KIND_BOOL) {
			snprintf(range, sizeof range, "true|false");
		} else {
			sim_fmt_double(lo, sizeof lo, t[i].min, "");
			sim_fmt_double(hi, sizeof hi, t[i].max, "");
			snprintf(range, sizeof range, "[%s, %s]", lo, hi);
		}
		printf("%-16s %-11s %-9s %-24s %s\n", t[i].name, t[i].group, t[i].unit, range,
		       t[i].doc);
	}
	const sim_method_info *const *mi = sim_methods(&n);
	printf("\nintegrators:\n");
	for (size_t i = 0; i < n; i++)
		printf("  %-8s order %d%s: %s\n", mi[i]->name, mi[i]->order,
		       mi[i]->adaptive ? ", adaptive" : "", mi[i]->doc);
	return 0;
}

static int unknown_command(const char *name)
{
	static const char *const names[] = {"run", "sweep", "fit", "list", "help"};
	char hint[96];
	fprintf(stderr, "convsim: unknown command '%s'%s; 'convsim help' lists the commands\n", name,
		cli_did_you_mean(hint, sizeof hint, sim_suggest(name, names, 5, sizeof *names)));
	return 2;
}

int main(int argc, char **argv)
{
	if (argc < 2) {
		cli_help(stderr, 0);
		return 2;
	}
	const char *c = argv[1];
	if (strcmp(c, "--version") == 0 || strcmp(c, "-V") == 0 || strcmp(c, "version") == 0) {
		printf("convsim %s\n", CONVSIM_VERSION);
		return 0;
	}
	if (strcmp(c, "--help") == 0 || strcmp(c, "-h") == 0 || strcmp(c, "help") == 0) {
		if (argc > 2 && strcmp(c, "help") == 0) {
			unsigned cmd = cli_command(argv[2]);
			if (!cmd)
				return unknown_command(argv[2]);
			cli_help(stdout, cmd);
			return 0;
		}
		cli_help(stdout, 0);
		return 0;
	}
	switch (cli_command(c)) {
	case CMD_RUN: return cmd_run(argc - 1, argv + 1);
	case CMD_SWEEP: return cmd_sweep(argc - 1, argv + 1);
	case CMD_FIT: return cli_cmd_fit(argc - 1, argv + 1);
	case CMD_LIST: return cmd_list(argc - 1, argv + 1);
	default: return unknown_command(c);
	}
}
