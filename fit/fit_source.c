/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_source.c - a fit's parameters with their uncertainties as the
 * source of bands on other curves (fit.h "bands on other curves"): read
 * back from a fit's JSON result (`convsim fit`'s, which the CLI's
 * --band-from names, or a fit job's, which a sweep's band_from_fit
 * names), applied to a study's model, and one study point's band by the
 * delta method that the fit's own band uses (fit_delta_half, fit_step). The reader takes the members
 * fit_out.c writes and skips every other; it is a reader of that result,
 * not a general JSON library.
 */
#include <ctype.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "decimal.h"
#include "fit.h"
#include "sim_mirror.h"
#include "units.h"

/* The covariance is finite and its diagonal positive: a band can be made. */
static int cov_ok(const fit_band_source *src)
{
	int p = src->nfree;
	for (int a = 0; a < p * p; a++)
		if (!isfinite(src->cov[a]))
			return 0;
	for (int a = 0; a < p; a++)
		if (!(src->cov[a * p + a] >= 0))
			return 0;
	return p > 0 && isfinite(src->quantile);
}

/* ---- the reader of fit_result_json's text ---- */

typedef struct scan {
	const char *s;
	int bad;
	int depth; /* of skip's nesting: a file nested deeper is refused */
} scan;

#define SCAN_MAX_DEPTH 64

static void ws(scan *c)
{
	while (isspace((unsigned char)*c->s))
		c->s++;
}

static int eat(scan *c, char ch)
{
	ws(c);
	if (*c->s != ch)
		return 0;
	c->s++;
	return 1;
}

/* A string into buf (escapes kept as their letter; names need none). */
static int string(scan *c, char *buf, size_t len)
{
	size_t n = 0;
	if (!eat(c, '"'))
		return c->bad = 1, 0;
	for (; *c->s && *c->s != '"'; c->s++) {
		if (*c->s == '\\' && c->s[1])
			c->s++;
		if (buf && n + 1 < len)
			buf[n++] = *c->s;
	}
	if (*c->s != '"')
		return c->bad = 1, 0;
	c->s++;
	if (buf)
		buf[n] = '\0';
	return 1;
}

/* A number (a plain decimal one, decimal.h: as JSON writes it, never
 * 0x10 or inf), or null as NaN. */
static double number(scan *c)
{
	ws(c);
	if (strncmp(c->s, "null", 4) == 0) {
		c->s += 4;
		return NAN;
	}
	double v = NAN;
	size_t n = sim_decimal_len(c->s, SIZE_MAX);
	if (!sim_decimal_n(c->s, n, &v))
		c->bad = 1;
	c->s += n;
	return v;
}

/* Skip any value (nested arrays and objects, strings, literals). */
static void skip(scan *c)
{
	ws(c);
	if (*c->s == '"') {
		string(c, NULL, 0);
		return;
	}
	if (*c->s == '[' || *c->s == '{') {
		char close = *c->s == '[' ? ']' : '}';
		if (++c->depth > SCAN_MAX_DEPTH) {
			c->bad = 1;
			return;
		}
		c->s++;
		if (eat(c, close)) {
			c->depth--;
			return;
		}
		do {
			if (close == '}') {
				string(c, NULL, 0);
				if (!eat(c, ':'))
					c->bad = 1;
			}
			skip(c);
		} while (!c->bad && eat(c, ','));
		if (!eat(c, close))
			c->bad = 1;
		c->depth--;
		return;
	}
	const char *start = c->s;
	while (*c->s && (isalnum((unsigned char)*c->s) || strchr("+-.", *c->s)))
		c->s++;
	if (c->s == start)
		c->bad = 1;
}

/* What the reader keeps, in user units. */
typedef struct read_fit {
	int n;
	char name[FIT_MAX_FREE][24];
	double value[FIT_MAX_FREE], se[FIT_MAX_FREE], lo[FIT_MAX_FREE], hi[FIT_MAX_FREE];
	double corr[FIT_MAX_FREE * FIT_MAX_FREE];
	int ncorr;
	double dof;
	char status[24], from[32];
} read_fit;

/* One member of a parameter object. */
static void parameter_member(scan *c, read_fit *f, const char *key)
{
	int i = f->n;
	double *dst = strcmp(key, "value") == 0	       ? &f->value[i]
		      : strcmp(key, "standard_error") == 0 ? &f->se[i]
		      : strcmp(key, "min") == 0		   ? &f->lo[i]
		      : strcmp(key, "max") == 0		   ? &f->hi[i]
							   : NULL;
	if (strcmp(key, "name") == 0)
		string(c, f->name[i], sizeof f->name[i]);
	else if (dst)
		*dst = number(c);
	else
		skip(c);
}

static void parameters(scan *c, read_fit *f)
{
	if (!eat(c, '['))
		return (void)(c->bad = 1);
	if (eat(c, ']'))
		return;
	do {
		if (f->n == FIT_MAX_FREE || !eat(c, '{'))
			return (void)(c->bad = 1);
		f->name[f->n][0] = '\0';
		f->value[f->n] = f->se[f->n] = f->lo[f->n] = f->hi[f->n] = NAN;
		if (!eat(c, '}')) {
			do {
				char key[32];
				string(c, key, sizeof key);
				if (c->bad || !eat(c, ':'))
					return (void)(c->bad = 1);
				parameter_member(c, f, key);
			} while (!c->bad && eat(c, ','));
			if (!eat(c, '}'))
				return (void)(c->bad = 1);
		}
		f->n++;
	} while (!c->bad && eat(c, ','));
	if (!eat(c, ']'))
		c->bad = 1;
}

/* The correlation: rows of numbers (null: NaN), row-major into corr. */
static void correlation(scan *c, read_fit *f)
{
	int row = 0;
	if (!eat(c, '['))
		return (void)(c->bad = 1);
	if (eat(c, ']'))
		return;
	do {
		int col = 0;
		if (row == FIT_MAX_FREE || !eat(c, '['))
			return (void)(c->bad = 1);
		if (!eat(c, ']')) {
			do {
				double v = number(c);
				if (col < FIT_MAX_FREE)
					f->corr[row * FIT_MAX_FREE + col] = v;
				col++;
			} while (!c->bad && eat(c, ','));
			if (!eat(c, ']'))
				return (void)(c->bad = 1);
		}
		if (col != f->n)
			c->bad = 1;
		row++;
	} while (!c->bad && eat(c, ','));
	f->ncorr = row;
	if (!eat(c, ']'))
		c->bad = 1;
}

/* The top-level object's members that matter. */
static int read_members(const char *json, read_fit *f)
{
	scan c = {.s = json};
	f->dof = NAN;
	if (!eat(&c, '{'))
		return -1;
	if (eat(&c, '}'))
		return 0;
	do {
		char key[40];
		string(&c, key, sizeof key);
		if (c.bad || !eat(&c, ':'))
			return -1;
		if (strcmp(key, "parameters") == 0)
			parameters(&c, f);
		else if (strcmp(key, "correlation") == 0)
			correlation(&c, f);
		else if (strcmp(key, "dof") == 0)
			f->dof = number(&c);
		else if (strcmp(key, "status") == 0)
			string(&c, f->status, sizeof f->status);
		else if (strcmp(key, "standard_errors_from") == 0)
			string(&c, f->from, sizeof f->from);
		else
			skip(&c);
	} while (!c.bad && eat(&c, ','));
	if (c.bad || !eat(&c, '}'))
		return -1;
	ws(&c);
	return *c.s ? -1 : 0;
}

int fit_band_source_parse(const char *json, fit_band_source *src, char *msg, size_t len)
{
	read_fit *f = calloc(1, sizeof *f);
	int rc = SIM_EPARAM;
	memset(src, 0, sizeof *src);
	if (!f) {
		snprintf(msg, len, "out of memory");
		return SIM_ENOMEM;
	}
	if (read_members(json, f) != 0) {
		snprintf(msg, len, "not the JSON result of convsim fit (a JSON object with "
				   "\"parameters\" and \"correlation\")");
		goto done;
	}
	if (f->n == 0 || f->ncorr != f->n) {
		snprintf(msg, len, "\"parameters\" and a \"correlation\" of as many rows are needed");
		goto done;
	}
	if (strcmp(f->status, "failed") == 0 || strcmp(f->status, "cancelled") == 0) {
		snprintf(msg, len, "the fit %s: its parameters have no uncertainties", f->status);
		goto done;
	}
	src->nfree = f->n;
	src->fd_rel = 0.05; /* fit_request_init's */
	src->quantile = fit_band_quantile(strcmp(f->from, "sigma") == 0,
					  isfinite(f->dof) ? (int)f->dof : 0);
	for (int j = 0; j < f->n; j++) {
		int err;
		char why[FIT_MSG];
		const sim_setting *t = fit_free_param(f->name[j], &err, why, sizeof why);
		if (!t) {
			snprintf(msg, len, "parameters[%d]: %s", j, why);
			goto done;
		}
		if (!isfinite(f->value[j]) || !isfinite(f->lo[j]) || !isfinite(f->hi[j]) ||
		    !(f->lo[j] < f->hi[j]) || !(f->se[j] >= 0)) {
			snprintf(msg, len, "parameters[%d] (%s): value, min < max and standard_error "
					   "must be finite numbers",
				 j, f->name[j]);
			goto done;
		}
		snprintf(src->free[j].name, sizeof src->free[j].name, "%s", t->name);
		src->x[j] = sim_setting_to_si(t, f->value[j]);
		src->free[j].lo = sim_setting_to_si(t, f->lo[j]);
		src->free[j].hi = sim_setting_to_si(t, f->hi[j]);
	}
	for (int a = 0; a < f->n; a++)
		for (int b = 0; b < f->n; b++) {
			const sim_setting *ta = sim_setting_find(src->free[a].name);
			const sim_setting *tb = sim_setting_find(src->free[b].name);
			double sa = sim_setting_to_si(ta, f->se[a]) - sim_setting_to_si(ta, 0);
			double sb = sim_setting_to_si(tb, f->se[b]) - sim_setting_to_si(tb, 0);
			src->cov[a * f->n + b] = f->corr[a * FIT_MAX_FREE + b] * sa * sb;
		}
	if (!cov_ok(src)) {
		snprintf(msg, len, "the fit's covariance is not determined (a correlation or "
				   "standard error is null): no band can be drawn from it");
		goto done;
	}
	rc = SIM_OK;
done:
	free(f);
	return rc;
}

int fit_band_source_prepare(const fit_band_source *src, const char *const *varied, size_t nvaried,
			    int *skip, sim_params *p, sim_scene *s, sim_method *m, char *msg,
			    size_t len)
{
	for (int j = 0; j < src->nfree; j++) {
		skip[j] = 0;
		for (size_t a = 0; a < nvaried; a++)
			skip[j] |= strcmp(varied[a], src->free[j].name) == 0;
	}
	for (int j = 0; j < src->nfree; j++) {
		if (skip[j])
			continue;
		int rc = sim_set(p, s, m, src->free[j].name, src->x[j], msg, len);
		if (rc != SIM_OK)
			return rc;
	}
	/* the images of the mirror reduction take their sources' bands only
	 * where every perturbed model is mirror-symmetric as well */
	for (int j = 0; j < src->nfree; j++) {
		sim_params pj = *p;
		sim_scene sj = *s;
		sim_method mj = *m;
		if (skip[j] || !sim_mirror_applies(&pj, &sj))
			continue;
		double x = src->x[j] + fit_step(&src->free[j], src->fd_rel, src->x[j]);
		if (sim_set(&pj, &sj, &mj, src->free[j].name, x, NULL, 0) != SIM_OK ||
		    !sim_mirror_applies(&pj, &sj))
			s->mirror = 0;
	}
	return SIM_OK;
}

int fit_band_point(const fit_band_source *src, const int *skip, const sim_params *p,
		   const sim_scene *s, const sim_method *m, double t_end,
		   const sim_measurement *at, double *lower, double *upper, char *msg,
		   size_t len)
{
	double vp[FIT_MAX_FREE], h[FIT_MAX_FREE], cov[FIT_MAX_FREE * FIT_MAX_FREE];
	int keep[FIT_MAX_FREE], n = 0;
	*lower = *upper = NAN;
	for (int j = 0; j < src->nfree; j++)
		if (!(skip && skip[j]))
			keep[n++] = j;
	for (int a = 0; a < n; a++) {
		int j = keep[a];
		sim_params pj = *p;
		sim_scene sj = *s;
		sim_method mj = *m;
		sim_measurement r;
		h[a] = fit_step(&src->free[j], src->fd_rel, src->x[j]);
		int rc = sim_set(&pj, &sj, &mj, src->free[j].name, src->x[j] + h[a], msg, len);
		if (rc == SIM_OK)
			rc = sim_measure(&pj, &sj, &mj, t_end, &r, msg, len);
		if (rc != SIM_OK)
			return rc;
		vp[a] = r.transport_velocity;
		for (int b = 0; b < n; b++)
			cov[a * n + b] = src->cov[j * src->nfree + keep[b]];
	}
	double v = at->transport_velocity;
	double half = fit_delta_half(n, cov, src->quantile, v, vp, h, at->uncertainty);
	*lower = v - half;
	*upper = v + half;
	return SIM_OK;
}
