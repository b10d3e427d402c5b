/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * cli.h - what the files of the command-line runner share: the option
 * table (one entry per option: its names, argument, unit, default and
 * meaning, from which both getopt_long's table and the help are made),
 * near-miss suggestions, number parsing with specific messages, and the
 * progress reporter. Every message starts with "convsim" and the command.
 */
#ifndef CONVSIM_CLI_H
#define CONVSIM_CLI_H

#include <stddef.h>
#include <stdio.h>

#include "sim.h"
#include "study.h"

#define CONVSIM_VERSION "1.0.0"

/* Commands, as bits (an option belongs to one or more). */
enum { CMD_RUN = 1, CMD_SWEEP = 2, CMD_LIST = 4, CMD_FIT = 8 };

enum {
	OPT_PRESET = 256, OPT_SET, OPT_DURATION, OPT_OUT, OPT_FORMAT, OPT_RATE, OPT_BETA,
	OPT_ROTATION, OPT_THREADS, OPT_QUIET, OPT_HELP, OPT_DATA, OPT_PEAKS, OPT_FREE, OPT_PRIOR,
	OPT_CURVE_STEP, OPT_FD_STEP, OPT_MAX_ITER, OPT_STARTS, OPT_COUPLING_STEPS, OPT_MAX_DEM_COST, OPT_VARY,
	OPT_LHS, OPT_SEED, OPT_BAND_FROM, OPT_MAX_OUTPUT
};

/* The default measuring window (s after the transient) of run, sweep and
 * fit: with the `steady` start, 4 s keep all 74 points of czubak2016
 * within 1 % of the converged reference (docs/accuracy.md "Accuracy"). */
#define MEASURE_WINDOW 4.0

/* The most --vary options a sweep takes (SIM_STUDY_MAX_AXES). */
#define CLI_MAX_VARY 8

/* A command's options as parsed (parse.c): the model (preset and --set),
 * and each command's own options. */
typedef struct cli_opts {
	const char *cmd;
	sim_params p;
	sim_scene sc;
	sim_method m;
	const char *preset, *out, *format, *beta, *rotation;
	double duration, rate;
	int threads, quiet;
	int coupling_steps; /* feed_model liggghts: machine steps per coupling interval */
	/* sweep: --vary NAME=SPEC in the order given, --lhs N, --seed S */
	const char *vary[CLI_MAX_VARY];
	int nvary, lhs;
	int beta_at; /* sweep: --beta's place among the --vary (it is one) */
	double seed;
	const char *band_from; /* sweep: a fit's JSON result (bands on every point) */
	/* fit */
	const char *data, *peaks, *free_list, *prior_list;
	double curve_step, fd_step; /* deg; relative */
	int max_iter, starts;
	/* run --set feed_model=auto: the pick (feed_auto.c), picked 1 */
	sim_feed_choice pick;
	int picked;
	double max_dem_cost; /* run --max-dem-cost: CPU s a simulated second, INFINITY none */
	double max_output;   /* run --max-output: bytes --out may take */
} cli_opts;

/* The first pass over command cmd's options: help (shown, -1), a wrong
 * option or an operand (reported, 2), else 0 with --preset in *preset
 * (may be NULL for commands without one). */
int cli_first_pass(int argc, char **argv, unsigned cmd, const char **preset);
/* Parse command cmd's options into *o (the preset's model, --set on top,
 * defaults). Returns 0, 2 (usage error, reported) or -1 (help shown:
 * exit 0). */
int cli_parse(int argc, char **argv, unsigned cmd, cli_opts *o);

/* convsim fit (fit_cmd.c): exit status 0, 1 (the fit failed or a file
 * could not be written) or 2 (usage). */
int cli_cmd_fit(int argc, char **argv);
/* convsim sweep (sweep_cmd.c): exit status 0, 1 (a point failed or the
 * table could not be written) or 2 (usage). */
int cli_cmd_sweep(int argc, char **argv);
/* The study of sweep's options into *st (study_opts.c): --beta (default
 * 0:180:10 when nothing is varied) and every --vary in the order given,
 * --lhs, --seed, the senses of --rotation, planned (sim_study_plan). 0, or
 * 2 after a message; st is the caller's to free either way. */
int cli_plan_study(const cli_opts *o, sim_study *st);

/* Output (options.c): a number as the daemon prints it (shortest round
 * trip), non-finite as `nonfinite`; whether a file is JSON (--format, else
 * the name's extension). */
void cli_put_num(FILE *f, double v, const char *nonfinite);
/* JSON text head (a member's name and colon, with what comes before it),
 * then v as cli_put_num writes it, null when not finite. */
void cli_put_json_num(FILE *f, const char *head, double v);
int cli_wants_json(const char *format, const char *file);

/* --out (out_file.c): a regular or new file is written as PATH.partial and
 * renamed over PATH when closed with all of it written, so a command that
 * fails or is killed leaves an earlier PATH as it was (and, killed, its
 * PATH.partial); a device, FIFO or link is written in place. Open: the
 * stream, or NULL with "convsim CMD: --out: cannot write ..." on stderr.
 * Close: keep 0 drops what was written; nonzero when keeping failed (a
 * write, the close or the rename), PATH then as it was. */
typedef struct cli_out {
	FILE *f;
	const char *path;
	char *partial;
} cli_out;
FILE *cli_out_open(cli_out *w, const char *cmd, const char *path);
/* The most bytes a trajectory of rows rows of width values takes in
 * --out, CSV or JSON: each value at most SIM_FMT_DOUBLE_MAX bytes and a
 * separator, 3 more a row (JSON's ",\n[" and "]"), 4096 for the header
 * and the end. */
double cli_out_bound(double rows, int width);
/* run's check before it starts: 0 if such a trajectory fits in
 * max_bytes, else 2 after "convsim CMD: --out would write ..." on stderr
 * with the estimate, the limit and the --max-output that allows it. */
int cli_out_fits(const char *cmd, double rows, int width, double max_bytes);
int cli_out_close(cli_out *w, int keep);
/* The whole of file path (stdin for "-", at most 16 MB), malloc'd (the
 * caller frees); NULL after "convsim CMD: --OPT: ..." on stderr. */
char *cli_slurp(const char *cmd, const char *opt, const char *path);

/* convsim run with feed_model = liggghts: the machine coupled to a
 * LIGGGHTS bed (dem/cli/run_coupled.c, in convsim-mpi where LIGGGHTS is
 * installed; in the plain convsim cli/coupled_none.c, which hands
 * the run over to convsim-mpi or says how to get it). Exit status as run. */
int cli_run_coupled(const cli_opts *o);
/* What this binary knows of a LIGGGHTS bed for o's scene (sim_feed_pick):
 * convsim-mpi with LIGGGHTS its cost (dem_bed_spec_cost), the plain
 * convsim whether it can hand the run to one; the limit --max-dem-cost. */
void cli_liggghts_here(const cli_opts *o, sim_feed_liggghts *lg);
/* run's feed_model auto (feed_auto.c): pick, set o->sc.feed_model, say
 * the pick on stderr. 0, or 2 after the refusal on stderr. */
int cli_feed_auto(cli_opts *o);
/* The summary's member ",\n  \"feed_model_pick\": {...}" where auto
 * picked, else nothing. */
void cli_put_feed_pick(FILE *f, const cli_opts *o);

typedef struct cli_opt {
	unsigned cmds;    /* CMD_* bits: the commands that take it */
	int id;           /* OPT_* */
	const char *name; /* long name, without "--" */
	char key;         /* short letter, or 0 */
	const char *arg;  /* metavariable, NULL for a flag */
	const char *unit; /* of the argument, or NULL */
	const char *def;  /* the default as the help shows it, or NULL */
	const char *doc;
} cli_opt;

/* The most options one table holds (convsim's, convsim-dem's). */
#define CLI_MAX_OPTIONS 64

/* The help lines of the options of table opts (n rows) that command bit
 * cmd takes: flag, argument and text, then unit and default. */
void cli_help_options(FILE *f, const cli_opt *opts, size_t n, unsigned cmd);
/* The next option of argv in table opts (n rows, at most CLI_MAX_OPTIONS)
 * for command bit cmd, as cli_next_option; messages start with who
 * ("convsim run") and point to hint ("convsim help run"). */
int cli_next_option_in(const cli_opt *opts, size_t n, unsigned cmd, const char *who,
		       const char *hint, int argc, char **argv, const char **arg);

/* The command bit for a command name, 0 if unknown. */
unsigned cli_command(const char *name);
/* Print command cmd's help (usage, every option with unit and default)
 * on f; cmd 0 prints the overview. */
void cli_help(FILE *f, unsigned cmd);
/* The next option of argv for command cmd (getopt_long over the table):
 * OPT_* with *arg set, -1 at the end, or 0 after printing a specific
 * error (unknown option with a suggestion, missing argument). */
int cli_next_option(int argc, char **argv, unsigned cmd, const char **arg);
/* Index of the first operand after the options (getopt's optind). */
int cli_operand_index(void);
/* Parse the same argv again from its start. */
void cli_restart_options(void);

/* " (did you mean 'X'?)" for a near miss, else "": into buf. */
const char *cli_did_you_mean(char *buf, size_t len, const char *suggestion);

/* Parse text as a plain decimal number (decimal.h: no 0x10, no spaces)
 * in [lo, hi] (lo excluded if lo_open). On error prints "convsim CMD:
 * --NAME must be ..., got 'text'" and returns -1. */
int cli_number(const char *cmd, const char *opt, const char *unit, const char *text,
	       double lo, double hi, int lo_open, double *out);

/* text as 1 to max plain decimal numbers separated by sep ("0:90:2" with
 * ':') into v[0..): their count, or -1 (no message) when a field is
 * empty or not one, or there are more than max. */
int cli_numbers(const char *text, char sep, double *v, int max);

/* Progress on stderr: a bar redrawn in place on a terminal, plain lines
 * (every tenth of the work) otherwise. Reports start after min_wall
 * seconds of wall time (0: at once). */
typedef struct cli_progress {
	const char *label;
	int tty, quiet, shown, decile;
	double t0, last, min_wall;
} cli_progress;
void cli_progress_start(cli_progress *p, const char *label, int quiet, double min_wall);
/* done of total units; detail is shown after the count (may be ""). */
void cli_progress_update(cli_progress *p, double done, double total, const char *unit,
			 const char *detail);
/* The closing line (always for force, else only if something was shown). */
void cli_progress_end(cli_progress *p, const char *summary, int force);
double cli_now(void);

/* Interruptions (interrupt.c): from cli_catch_interrupts on, SIGINT and
 * SIGTERM are noted, not fatal, so that a long job can stop starting
 * work and write what it has (marked); the handler is reset by the first
 * signal, so a second one ends the program at once. cli_interrupted():
 * the signal noted, else 0. */
void cli_catch_interrupts(void);
int cli_interrupted(void);

#endif
