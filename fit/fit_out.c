/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_out.c - a fit's result as text, the same for the CLI and the daemon:
 * JSON (parameters with standard errors, correlation, per-datum model and
 * residual, the curves, the solver's figures, warnings) and CSV (one table,
 * FIT_CSV_HEADER). User units: beta in deg, parameters in their setting's
 * unit; numbers by core/table.h's shortest round-trip printer.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit.h"
#include "table.h"

typedef struct text {
	char *s;
	size_t len, cap;
	int failed;
} text;

static void put(text *t, const char *fmt, ...) __attribute__((format(printf, 2, 3)));
static void put(text *t, const char *fmt, ...)
{
	va_list ap;
	for (int pass = 0; pass < 2 && !t->failed; pass++) {
		va_start(ap, fmt);
		int n = vsnprintf(t->s ? t->s + t->len : NULL, t->s ? t->cap - t->len : 0, fmt, ap);
		va_end(ap);
		if (n < 0) {
			t->failed = 1;
		} else if (t->s && t->len + (size_t)n < t->cap) {
			t->len += (size_t)n;
			return;
		} else {
			size_t cap = (t->cap + (size_t)n + 1) * 2;
			char *s = realloc(t->s, cap);
			if (!s)
				t->failed = 1;
			else
				t->s = s, t->cap = cap;
		}
	}
}

static void num(text *t, double v, const char *nonfinite)
{
	char b[40];
	sim_fmt_double(b, sizeof b, v, nonfinite);
	put(t, "%s", b);
}

static void jstr(text *t, const char *s)
{
	put(t, "\"");
	for (; *s; s++) {
		unsigned char c = (unsigned char)*s;
		if (c == '"' || c == '\\')
			put(t, "\\%c", c);
		else if (c < 0x20)
			put(t, "\\u%04x", c);
		else
			put(t, "%c", c);
	}
	put(t, "\"");
}

static char *take(text *t)
{
	if (t->failed || !t->s) {
		free(t->s);
		return NULL;
	}
	return t->s;
}

static const char *rot_name(int r)
{
	return r == SIM_CW ? "cw" : "ccw";
}

/* An angle in deg as a user wrote it: rad back to deg, rounded to 1e-9
 * deg (60 deg, not 59.99999999999999). */
static double deg(double rad)
{
	return round(rad * DEG_PER_RAD * 1e9) / 1e9;
}

/* A parameter's value in its user unit. */
static double user(const fit_free *f, double si)
{
	return sim_table_user(f->name, si);
}

/* ,"prior": null, {"mean", "sd"} (normal) or {"mean", "factor"}
 * (log-normal), in the parameter's user unit. */
static void json_prior(text *t, const fit_free *f, const fit_prior *pr)
{
	put(t, ",\"prior\":");
	if (!fit_has_prior(pr)) {
		put(t, "null");
		return;
	}
	put(t, "{\"mean\":");
	num(t, user(f, pr->mean), "null");
	if (pr->log) {
		put(t, ",\"factor\":");
		num(t, exp(pr->sd), "null");
	} else {
		put(t, ",\"sd\":");
		num(t, user(f, pr->sd), "null");
	}
	put(t, "}");
}

static void json_parameters(text *t, const fit_request *q, const fit_result *r)
{
	put(t, "\"parameters\":[");
	for (int j = 0; j < r->nfree; j++) {
		const fit_free *f = &q->free[j];
		const sim_setting *s = sim_setting_find(f->name);
		put(t, "%s{\"name\":", j ? "," : "");
		jstr(t, f->name);
		put(t, ",\"unit\":");
		jstr(t, s ? s->unit : "");
		const char *keys[] = {"value", "standard_error", "start", "min", "max"};
		double vals[] = {r->x[j], r->se[j], r->x0[j], f->lo, f->hi};
		for (int k = 0; k < 5; k++) {
			put(t, ",\"%s\":", keys[k]);
			num(t, user(f, vals[k]), "null");
		}
		put(t, ",\"at_bound\":%s", r->at_bound[j] < 0   ? "\"lower\""
					   : r->at_bound[j] > 0 ? "\"upper\""
								: "null");
		json_prior(t, f, &q->prior[j]);
		put(t, "}");
	}
	put(t, "],\"correlation\":[");
	for (int a = 0; a < r->nfree; a++) {
		put(t, "%s[", a ? "," : "");
		for (int b = 0; b < r->nfree; b++) {
			put(t, "%s", b ? "," : "");
			num(t, r->corr[a * r->nfree + b], "null");
		}
		put(t, "]");
	}
	put(t, "]");
}

/* Datum i: measured, sigma, model, its uncertainty, start (user units). */
static void datum(const fit_request *q, const fit_result *r, size_t i, double v[5])
{
	double k = q->npoints ? 1 : DEG_PER_RAD;
	v[0] = q->npoints ? q->points[i].v : deg(q->peaks[i].beta);
	v[1] = (q->npoints ? q->points[i].sigma : q->peaks[i].sigma) * k;
	v[2] = r->model ? r->model[i] * k : NAN;
	v[3] = r->model_u ? r->model_u[i] * k : NAN;
	v[4] = r->model_start ? r->model_start[i] * k : NAN;
}

static void json_data(text *t, const fit_request *q, const fit_result *r)
{
	put(t, ",\"data\":\"%s\",\"%s\":[", q->npoints ? "points" : "peaks",
	    q->npoints ? "points" : "peaks");
	size_t n = q->npoints ? q->npoints : (size_t)q->npeaks;
	for (size_t i = 0; i < n; i++) {
		double v[5];
		datum(q, r, i, v);
		put(t, "%s{\"beta\":", i ? "," : "");
		num(t, deg(q->npoints ? q->points[i].beta : q->peaks[i].beta), "null");
		put(t, ",\"rotation\":\"%s\",\"%s\":",
		    rot_name(q->npoints ? q->points[i].rotation : q->peaks[i].rotation),
		    q->npoints ? "v" : "measured");
		num(t, v[0], "null");
		const char *keys[] = {"sigma", "model", "model_uncertainty", "residual",
				      "model_start"};
		double vals[] = {v[1], v[2], v[3], v[2] - v[0], v[4]};
		for (int k = 0; k < 5; k++) {
			put(t, ",\"%s\":", keys[k]);
			num(t, vals[k], "null");
		}
		put(t, "}");
	}
	put(t, "]");
}

/* The model error of the fitted curve's scene at each grid angle, per
 * rotation (sim_model_check: the request's scene with the fitted values):
 * "model_error" and "model_checked" arrays, and the note at the first
 * angle not checked ("" when all are). */
static void json_curve_model(text *t, const fit_request *q, const fit_result *r, int ro)
{
	sim_params p = q->p;
	sim_scene sc = q->sc;
	sim_method m = q->m;
	for (int j = 0; j < r->nfree; j++)
		sim_set(&p, &sc, &m, q->free[j].name, r->x[j], NULL, 0);
	p.rotation = r->rotations[ro];
	char note[sizeof ((sim_model_error *)0)->note] = "";
	for (int a = 0; a < 2; a++) {
		put(t, ",\"%s\":[", a ? "model_checked" : "model_error");
		for (size_t k = 0; k < r->ncurve; k++) {
			sim_model_error me;
			p.beta = r->curve_beta[k];
			sim_model_check(&p, &sc, &me);
			put(t, "%s", k ? "," : "");
			if (a)
				put(t, "%s", me.checked ? "true" : "false");
			else
				num(t, me.checked ? me.error : NAN, "null");
			if (!me.checked && !note[0])
				snprintf(note, sizeof note, "%s", me.note);
		}
		put(t, "]");
	}
	put(t, ",\"model_check_note\":");
	jstr(t, note);
}

static void json_curve(text *t, const fit_request *q, const fit_result *r)
{
	put(t, ",\"curve\":");
	if (!r->ncurve) {
		put(t, "null");
		return;
	}
	put(t, "{\"beta\":[");
	for (size_t k = 0; k < r->ncurve; k++) {
		put(t, "%s", k ? "," : "");
		num(t, deg(r->curve_beta[k]), "null");
	}
	put(t, "]");
	put(t, ",\"band_level\":0.95,\"band_quantile\":");
	num(t, r->band_quantile, "null");
	for (int ro = 0; ro < r->nrot; ro++) {
		const double *arr[] = {r->curve_fit, r->curve_fit_u, r->curve_start, r->band_lo,
				       r->band_hi};
		const char *keys[] = {"fit", "fit_uncertainty", "start", "band\":{\"lower", "upper"};
		put(t, ",\"%s\":{", rot_name(r->rotations[ro]));
		for (int a = 0; a < 5; a++) {
			put(t, "%s\"%s\":[", a ? "," : "", keys[a]);
			for (size_t k = 0; k < r->ncurve; k++) {
				put(t, "%s", k ? "," : "");
				num(t, arr[a][(size_t)ro * r->ncurve + k], "null");
			}
			put(t, "]");
		}
		put(t, "}");
		json_curve_model(t, q, r, ro);
		put(t, "}");
	}
	put(t, "}");
}

/* The runs of a multi-start fit: where each started and ended (user
 * units), its cost (in chi2's unit, k2 converting) and status. */
static void json_starts(text *t, const fit_request *q, const fit_result *r, double k2)
{
	put(t, ",\"best_start\":%d,\"starts\":[", r->nstarts ? r->best_start : 0);
	for (int s = 0; s < r->nstarts; s++) {
		const fit_start *st = &r->starts[s];
		const double *arr[] = {st->x0, st->x};
		const char *keys[] = {"start", "value"};
		put(t, "%s{", s ? "," : "");
		for (int a = 0; a < 2; a++) {
			put(t, "%s\"%s\":[", a ? "," : "", keys[a]);
			for (int j = 0; j < r->nfree; j++) {
				put(t, "%s", j ? "," : "");
				num(t, user(&q->free[j], arr[a][j]), "null");
			}
			put(t, "]");
		}
		/* the data's share: a run's cost includes the priors' */
		put(t, ",\"chi2\":");
		num(t, (st->chi2 - fit_prior_cost(q, st->x)) * k2, "null");
		put(t, ",\"status\":\"%s\",\"iterations\":%d}", fit_status_name(st->status),
		    st->iterations);
	}
	put(t, "]");
}

char *fit_result_json(const fit_request *q, const fit_result *r)
{
	text t = {0};
	put(&t, "{\"status\":\"%s\",\"error\":", fit_status_name(r->status));
	if (r->error[0])
		jstr(&t, r->error);
	else
		put(&t, "null");
	put(&t, ",");
	json_parameters(&t, q, r);
	/* chi2 and the residual variance in the data's unit, as the residuals
	 * are: dimensionless with sigma, (m/s)^2 for points, deg^2 for peaks
	 * (the solver works in rad) */
	double k2 = q->npoints || r->sigma_given ? 1 : DEG_PER_RAD * DEG_PER_RAD;
	const char *keys[] = {"chi2", "residual_variance", "condition_number", "cpu_seconds",
			      "wall_seconds"};
	double vals[] = {r->chi2 * k2, r->s2 * k2, r->cond, r->cpu_seconds, r->wall_seconds};
	for (int k = 0; k < 5; k++) {
		put(&t, ",\"%s\":", keys[k]);
		num(&t, vals[k], "null");
	}
	put(&t, ",\"chi2_unit\":\"%s\",\"dof\":%d,\"standard_errors_from\":\"%s\","
		"\"iterations\":%d,\"evaluations\":%ld",
	    r->sigma_given ? "" : q->npoints ? "(m/s)^2" : "deg^2", r->dof,
	    r->sigma_given ? "sigma" : "residual variance", r->iterations, r->evaluations);
	put(&t, ",\"rejected\":%d,\"chi2_prior\":", r->rejected);
	num(&t, r->chi2_prior, "null");
	json_starts(&t, q, r, k2);
	json_data(&t, q, r);
	json_curve(&t, q, r);
	put(&t, ",\"warnings\":[");
	for (int w = 0; w < r->nwarn; w++) {
		put(&t, "%s", w ? "," : "");
		jstr(&t, r->warnings[w]);
	}
	put(&t, "]}");
	return take(&t);
}

static void csv_row(text *t, const char *kind, const char *name, double beta, const char *rot,
		    const double v[8])
{
	put(t, "%s,%s,", kind, name);
	num(t, beta, "");
	put(t, ",%s", rot);
	for (int k = 0; k < 8; k++) {
		put(t, ",");
		num(t, v[k], "");
	}
	put(t, "\n");
}

char *fit_result_csv(const fit_request *q, const fit_result *r)
{
	text t = {0};
	put(&t, "%s\n", FIT_CSV_HEADER);
	for (int j = 0; j < r->nfree; j++) {
		const fit_free *f = &q->free[j];
		double v[8] = {NAN, NAN, user(f, r->x[j]), user(f, r->se[j]), NAN, user(f, r->x0[j]),
			       NAN, NAN};
		csv_row(&t, "parameter", f->name, NAN, "", v);
	}
	size_t n = q->npoints ? q->npoints : (size_t)q->npeaks;
	for (size_t i = 0; i < n; i++) {
		double d[5];
		datum(q, r, i, d);
		double v[8] = {d[0], d[1], d[2], d[3], d[2] - d[0], d[4], NAN, NAN};
		double beta = q->npoints ? q->points[i].beta : q->peaks[i].beta;
		int rot = q->npoints ? q->points[i].rotation : q->peaks[i].rotation;
		csv_row(&t, q->npoints ? "point" : "peak", "", deg(beta), rot_name(rot), v);
	}
	for (int ro = 0; ro < r->nrot && r->ncurve; ro++)
		for (size_t k = 0; k < r->ncurve; k++) {
			size_t i = (size_t)ro * r->ncurve + k;
			double v[8] = {NAN, NAN, r->curve_fit[i], r->curve_fit_u[i], NAN,
				       r->curve_start[i], r->band_lo[i], r->band_hi[i]};
			csv_row(&t, "curve", "", deg(r->curve_beta[k]),
				rot_name(r->rotations[ro]), v);
		}
	return take(&t);
}
