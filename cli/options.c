/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * options.c - the command line's options as one table: getopt_long's
 * table and the help are both made from it, so they cannot drift. Also
 * the near-miss suggestions ("did you mean"), number parsing with
 * specific messages, and the progress reporter (a bar on a terminal,
 * plain lines into a file or pipe).
 */
#include <errno.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "cli.h"
#include "decimal.h"
#include "suggest.h"
#include "table.h"

#define RS (CMD_RUN | CMD_SWEEP | CMD_FIT)
#define ALL (CMD_RUN | CMD_SWEEP | CMD_LIST | CMD_FIT)

static const cli_opt options[] = {
	{RS, OPT_PRESET, "preset", 'p', "NAME", NULL, "czubak2016",
	 "starting values for every setting"},
	{RS, OPT_SET, "set", 's', "NAME=VALUE", NULL, NULL,
	 "set one setting, in the unit `convsim list` shows; repeatable"},
	{CMD_RUN, OPT_DURATION, "duration", 'd', "S", "s", "transient + 4",
	 "simulated time to run (4 s for czubak2016, whose transient is 0)"},
	{CMD_SWEEP, OPT_DURATION, "duration", 'd', "S", "s", "transient + 4",
	 "simulated time per point; v is measured after the transient (a feed thrown hard: over as long a window from 8 s, finer steps)"},
	{CMD_RUN, OPT_OUT, "out", 'o', "FILE", NULL, "none",
	 "also write the trajectory (the daemon's columns) to FILE"},
	{CMD_SWEEP, OPT_OUT, "out", 'o', "FILE", NULL, "stdout", "write the v(beta) table to FILE"},
	{CMD_RUN, OPT_FORMAT, "format", 'f', "csv|json", NULL, "by FILE's extension, else csv",
	 "format of the trajectory file"},
	{CMD_SWEEP, OPT_FORMAT, "format", 'f', "csv|json", NULL, "csv", "format of the v(beta) table"},
	{CMD_RUN, OPT_RATE, "sample-rate", 'r', "HZ", "Hz", "1000",
	 "trajectory rows per simulated second, in (0, 1e6]"},
	{CMD_RUN, OPT_BETA, "beta", 'b', "DEG", "deg", "the preset's (38)",
	 "guide angle in [0, 180]; the same as --set beta=DEG"},
	{CMD_RUN, OPT_ROTATION, "rotation", 0, "cw|ccw", NULL, "the preset's (cw)",
	 "cw (the paper's clockwise, rotor speed > 0) or ccw; the same as --set rotation=..."},
	{CMD_RUN, OPT_MAX_OUTPUT, "max-output", 0, "BYTES", "bytes", "1e9 (1 GB)",
	 "a run whose --out could take more (rows x columns, at most 25 bytes a value) is refused "
	 "before it starts"},
	{CMD_RUN, OPT_COUPLING_STEPS, "coupling-steps", 0, "N", NULL, "1",
	 "feed_model=liggghts: machine steps per coupling interval with the bed (docs/dem.md)"},
	{CMD_RUN, OPT_MAX_DEM_COST, "max-dem-cost", 0, "S", "CPU s per simulated s", "none",
	 "feed_model=auto: a LIGGGHTS bed expected to cost more is not picked "
	 "(docs/feed-models.md)"},
	{CMD_SWEEP, OPT_BETA, "beta", 'b', "FROM:TO:STEP", "deg", "0:180:10",
	 "guide angles in [0, 180], or one angle; the same as --vary beta=FROM:TO:STEP"},
	{CMD_SWEEP, OPT_VARY, "vary", 'V', "NAME=FROM:TO:STEP|NAME=V1,V2,...", NULL, NULL,
	 "vary a number setting of `convsim list` over a range or a list, in its unit; "
	 "repeatable (a grid, the first outermost); without beta varied, beta stays the model's"},
	{CMD_SWEEP, OPT_LHS, "lhs", 0, "N", NULL, "the full grid",
	 "a Latin-hypercube sample of N points over the --vary ranges instead of their grid"},
	{CMD_SWEEP, OPT_SEED, "seed", 0, "S", NULL, "1", "seed of the --lhs sample, 0..4294967295"},
	{CMD_SWEEP, OPT_BAND_FROM, "band-from", 0, "FIT.json", NULL, NULL,
	 "the JSON result of convsim fit: its fitted values on the model and a 95 % band on every "
	 "point from its covariance (a varied parameter takes the grid's values and leaves the band)"},
	{CMD_SWEEP, OPT_ROTATION, "rotation", 0, "cw,ccw", NULL, "cw,ccw",
	 "cw (the paper's clockwise, rotor speed > 0), ccw, or both"},
	{CMD_SWEEP | CMD_FIT, OPT_THREADS, "threads", 'j', "N", NULL, "2",
	 "simulations run in parallel, 1..64"},
	{CMD_FIT, OPT_DURATION, "duration", 'd', "S", "s", "transient + 4",
	 "simulated time per model evaluation; v is measured after the transient"},
	{CMD_FIT, OPT_DATA, "data", 0, "FILE", NULL, NULL,
	 "measured points as CSV with the header beta,rotation,v[,sigma] (deg, cw|ccw, m/s, m/s); "
	 "- reads stdin"},
	{CMD_FIT, OPT_PEAKS, "peaks", 0, "ROT:DEG[:SIGMA],...", "deg", NULL,
	 "measured peak positions of v(beta) instead of points, e.g. cw:38,cw:128"},
	{CMD_FIT, OPT_FREE, "free", 0, "NAME[:MIN:MAX],...", NULL, NULL,
	 "free parameters by setting name, bounds in the setting's unit (default its range); "
	 "they start at the model's values (--preset, --set)"},
	{CMD_FIT, OPT_PRIOR, "prior", 0, "NAME:MEAN:SD|NAME:MEAN:xFACTOR,...", NULL, NULL,
	 "Gaussian priors on free parameters, in the setting's unit: normal with MEAN and SD, or "
	 "log-normal with median MEAN and FACTOR (MEAN/FACTOR..MEAN*FACTOR one standard deviation); "
	 "needs sigma with the data"},
	{CMD_FIT, OPT_CURVE_STEP, "curve-step", 0, "DEG", "deg", "5",
	 "grid of the fitted and the original curve over [0, 180]; 0: none"},
	{CMD_FIT, OPT_FD_STEP, "fd-step", 0, "REL", NULL, "0.05",
	 "finite-difference step relative to each parameter's value"},
	{CMD_FIT, OPT_MAX_ITER, "max-iter", 0, "N", NULL, "30", "Levenberg-Marquardt iterations, at most"},
	{CMD_FIT, OPT_STARTS, "starts", 0, "N", NULL, "1",
	 "runs from the start and N - 1 points of a Halton design over the bounds; the lowest "
	 "cost wins"},
	{CMD_FIT, OPT_OUT, "out", 'o', "FILE", NULL, "stdout", "write the result to FILE"},
	{CMD_FIT, OPT_FORMAT, "format", 'f', "json|csv", NULL, "json", "format of the result"},
	{RS, OPT_QUIET, "quiet", 'q', NULL, NULL, NULL, "no progress on stderr"},
	{ALL, OPT_HELP, "help", 'h', NULL, NULL, NULL, "show this help on stdout and exit"},
};
#define NOPTIONS (sizeof options / sizeof *options)
_Static_assert(NOPTIONS <= CLI_MAX_OPTIONS, "convsim's options fit CLI_MAX_OPTIONS");

static const struct {
	const char *name;
	unsigned cmd;
	const char *synopsis, *about;
} commands[] = {
	{"run", CMD_RUN, "convsim run [OPTIONS]",
	 "Run one simulation and print its JSON summary on stdout (transport velocity with its\n"
	 "error bar, means over whole periods, cost, energy balance); with --out also the\n"
	 "trajectory. Progress goes to stderr on runs longer than a second."},
	{"sweep", CMD_SWEEP, "convsim sweep [OPTIONS]",
	 "Measure the steady transport velocity v(beta), or a study of v over any number\n"
	 "settings (--vary, a grid or a --lhs sample): one fresh simulation per point and\n"
	 "rotation sense, on a thread pool. The table goes to stdout (or --out), progress to\n"
	 "stderr: a bar on a terminal, plain lines otherwise. Built with MPI, under mpirun\n"
	 "the points are spread over the ranks and rank 0 writes the table (docs/cli.md,\n"
	 "\"On a cluster\")."},
	{"fit", CMD_FIT, "convsim fit (--data FILE | --peaks ROT:DEG,...) --free NAME,... [OPTIONS]",
	 "Fit free model parameters to measured v(beta) points or peak positions by\n"
	 "Levenberg-Marquardt (GSL), each model value a steady-state measurement, the\n"
	 "Jacobian's evaluations in parallel. Prints the result (values, standard errors,\n"
	 "correlation, residuals, the fitted and the original curve, warnings) as JSON or\n"
	 "CSV; a summary and progress go to stderr."},
	{"list", CMD_LIST, "convsim list",
	 "Print every setting (name, group, unit, range, meaning) and the integrators."},
};
#define NCOMMANDS (sizeof commands / sizeof *commands)

unsigned cli_command(const char *name)
{
	for (size_t i = 0; i < NCOMMANDS; i++)
		if (strcmp(commands[i].name, name) == 0)
			return commands[i].cmd;
	return 0;
}

static const char *command_name(unsigned cmd)
{
	for (size_t i = 0; i < NCOMMANDS; i++)
		if (commands[i].cmd == cmd)
			return commands[i].name;
	return "";
}

void cli_help_options(FILE *f, const cli_opt *opts, size_t n, unsigned cmd)
{
	for (size_t i = 0; i < n; i++) {
		const cli_opt *o = &opts[i];
		if (!(o->cmds & cmd))
			continue;
		char flag[64];
		snprintf(flag, sizeof flag, "%c%c%s--%s%s%s", o->key ? '-' : ' ',
			 o->key ? o->key : ' ', o->key ? ", " : "  ", o->name, o->arg ? " " : "",
			 o->arg ? o->arg : "");
		fprintf(f, "  %-26s %s", flag, o->doc);
		int preset = o->id == OPT_PRESET && strcmp(o->name, "preset") == 0;
		if (preset) /* the names from their table */
			for (const char *const *p = sim_preset_names; *p; p++)
				fprintf(f, "%s%s", p == sim_preset_names ? " (known: " : ", ", *p);
		fprintf(f, "%s\n", preset ? ")" : "");
		if (o->unit || o->def)
			fprintf(f, "  %-26s %s%s%s%s%s\n", "", o->unit ? "unit: " : "",
				o->unit ? o->unit : "", o->unit && o->def ? "; " : "",
				o->def ? "default: " : "", o->def ? o->def : "");
	}
}

void cli_help(FILE *f, unsigned cmd)
{
	if (!cmd) {
		fprintf(f, "convsim %s - the reversible vibratory conveyor simulator's command line\n\n"
			   "usage: convsim COMMAND [OPTIONS]\n"
			   "       convsim help [COMMAND]     this text, or COMMAND's options\n"
			   "       convsim --version\n\ncommands:\n",
			CONVSIM_VERSION);
		for (size_t i = 0; i < NCOMMANDS; i++)
			fprintf(f, "  %-6s %s\n", commands[i].name,
				i == 0   ? "one simulation: JSON summary, optional trajectory"
				: i == 1 ? "v(beta) for both rotation senses, as CSV or JSON"
				: i == 2 ? "fit parameters to measured v(beta) or its peaks"
					 : "every setting with its unit and range; the integrators");
		fprintf(f, "\n'convsim help COMMAND' or 'convsim COMMAND --help' lists the options "
			   "with their\ndefaults and units. Exit status: 0 done, 1 the simulation "
			   "failed, 2 a usage error.\n");
		return;
	}
	size_t c = 0;
	while (c < NCOMMANDS && commands[c].cmd != cmd)
		c++;
	if (c == NCOMMANDS)
		return;
	fprintf(f, "usage: %s\n\n%s\n\noptions:\n", commands[c].synopsis, commands[c].about);
	cli_help_options(f, options, NOPTIONS, cmd);
	if (cmd & (CMD_RUN | CMD_SWEEP | CMD_FIT))
		fprintf(f, "\nsettings for --set: 'convsim list' (for example --set beta=30 "
			   "--set rotation=ccw\n--set method=rk4 --set dt=1e-5 --set "
			   "trough_rotation=true).\n");
}

const char *cli_did_you_mean(char *buf, size_t len, const char *suggestion)
{
	if (suggestion)
		snprintf(buf, len, " (did you mean '%.60s'?)", suggestion);
	else
		snprintf(buf, len, "%s", "");
	return buf;
}

int cli_next_option_in(const cli_opt *opts, size_t nopts, unsigned cmd, const char *who,
		       const char *hint, int argc, char **argv, const char **arg)
{
	struct option longopts[CLI_MAX_OPTIONS + 1];
	char shortopts[2 * CLI_MAX_OPTIONS + 2] = ":";
	const char *names[CLI_MAX_OPTIONS];
	size_t n = 0, at = 1;
	for (size_t i = 0; i < nopts && i < CLI_MAX_OPTIONS; i++) {
		const cli_opt *o = &opts[i];
		if (!(o->cmds & cmd))
			continue;
		longopts[n] = (struct option){o->name, o->arg ? required_argument : no_argument,
					      NULL, o->id};
		names[n++] = o->name;
		if (o->key) {
			shortopts[at++] = o->key;
			if (o->arg)
				shortopts[at++] = ':';
		}
	}
	longopts[n] = (struct option){NULL, 0, NULL, 0};
	shortopts[at] = '\0';
	opterr = 0;
	int c = getopt_long(argc, argv, shortopts, longopts, NULL);
	*arg = optarg;
	if (c == -1)
		return -1;
	if (c == ':' || c == '?') {
		const char *bad = argv[optind - 1];
		char word[64], near[96];
		if (optopt && optopt < 256) {
			snprintf(word, sizeof word, "-%c", optopt);
		} else {
			snprintf(word, sizeof word, "%s", bad);
			char *eq = strchr(word, '=');
			if (eq)
				*eq = '\0';
		}
		if (c == ':') {
			fprintf(stderr, "%s: option %s needs an argument (see '%s')\n", who, word,
				hint);
			return 0;
		}
		const char *plain = word;
		while (*plain == '-')
			plain++;
		const char *s = strlen(plain) > 1 ? sim_suggest(plain, names, n, sizeof *names) : NULL;
		char full[80];
		if (s)
			snprintf(full, sizeof full, "--%s", s);
		fprintf(stderr, "%s: unknown or ambiguous option '%s'%s; '%s' lists them\n", who,
			word, cli_did_you_mean(near, sizeof near, s ? full : NULL), hint);
		return 0;
	}
	/* a short letter maps to its entry's id */
	for (size_t i = 0; i < nopts; i++)
		if (opts[i].key == c && (opts[i].cmds & cmd))
			return opts[i].id;
	return c;
}

int cli_next_option(int argc, char **argv, unsigned cmd, const char **arg)
{
	char who[64], hint[64];
	snprintf(who, sizeof who, "convsim %s", command_name(cmd));
	snprintf(hint, sizeof hint, "convsim help %s", command_name(cmd));
	return cli_next_option_in(options, NOPTIONS, cmd, who, hint, argc, argv, arg);
}

int cli_operand_index(void)
{
	return optind;
}

void cli_restart_options(void)
{
	optind = 0; /* glibc: 0 starts getopt afresh */
}

int cli_number(const char *cmd, const char *opt, const char *unit, const char *text,
	       double lo, double hi, int lo_open, double *out)
{
	double v = NAN;
	int ok = sim_decimal(text, &v) && (lo_open ? v > lo : v >= lo) && v <= hi;
	if (ok) {
		*out = v;
		return 0;
	}
	fprintf(stderr, "convsim %s: --%s must be a number%s%s in %c%g, %g], got '%s'\n", cmd, opt,
		unit ? " of " : "", unit ? unit : "", lo_open ? '(' : '[', lo, hi, text);
	return -1;
}

int cli_numbers(const char *text, char sep, double *v, int max)
{
	int k = 0;
	for (const char *p = text;; k++) {
		const char *end = strchr(p, sep);
		size_t n = end ? (size_t)(end - p) : strlen(p);
		if (k == max || !sim_decimal_n(p, n, &v[k]))
			return -1;
		if (!end)
			return k + 1;
		p = end + 1;
	}
}

/* ---- progress ------------------------------------------------------------ */

double cli_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void cli_progress_start(cli_progress *p, const char *label, int quiet, double min_wall)
{
	*p = (cli_progress){.label = label, .quiet = quiet, .tty = isatty(STDERR_FILENO),
			    .t0 = cli_now(), .decile = -1, .min_wall = min_wall};
}

void cli_progress_update(cli_progress *p, double done, double total, const char *unit,
			 const char *detail)
{
	if (p->quiet || !(total > 0))
		return;
	double now = cli_now(), wall = now - p->t0, frac = done / total;
	if (wall < p->min_wall)
		return;
	if (p->tty) {
		if (p->shown && now - p->last < 0.1 && done < total)
			return;
		char bar[31];
		int full = (int)(30 * frac);
		for (int i = 0; i < 30; i++)
			bar[i] = i < full ? '#' : '.';
		bar[30] = '\0';
		fprintf(stderr, "\r%s [%s] %3.0f%%  %g/%g %s%s  %.1f s ", p->label, bar, 100 * frac,
			done, total, unit, detail, wall);
	} else {
		int decile = (int)floor(10 * frac + 1e-9);
		if (decile <= p->decile || done >= total) /* the end has its own line */
			return;
		p->decile = decile;
		fprintf(stderr, "%s: %g/%g %s (%.0f %%)%s, %.1f s\n", p->label, done, total, unit,
			100 * frac, detail, wall);
	}
	fflush(stderr);
	p->shown = 1;
	p->last = now;
}

void cli_progress_end(cli_progress *p, const char *summary, int force)
{
	if (p->quiet || !(force || p->shown))
		return;
	if (p->tty && p->shown)
		fputs("\r\033[K", stderr);
	fprintf(stderr, "%s: %s\n", p->label, summary);
}

/* ---- output ---- */

/* Print a number as the daemon does (shortest round trip); non-finite as
 * `nonfinite`. */
void cli_put_num(FILE *f, double v, const char *nonfinite)
{
	char num[40];
	sim_fmt_double(num, sizeof num, v, nonfinite);
	fputs(num, f);
}

void cli_put_json_num(FILE *f, const char *head, double v)
{
	fputs(head, f);
	cli_put_num(f, v, "null");
}

/* The file's format: --format, else by the name's extension. */
int cli_wants_json(const char *format, const char *file)
{
	if (format)
		return strcmp(format, "json") == 0;
	size_t n = file ? strlen(file) : 0;
	return n > 5 && strcmp(file + n - 5, ".json") == 0;
}

char *cli_slurp(const char *cmd, const char *opt, const char *path)
{
	FILE *f = strcmp(path, "-") == 0 ? stdin : fopen(path, "r");
	if (!f) {
		fprintf(stderr, "convsim %s: --%s: cannot read '%s': %s\n", cmd, opt, path,
			strerror(errno));
		return NULL;
	}
	size_t len = 0, cap = 4096;
	char *s = malloc(cap);
	for (size_t n; s && (n = fread(s + len, 1, cap - len - 1, f)) > 0;) {
		len += n;
		if (len + 1 == cap) {
			char *t = len < (16u << 20) ? realloc(s, cap *= 2) : NULL;
			if (!t)
				free(s);
			s = t;
		}
	}
	if (f != stdin)
		fclose(f);
	if (!s)
		fprintf(stderr, "convsim %s: --%s: '%s' is too large (16 MB at most)\n", cmd, opt,
			path);
	else
		s[len] = '\0';
	return s;
}
