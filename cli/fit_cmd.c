/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_cmd.c - `convsim fit`: free parameters (--free) fitted to measured
 * points (--data, CSV) or peak positions (--peaks) by the fitting module
 * (fit/fit.h) on --threads threads. The result goes to stdout (or
 * --out) as the daemon's JSON or CSV (fit_out.c writes both); a summary,
 * the warnings and progress go to stderr. Bad input exits with 2 before
 * anything runs.
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cli.h"
#include "decimal.h"
#include "fit.h"
#include "table.h"
#include "units.h"

/* --free NAME[:MIN:MAX],... into req. */
static int parse_free(const char *list, fit_request *req)
{
	char buf[512], field[48], msg[FIT_MSG];
	snprintf(buf, sizeof buf, "%s", list);
	for (char *save, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		double range[2] = {NAN, NAN};
		char *colon = strchr(tok, ':');
		if (colon) {
			*colon = '\0';
			if (cli_numbers(colon + 1, ':', range, 2) != 2) {
				fprintf(stderr, "convsim fit: --free takes NAME or NAME:MIN:MAX, got "
						"'%s:%s'\n", tok, colon + 1);
				return -1;
			}
		}
		if (fit_add_free(req, tok, range[0], range[1], field, sizeof field, msg, sizeof msg,
				 NULL) != SIM_OK) {
			fprintf(stderr, "convsim fit: --free: %s\n", msg);
			return -1;
		}
	}
	if (!req->nfree)
		fprintf(stderr, "convsim fit: --free names no parameter\n");
	return req->nfree ? 0 : -1;
}

/* --prior NAME:MEAN:SD|NAME:MEAN:xFACTOR,... into req (after --free). */
static int parse_priors(const char *list, fit_request *req)
{
	char buf[512], msg[FIT_MSG];
	snprintf(buf, sizeof buf, "%s", list);
	for (char *save, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		/* NAME, then MEAN and SD (or x and FACTOR) as numbers */
		char name[24];
		double mean = NAN, sd = NAN, factor = NAN;
		size_t len = strspn(tok, "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz"
					 "0123456789_");
		const char *spread = tok[len] == ':' ? strchr(tok + len + 1, ':') : NULL;
		int ok = len > 0 && len < sizeof name && spread &&
			 sim_decimal_n(tok + len + 1, (size_t)(spread - tok - len - 1), &mean);
		if (ok && spread[1] == 'x')
			ok = sim_decimal(spread + 2, &factor);
		else if (ok)
			ok = sim_decimal(spread + 1, &sd);
		snprintf(name, sizeof name, "%.*s", (int)len, tok);
		if (!ok) {
			fprintf(stderr, "convsim fit: --prior takes NAME:MEAN:SD (normal) or "
					"NAME:MEAN:xFACTOR (log-normal), e.g. R:0.5:0.1,k_c:3000:x3; "
					"got '%s'\n", tok);
			return -1;
		}
		if (fit_set_prior(req, name, mean, sd, factor, msg, sizeof msg, NULL, NULL) != SIM_OK) {
			fprintf(stderr, "convsim fit: --prior: %s\n", msg);
			return -1;
		}
	}
	return 0;
}

/* --peaks ROT:DEG[:SIGMA],... into req. */
static int parse_peaks(const char *list, fit_request *req)
{
	char buf[512];
	snprintf(buf, sizeof buf, "%s", list);
	for (char *save, *tok = strtok_r(buf, ",", &save); tok; tok = strtok_r(NULL, ",", &save)) {
		double v[2] = {NAN, NAN}; /* DEG, SIGMA */
		const char *colon = strchr(tok, ':');
		size_t len = colon ? (size_t)(colon - tok) : 0;
		int cw = len == 2 && strncmp(tok, "cw", 2) == 0;
		int n = cw || (len == 3 && strncmp(tok, "ccw", 3) == 0)
				? cli_numbers(colon + 1, ':', v, 2)
				: -1;
		int ok = n == 1 || n == 2;
		if (!ok || req->npeaks >= FIT_MAX_PEAKS) {
			fprintf(stderr, "convsim fit: --peaks takes up to %d of ROT:DEG[:SIGMA] (cw or "
					"ccw, deg, deg), e.g. cw:38,cw:128; got '%s'\n",
				FIT_MAX_PEAKS, tok);
			return -1;
		}
		fit_peak *p = &req->peaks[req->npeaks++];
		p->rotation = cw ? SIM_CW : SIM_CCW;
		p->beta = v[0] * RAD_PER_DEG;
		p->sigma = v[1] * RAD_PER_DEG;
	}
	return 0;
}

/* Progress on stderr: one line per iteration and phase. */
typedef struct fit_progress_line {
	const fit_request *req;
	int quiet, iteration;
	const char *phase;
	double t0;
} fit_progress_line;

static void progress(void *arg, const fit_progress *pr)
{
	fit_progress_line *p = arg;
	if (p->quiet || (pr->iteration == p->iteration && strcmp(pr->phase, p->phase) == 0))
		return;
	p->iteration = pr->iteration;
	p->phase = pr->phase;
	fprintf(stderr, "fit: %s, iteration %d, %ld evaluations, cost %.4g,", pr->phase,
		pr->iteration, pr->evaluations, pr->cost);
	for (int j = 0; j < p->req->nfree; j++)
		fprintf(stderr, " %s = %.6g", p->req->free[j].name,
			sim_table_user(p->req->free[j].name, pr->x[j]));
	fprintf(stderr, ", %.1f s\n", cli_now() - p->t0);
}

/* The request from the options: 0, or 2 after a message. */
static int build_request(const cli_opts *o, fit_request *req, fit_point **points)
{
	fit_request_init(req);
	req->p = o->p;
	req->sc = o->sc;
	req->m = o->m;
	req->t_end = o->duration;
	req->threads = o->threads;
	req->curve_step = o->curve_step * RAD_PER_DEG;
	req->fd_rel = o->fd_step;
	req->max_iter = o->max_iter;
	req->starts = o->starts;
	if (!o->free_list) {
		fprintf(stderr, "convsim fit: --free is required: name the parameters to fit, e.g. "
				"--free e or --free e:0.005:0.05\n");
		return 2;
	}
	if (!o->data == !o->peaks) {
		fprintf(stderr, "convsim fit: give --data FILE (points) or --peaks ROT:DEG,... "
				"(one of them)\n");
		return 2;
	}
	if (parse_free(o->free_list, req) || (o->prior_list && parse_priors(o->prior_list, req)) ||
	    (o->peaks && parse_peaks(o->peaks, req)))
		return 2;
	char msg[FIT_MSG], field[48];
	if (o->data) {
		char *text = cli_slurp("fit", "data", o->data);
		if (!text)
			return 2;
		int rc = fit_parse_csv(text, points, &req->npoints, msg, sizeof msg, NULL);
		free(text);
		if (rc != SIM_OK) {
			fprintf(stderr, "convsim fit: --data %s: %s\n", o->data, msg);
			return 2;
		}
		req->points = *points;
	}
	if (fit_check(req, field, sizeof field, msg, sizeof msg) != SIM_OK) {
		const char *opt = strncmp(field, "points", 6) == 0  ? "--data"
				  : strncmp(field, "peaks", 5) == 0 ? "--peaks"
				  : strcmp(field, "t_end") == 0     ? "--duration"
				  : strstr(field, ".prior")         ? "--prior"
				  : strncmp(field, "free", 4) == 0  ? "--free"
								    : "--set";
		int data = strcmp(opt, "--data") == 0; /* and the file, as the CSV's errors */
		fprintf(stderr, "convsim fit: %s%s%s: %s\n", opt, data ? " " : "", data ? o->data : "",
			msg);
		return 2;
	}
	return 0;
}

/* The values, standard errors and warnings on stderr. */
static void summary(const fit_request *req, const fit_result *res)
{
	fprintf(stderr, "convsim fit: %s after %d iterations, %ld evaluations, %.1f CPU s\n",
		fit_status_name(res->status), res->iterations, res->evaluations, res->cpu_seconds);
	for (int j = 0; j < res->nfree; j++) {
		const sim_setting *t = sim_setting_find(req->free[j].name);
		fprintf(stderr, "  %s = %.6g +- %.2g %s (start %.6g)\n", req->free[j].name,
			sim_setting_from_si(t, res->x[j]), sim_setting_from_si(t, res->se[j]),
			sim_unit_shown(t), sim_setting_from_si(t, res->x0[j]));
	}
	/* costs in the data's unit, as the JSON's chi2 (peaks: deg^2) */
	int peaks_deg = !req->npoints && !res->sigma_given;
	double k2 = peaks_deg ? DEG_PER_RAD * DEG_PER_RAD : 1;
	for (int s = 0; res->nstarts > 1 && s < res->nstarts; s++) {
		const fit_start *st = &res->starts[s];
		fprintf(stderr, "  %s start %d:", s == res->best_start ? "*" : " ", s + 1);
		for (int j = 0; j < res->nfree; j++)
			fprintf(stderr, " %s %.4g -> %.6g", req->free[j].name,
				sim_table_user(req->free[j].name, st->x0[j]),
				sim_table_user(req->free[j].name, st->x[j]));
		fprintf(stderr, ", chi2 %.4g%s, %s\n", st->chi2 * k2, peaks_deg ? " deg^2" : "",
			fit_status_name(st->status));
	}
	if (res->rejected)
		fprintf(stderr, "  %d trial points could not be evaluated (rejected steps)\n",
			res->rejected);
	for (int w = 0; w < res->nwarn; w++)
		fprintf(stderr, "  warning: %s\n", res->warnings[w]);
	if (res->error[0])
		fprintf(stderr, "  error: %s\n", res->error);
}

int cli_cmd_fit(int argc, char **argv)
{
	cli_opts o = {0};
	int rc = cli_parse(argc, argv, CMD_FIT, &o);
	if (rc)
		return rc < 0 ? 0 : rc;
	fit_request req;
	fit_point *points = NULL;
	rc = build_request(&o, &req, &points);
	if (rc) {
		free(points);
		return rc;
	}
	cli_out file = {0};
	FILE *out = o.out ? cli_out_open(&file, "fit", o.out) : stdout;
	if (!out) {
		free(points);
		return 1;
	}
	fit_progress_line pr = {&req, o.quiet, -1, "", cli_now()};
	req.progress = progress;
	req.ctx = &pr;
	fit_result res;
	fit_run(&req, &res);
	int csv = o.format && strcmp(o.format, "csv") == 0;
	char *text = csv ? fit_result_csv(&req, &res) : fit_result_json(&req, &res);
	if (text)
		fprintf(out, "%s%s", text, csv ? "" : "\n");
	int write_failed = !text || ferror(out);
	if (out != stdout)
		write_failed |= cli_out_close(&file, !write_failed);
	if (write_failed)
		fprintf(stderr, "convsim fit: writing the result failed\n");
	if (!o.quiet || res.status == FIT_FAILED)
		summary(&req, &res);
	rc = res.status == FIT_FAILED || write_failed ? 1 : 0;
	free(text);
	fit_result_free(&res);
	free(points);
	return rc;
}
