/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * study_opts.c - the study of `convsim sweep`'s options (core/study.h):
 * --beta (the shorthand for --vary beta=...), every --vary NAME=FROM:TO:STEP
 * or NAME=V1,V2,... in the order given, --lhs and --seed, --rotation's
 * senses, each checked with a message that names the option and what it
 * accepts. sweep_cmd.c measures what this plans.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "study.h"
#include "suggest.h"
#include "units.h"

/* --beta FROM:TO:STEP or one angle into *from, *to, *step. */
static int parse_beta(const char *text, double *from, double *to, double *step)
{
	double v[3] = {NAN, NAN, NAN};
	int n = cli_numbers(text, ':', v, 3);
	if (n == 1) {
		v[1] = v[0];
		v[2] = 1;
		n = 3;
	}
	*from = v[0];
	*to = v[1];
	*step = v[2];
	if (n != 3 || !(*step > 0) || !(*from >= 0) || !(*to <= 180) || !(*to >= *from)) {
		fprintf(stderr, "convsim sweep: --beta must be FROM:TO:STEP in degrees with 0 <= FROM "
				"<= TO <= 180 and STEP > 0 (or one angle), got '%s'\n",
			text);
		return -1;
	}
	return 0;
}

/* One --vary NAME=FROM:TO:STEP or NAME=V1,V2,... (or NAME=V) as an axis
 * of st, checked by the study (name, range); 0 or -1 after a message. */
static int add_vary(sim_study *st, const cli_opts *o, const char *text)
{
	const char *eq = strchr(text, '=');
	char name[64], msg[240], hint[96] = "";
	double v[3];
	int rc = SIM_EPARAM;
	if (!eq || eq == text || (size_t)(eq - text) >= sizeof name) {
		fprintf(stderr, "convsim sweep: --vary needs NAME=FROM:TO:STEP or NAME=V1,V2,..., "
				"got '%s'\n",
			text);
		return -1;
	}
	snprintf(name, sizeof name, "%.*s", (int)(eq - text), text);
	const char *spec = eq + 1;
	if (strchr(spec, ':')) {
		if (cli_numbers(spec, ':', v, 3) == 3)
			rc = sim_study_add_range(st, &o->p, &o->sc, &o->m, name, v[0], v[1], v[2],
						 msg, sizeof msg);
		else
			snprintf(msg, sizeof msg, "a range is FROM:TO:STEP, three numbers");
	} else {
		size_t n = 1;
		for (const char *c = spec; *c; c++)
			n += *c == ',';
		double *list = calloc(n, sizeof(double));
		if (list && cli_numbers(spec, ',', list, (int)n) == (int)n)
			rc = sim_study_add_list(st, &o->p, &o->sc, &o->m, name, list, n, msg,
						sizeof msg);
		else
			snprintf(msg, sizeof msg, "a list is numbers separated by commas");
		free(list);
	}
	if (rc == SIM_OK)
		return 0;
	if (rc == SIM_EUNKNOWN && !sim_setting_find(name)) {
		size_t nset;
		const sim_setting *t = sim_settings(&nset);
		cli_did_you_mean(hint, sizeof hint, sim_suggest(name, &t->name, nset, sizeof *t));
	}
	fprintf(stderr, "convsim sweep: --vary %s: %s%s; 'convsim list' shows every setting\n", text,
		msg, hint);
	return -1;
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

/* --beta TEXT as the axis beta (the shorthand's own message for a bad
 * range); 0 or -1 after a message. */
static int add_beta(sim_study *st, const cli_opts *o, const char *text)
{
	double from, to, step;
	char msg[240];
	if (parse_beta(text, &from, &to, &step))
		return -1;
	if (sim_study_add_range(st, &o->p, &o->sc, &o->m, "beta", from, to, step, msg,
				sizeof msg) != SIM_OK) {
		fprintf(stderr, "convsim sweep: --beta %s: %s\n", text, msg);
		return -1;
	}
	return 0;
}

int cli_plan_study(const cli_opts *o, sim_study *st)
{
	int nrot;
	if ((nrot = parse_rotation(o->rotation, st->rotation)) < 0)
		return 2;
	st->nrot = (size_t)nrot;
	st->lhs = (size_t)o->lhs;
	st->seed = (uint64_t)o->seed;
	const char *beta = o->beta ? o->beta : o->nvary ? NULL : "0:180:10";
	char msg[240];
	for (int i = 0; i <= o->nvary; i++) {
		if (beta && i == o->beta_at && add_beta(st, o, beta))
			return 2;
		if (i < o->nvary && add_vary(st, o, o->vary[i]))
			return 2;
	}
	if (o->lhs && !o->nvary) {
		fprintf(stderr, "convsim sweep: --lhs samples the --vary ranges; give at least one "
				"--vary\n");
		return 2;
	}
	if (sim_study_plan(st, msg, sizeof msg) != SIM_OK) {
		fprintf(stderr, "convsim sweep: %s\n", msg);
		return 2;
	}
	return 0;
}
