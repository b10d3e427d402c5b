/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * parse.c - a command's options into one cli_opts: the preset first (a
 * first pass finds it, so that --set applies on top of it wherever it
 * stands), then every option with its checks; the help and unknown
 * options through the option table (options.c). Shared by run, sweep,
 * fit and list.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "fit.h"
#include "suggest.h"
#include "units.h"

/* "unknown setting 'x'" gets the nearest setting's name; opt is how the
 * user gave it ("--set beta=x", "--beta x"). */
static void setting_error(const cli_opts *o, const char *opt, const char *name, const char *msg)
{
	size_t n;
	const sim_setting *t = sim_settings(&n);
	char hint[96] = "";
	if (!sim_setting_find(name))
		cli_did_you_mean(hint, sizeof hint, sim_suggest(name, &t->name, n, sizeof *t));
	fprintf(stderr, "convsim %s: %s: %s%s; 'convsim list' shows every setting\n", o->cmd, opt,
		msg, hint);
}

/* Setting name to text value (in the unit `convsim list` shows): 0, or -1
 * after a message naming opt. */
static int set_setting(cli_opts *o, const char *opt, const char *name, const char *value)
{
	char msg[200];
	if (sim_set_user_str(&o->p, &o->sc, &o->m, name, value, msg, sizeof msg) != SIM_OK) {
		setting_error(o, opt, name, msg);
		return -1;
	}
	return 0;
}

static int apply_set(cli_opts *o, const char *v)
{
	const char *eq = strchr(v, '=');
	if (!eq || eq == v) {
		fprintf(stderr, "convsim %s: --set needs NAME=VALUE, got '%s'\n", o->cmd, v);
		return -1;
	}
	char name[64], opt[96];
	snprintf(name, sizeof name, "%.*s", (int)(eq - v), v);
	snprintf(opt, sizeof opt, "--set %s", v);
	return set_setting(o, opt, name, eq + 1);
}

/* run's --beta DEG and --rotation cw|ccw: the settings beta and rotation,
 * as --set would set them (sweep's take lists instead). */
static int set_option(cli_opts *o, const char *name, const char *value)
{
	char opt[96];
	snprintf(opt, sizeof opt, "--%s %s", name, value);
	return set_setting(o, opt, name, value);
}

/* The first pass over command cmd's options: help (shown, -1), a wrong
 * option or an operand (reported, 2), else 0 with --preset in *preset
 * (may be NULL for commands without one). */
int cli_first_pass(int argc, char **argv, unsigned cmd, const char **preset)
{
	const char *arg;
	int id;
	while ((id = cli_next_option(argc, argv, cmd, &arg)) != -1) {
		if (id == 0)
			return 2;
		if (id == OPT_HELP) {
			cli_help(stdout, cmd);
			return -1;
		}
		if (id == OPT_PRESET && preset)
			*preset = arg;
	}
	if (cli_operand_index() < argc) {
		fprintf(stderr, "convsim %s: unexpected argument '%s' (options start with --)\n",
			argv[0], argv[cli_operand_index()]);
		return 2;
	}
	return 0;
}

/* Parse command cmd's options into *o. Returns 0, 2 (usage error) or -1
 * (help shown: exit 0). */
/* --opt as a whole number in [1, hi] into *out: 0, or 1 after a message. */
static int whole(const char *cmd, const char *opt, const char *arg, double hi, int *out)
{
	double v;
	if (cli_number(cmd, opt, NULL, arg, 1, hi, 0, &v))
		return 1;
	if (v != floor(v)) {
		fprintf(stderr, "convsim %s: --%s must be a whole number, got '%s'\n", cmd, opt, arg);
		return 1;
	}
	*out = (int)v;
	return 0;
}

/* The model of --preset into *o: 0, or 2 after naming the presets. */
static int load_preset(cli_opts *o)
{
	if (sim_preset(o->preset, &o->p, &o->sc, &o->m) != SIM_OK) {
		char hint[96];
		size_t n = 0;
		while (sim_preset_names[n])
			n++;
		fprintf(stderr, "convsim %s: --preset: unknown preset '%s'%s; known:", o->cmd,
			o->preset,
			cli_did_you_mean(hint, sizeof hint,
					 sim_suggest(o->preset, sim_preset_names, n,
						     sizeof *sim_preset_names)));
		for (size_t i = 0; i < n; i++)
			fprintf(stderr, "%s %s", i ? "," : "", sim_preset_names[i]);
		fputc('\n', stderr);
		return 2;
	}
	return 0;
}

/* One option of command cmd (its id, its argument) into *o: 0, or 1
 * after a message. */
static int apply_option(cli_opts *o, unsigned cmd, int id, const char *arg)
{
	int bad = 0;
	switch (id) {
	case OPT_SET: bad = apply_set(o, arg); break;
	case OPT_DURATION:
		bad = cli_number(o->cmd, "duration", "seconds", arg, 0, 1e5, 1, &o->duration);
		break;
	case OPT_RATE:
		bad = cli_number(o->cmd, "sample-rate", "Hz", arg, 0, 1e6, 1, &o->rate);
		break;
	case OPT_THREADS: bad = whole(o->cmd, "threads", arg, 64, &o->threads); break;
	case OPT_COUPLING_STEPS:
		bad = whole(o->cmd, "coupling-steps", arg, 1000, &o->coupling_steps);
		break;
	case OPT_MAX_DEM_COST:
		bad = cli_number(o->cmd, "max-dem-cost", "CPU seconds", arg, 0, 1e9, 1,
				 &o->max_dem_cost);
		break;
	case OPT_MAX_OUTPUT:
		bad = cli_number(o->cmd, "max-output", "bytes", arg, 0, 1e18, 1, &o->max_output);
		break;
	case OPT_OUT: o->out = arg; break;
	case OPT_FORMAT: o->format = arg; break;
	case OPT_BETA:
	case OPT_ROTATION: /* run: one setting, as --set; sweep: a range, a list */
		if (cmd == CMD_RUN)
			bad = set_option(o, id == OPT_BETA ? "beta" : "rotation", arg);
		else
			*(id == OPT_BETA ? &o->beta : &o->rotation) = arg;
		if (id == OPT_BETA)
			o->beta_at = o->nvary;
		break;
	case OPT_QUIET: o->quiet = 1; break;
	case OPT_VARY:
		if (o->nvary == CLI_MAX_VARY) {
			fprintf(stderr, "convsim %s: --vary: at most %d settings are varied\n",
				o->cmd, CLI_MAX_VARY);
			bad = 1;
		} else {
			o->vary[o->nvary++] = arg;
		}
		break;
	case OPT_LHS: bad = whole(o->cmd, "lhs", arg, 10000, &o->lhs); break;
	case OPT_SEED:
		bad = cli_number(o->cmd, "seed", NULL, arg, 0, 4294967295.0, 0, &o->seed);
		if (!bad && o->seed != floor(o->seed)) {
			fprintf(stderr, "convsim %s: --seed must be a whole number, got '%s'\n",
				o->cmd, arg);
			bad = 1;
		}
		break;
	case OPT_DATA: o->data = arg; break;
	case OPT_BAND_FROM: o->band_from = arg; break;
	case OPT_PEAKS: o->peaks = arg; break;
	case OPT_FREE: o->free_list = arg; break;
	case OPT_PRIOR: o->prior_list = arg; break;
	case OPT_CURVE_STEP:
		bad = cli_number(o->cmd, "curve-step", "deg", arg, 0, 90, 0, &o->curve_step);
		break;
	case OPT_FD_STEP:
		bad = cli_number(o->cmd, "fd-step", NULL, arg, 0, 0.5, 1, &o->fd_step);
		break;
	case OPT_MAX_ITER: bad = whole(o->cmd, "max-iter", arg, 1000, &o->max_iter); break;
	case OPT_STARTS: bad = whole(o->cmd, "starts", arg, FIT_MAX_STARTS, &o->starts); break;
	default: break;
	}
	return bad;
}

int cli_parse(int argc, char **argv, unsigned cmd, cli_opts *o)
{
	o->cmd = argv[0];
	o->preset = "czubak2016";
	o->duration = NAN;
	o->rate = 1000.0;
	o->threads = 2;
	o->coupling_steps = 1;
	o->max_dem_cost = INFINITY;
	o->max_output = 1e9;
	o->rotation = "cw,ccw";
	o->seed = 1;
	o->curve_step = 5;
	o->fd_step = 0.05;
	o->max_iter = 30;
	o->starts = 1;
	/* the preset first, so that --set applies on top of it wherever it
	 * stands; a first pass finds it */
	int rc = cli_first_pass(argc, argv, cmd, &o->preset);
	if (rc)
		return rc;
	const char *arg;
	int id;
	if (load_preset(o))
		return 2;
	cli_restart_options();
	while ((id = cli_next_option(argc, argv, cmd, &arg)) != -1)
		if (apply_option(o, cmd, id, arg))
			return 2;
	if (o->format && strcmp(o->format, "csv") != 0 && strcmp(o->format, "json") != 0) {
		fprintf(stderr, "convsim %s: --format must be csv or json, got '%s'\n", o->cmd,
			o->format);
		return 2;
	}
	if (isnan(o->duration))
		o->duration = o->sc.transient + MEASURE_WINDOW;
	return 0;
}
