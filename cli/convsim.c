/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * convsim.c - command-line runner of the simulation core.
 *
 *   convsim run   [--preset NAME] [--set NAME=VALUE ...] [--duration S]
 *                 [--out FILE] [--format csv|json] [--sample-rate HZ]
 *   convsim sweep [--preset NAME] [--beta FROM:TO:STEP] [--rotation cw,ccw]
 *                 [--set NAME=VALUE ...] [--duration S] [--threads N]
 *                 [--out FILE] [--format csv|json]
 *                 [--vary NAME=FROM:TO:STEP|NAME=V1,V2,... ...] [--lhs N --seed S]
 *   convsim fit   (--data FILE | --peaks ROT:DEG,...) --free NAME,... (fit_cmd.c)
 *   convsim list | help [COMMAND] | --version
 *
 * `run` prints a JSON summary on stdout; `sweep` prints v(beta), or a
 * study of v over any settings (core/study.h), per rotation sense. Options come from one table (options.c); numbers are
 * printed as the daemon prints them, and the trajectory and sweep tables
 * have the daemon's columns (core/table.h). Uses the core only. `sweep`
 * is sweep_cmd.c, `fit` fit_cmd.c.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "cli.h"
#include "handover.h"
#include "sim.h"
#include "suggest.h"
#include "tether.h"
#include "table.h"
#include "units.h"

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
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
	cli_put_num(f, stride, "null");
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
		cli_put_num(tf->f, c < SIM_TRAJECTORY_NAMED ? row[c] : tf->colbuf[c - SIM_TRAJECTORY_NAMED],
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
#define NUM(name, v)                                           \
	do {                                                   \
		cli_put_json_num(f, ",\n  \"" name "\": ", (v)); \
	} while (0)
	fprintf(f, "{\n  \"preset\": \"%s\"", o->preset);
	NUM("duration", st->t);
	fprintf(f, ",\n  \"integrator\": {\"method\": \"%s\", \"dt\": ", o->m.name);
	cli_put_num(f, st->dt, "null");
	fputs(", \"rtol\": ", f);
	cli_put_num(f, o->m.rtol, "null");
	fputs(", \"atol\": ", f);
	cli_put_num(f, o->m.atol, "null");
	fprintf(f, ", \"substeps\": %d},\n  \"reductions\": [", st->substeps);
	for (int b = 0, first = 1; sim_reduction_name(b); b++)
		if (st->reductions & (1u << b)) {
			fprintf(f, "%s\"%s\"", first ? "" : ", ", sim_reduction_name(b));
			first = 0;
		}
	fputc(']', f);
	/* how far the column model is from a DEM bed here (docs/dem.md
	 * "Model error"); feed_warning is the note where it is not checked */
	sim_model_error me;
	int mc = sim_model_check(&o->p, &o->sc, &me);
	fputs(",\n  \"feed_warning\": ", f);
	if (mc == 0)
		fprintf(f, "\"%s\"", me.note);
	else
		fputs("null", f);
	NUM("transport_velocity", st->transport_velocity);
	NUM("transport_velocity_uncertainty", st->transport_velocity_uncertainty);
	NUM("model_error", me.checked ? me.error : NAN);
	NUM("model_error_uncertainty", me.checked ? me.error_uncertainty : NAN);
	fprintf(f, ",\n  \"model_checked\": %s,\n  \"model_check_note\": \"%s\"",
		me.checked ? "true" : "false", me.note);
	cli_put_feed_pick(f, o);
	fprintf(f, ",\n  \"steady\": %s", st->steady ? "true" : "false");
	NUM("step_error", st->step_error);
	NUM("tol", st->tol);
	NUM("tol_allowed", st->tol_allowed);
	fprintf(f, ",\n  \"tol_met\": %s", st->tol_met ? "true" : "false");
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
	cli_put_json_num(f, ",\n  \"energy\": {\"input\": ", st->e_input);
	cli_put_json_num(f, ", \"kinetic\": ", st->e_kinetic);
	cli_put_json_num(f, ", \"potential\": ", st->e_potential);
	cli_put_json_num(f, ", \"dissipated\": ", st->e_dissipated);
	cli_put_json_num(f, ", \"residual\": ", st->e_residual);
	fputs("},\n  \"error\": ", f);
	if (err != SIM_OK)
		fprintf(f, "\"%s\"\n}\n", sim_last_error(s));
	else
		fputs("null\n}\n", f);
#undef NUM
}

/* What --out would take, before anything is built (cli_out_fits): the
 * row at t = 0 and one a sample, the named columns and at most every
 * feed column. 0, or 2 after the refusal. */
static int run_out_fits(const cli_opts *o, long nsamples)
{
	int width = SIM_TRAJECTORY_NAMED + (o->sc.feed ? o->sc.columns : 0);
	return o->out ? cli_out_fits("run", (double)nsamples + 1, width, o->max_output) : 0;
}

static int cmd_run(int argc, char **argv)
{
	cli_opts o = {0};
	int rc = cli_parse(argc, argv, CMD_RUN, &o);
	if (rc)
		return rc < 0 ? 0 : rc;
	if (o.sc.feed_model == SIM_FEED_AUTO && cli_feed_auto(&o) != 0)
		return 2;
	if (o.sc.feed_model == SIM_FEED_EXTERNAL)
		return cli_run_coupled(&o);
	long nsamples = (long)ceil(o.duration * o.rate - 1e-9);
	if (run_out_fits(&o, nsamples))
		return 2;
	char msg[200];
	int err;
	double w0 = cli_now(), c0 = cpu_now(); /* the steady start's settling included */
	sim *s = sim_new(&o.p, &o.sc, &o.m, &err, msg, sizeof msg);
	if (!s) {
		fprintf(stderr, "convsim run: %s\n", msg);
		return 2;
	}
	traj_file tf = {.json = cli_wants_json(o.format, o.out), .columns = sim_columns(s)};
	cli_out out = {0};
	if (o.out) {
		tf.f = cli_out_open(&out, "run", o.out);
		tf.colbuf = calloc(SIM_MAX_COLUMNS, sizeof(double));
		if (!tf.f || !tf.colbuf) {
			cli_out_close(&out, 0);
			free(tf.colbuf);
			sim_free(s);
			return 1;
		}
	}
	sim_status st;
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
		write_failed = cli_out_close(&out, 1);
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

/* The command's work: its exit status (main checks stdout after it). */
static int dispatch(int argc, char **argv)
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
	case CMD_SWEEP: return cli_cmd_sweep(argc - 1, argv + 1);
	case CMD_FIT: return cli_cmd_fit(argc - 1, argv + 1);
	case CMD_LIST: return cmd_list(argc - 1, argv + 1);
	default: return unknown_command(c);
	}
}

/* What went to stdout (a summary, a table, a fit's result, the help)
 * reached it: a full disk or a closed stdout is exit 1 with the reason
 * on stderr, never a 0 over a table cut short. rc is the command's. */
static int stdout_written(int argc, char **argv, int rc)
{
	errno = 0;
	int flushed = fflush(stdout) == 0;
	if (flushed && !ferror(stdout))
		return rc;
	const char *c = argc > 1 && cli_command(argv[1]) ? argv[1] : NULL;
	fprintf(stderr, "convsim%s%s: writing to stdout failed%s%s\n", c ? " " : "", c ? c : "",
		!flushed && errno ? ": " : "", !flushed && errno ? strerror(errno) : "");
	return rc ? rc : 1;
}

int main(int argc, char **argv)
{
	sim_tether_from_env(); /* the test suite's: end with the test */
	cli_handover_init(argv);
	return stdout_written(argc, argv, dispatch(argc, argv));
}
