/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_data.c - what a fit is given, checked before anything runs: the
 * free parameters (by name from the settings table, bounds from their
 * ranges), the measured points as CSV (header beta,rotation,v[,sigma]) and
 * the whole request (fit_check). Messages speak in user units (deg) and
 * name the field, so the CLI and the API report alike.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "decimal.h"
#include "fit.h"
#include "suggest.h"
#include "units.h"

void fit_request_init(fit_request *r)
{
	memset(r, 0, sizeof *r);
	sim_preset_czubak2016(&r->p, &r->sc, &r->m);
	r->t_end = r->sc.transient + 4.0;
	r->peak_halfwidth = 10.0 * RAD_PER_DEG;
	r->peak_step = 2.0 * RAD_PER_DEG;
	r->curve_step = 5.0 * RAD_PER_DEG;
	r->max_iter = 30;
	r->starts = 1;
	r->fd_rel = 0.05;
	r->xtol = 1e-3;
	r->threads = 2;
}

const char *fit_status_name(int status)
{
	static const char *const names[] = {"converged", "max-iterations", "cancelled", "failed"};
	return status >= 0 && status <= FIT_FAILED ? names[status] : "failed";
}

/* Settings of group params that no steady state depends on, or that each
 * point sets itself. */
static int fixed_only(const char *name)
{
	static const char *const fixed[] = {"beta", "beta_rate", "beta_accel", "drive_accel"};
	for (size_t i = 0; i < sizeof fixed / sizeof *fixed; i++)
		if (strcmp(fixed[i], name) == 0)
			return 1;
	return 0;
}

const sim_setting *fit_free_param(const char *name, int *err, char *msg, size_t len)
{
	const sim_setting *t = sim_setting_find(name);
	if (!t) {
		size_t n;
		const sim_setting *all = sim_settings(&n);
		const char *near = sim_suggest(name, &all->name, n, sizeof *all);
		snprintf(msg, len, "unknown parameter '%s'%s%s%s; 'convsim list' shows every setting",
			 name, near ? " (did you mean '" : "", near ? near : "", near ? "'?)" : "");
		*err = SIM_EUNKNOWN;
		return NULL;
	}
	if (t->kind != SIM_KIND_REAL || strcmp(t->group, "params") != 0 || fixed_only(name)) {
		snprintf(msg, len,
			 "'%s' cannot be fitted: free parameters are the real model parameters "
			 "(group params) but beta (set by each point), beta_rate, beta_accel and "
			 "drive_accel; integer, true/false, choice, scene and integrator settings "
			 "stay fixed",
			 name);
		*err = SIM_EPARAM;
		return NULL;
	}
	return t;
}

int fit_add_free(fit_request *req, const char *name, double lo_user, double hi_user,
		 char *field, size_t flen, char *msg, size_t mlen, fit_range *range)
{
	int err;
	snprintf(field, flen, "name");
	if (range)
		*range = (fit_range){0};
	const sim_setting *t = fit_free_param(name, &err, msg, mlen);
	if (!t)
		return err;
	for (int i = 0; i < req->nfree; i++)
		if (strcmp(req->free[i].name, name) == 0) {
			snprintf(msg, mlen, "free parameter '%s' is named twice", name);
			return SIM_EPARAM;
		}
	if (req->nfree >= FIT_MAX_FREE) {
		snprintf(msg, mlen, "at most %d free parameters", FIT_MAX_FREE);
		return SIM_EPARAM;
	}
	double lo = isnan(lo_user) ? t->min : lo_user, hi = isnan(hi_user) ? t->max : hi_user;
	if (!(lo >= t->min && hi <= t->max && lo < hi)) {
		/* the bound at fault: min below the range or not below max
		 * (min in [table min, table max)), else max ((min, table max]) */
		int at_min = !(lo >= t->min && lo < t->max);
		snprintf(field, flen, "%s", at_min ? "min" : "max");
		if (range)
			*range = (fit_range){.has = 1, .min = at_min ? t->min : lo, .max = t->max};
		snprintf(msg, mlen, "the bounds of '%s' must satisfy %g <= min < max <= %g %s", name,
			 t->min, t->max, sim_unit_shown(t));
		return SIM_EPARAM;
	}
	fit_free *f = &req->free[req->nfree++];
	snprintf(f->name, sizeof f->name, "%s", name);
	f->lo = sim_setting_to_si(t, lo);
	f->hi = sim_setting_to_si(t, hi);
	sim_get(&req->p, &req->sc, &req->m, name, &f->start);
	return SIM_OK;
}

/* ---- CSV ---------------------------------------------------------------- */

enum { COL_BETA, COL_ROTATION, COL_V, COL_SIGMA, NCOLS };
static const char *const col_names[NCOLS] = {"beta", "rotation", "v", "sigma"};

/* The header's columns into col[] (index of each name, -1 if absent). */
static int parse_header(const char *line, size_t len, int col[NCOLS], char *msg, size_t mlen)
{
	for (int c = 0; c < NCOLS; c++)
		col[c] = -1;
	int k = 0;
	for (const char *p = line, *end = line + len; p <= end; k++) {
		const char *q = memchr(p, ',', (size_t)(end - p));
		size_t n = (size_t)((q ? q : end) - p);
		while (n && (p[n - 1] == ' ' || p[n - 1] == '\r'))
			n--;
		while (n && *p == ' ')
			p++, n--;
		int c = 0;
		while (c < NCOLS && !(strlen(col_names[c]) == n && strncmp(p, col_names[c], n) == 0))
			c++;
		if (n == 8 && strncmp(p, "velocity", 8) == 0)
			c = COL_V; /* the sweep table's name for v */
		if (c == NCOLS) {
			snprintf(msg, mlen, "CSV line 1: unknown column '%.*s'; the header is "
					    "beta,rotation,v[,sigma]", (int)(n > 40 ? 40 : n), p);
			return -1;
		}
		col[c] = k;
		p = q ? q + 1 : end + 1;
	}
	for (int c = 0; c < COL_SIGMA; c++)
		if (col[c] < 0) {
			snprintf(msg, mlen, "CSV line 1: column '%s' is missing; the header is "
					    "beta,rotation,v[,sigma]", col_names[c]);
			return -1;
		}
	return k;
}

/* One data line of ncol cells into *pt; a rotation that is no sense
 * with its choices in *range (when not NULL). */
static int parse_row(char *line, int lineno, const int col[NCOLS], int ncol, fit_point *pt,
		     char *msg, size_t mlen, fit_range *range)
{
	char *cell[16] = {0};
	int k = 0;
	for (char *save, *tok = strtok_r(line, ",", &save); tok && k < 16;
	     tok = strtok_r(NULL, ",", &save))
		cell[k++] = tok;
	if (k != ncol) {
		snprintf(msg, mlen, "CSV line %d: %d cells where the header has %d", lineno, k,
			 ncol);
		return -1;
	}
	double num[NCOLS] = {0, 0, 0, NAN};
	for (int c = 0; c < NCOLS; c++) {
		if (col[c] < 0 || c == COL_ROTATION)
			continue;
		/* a plain decimal number (decimal.h), spaces around it allowed:
		 * "30, cw, 0.1" as people write it, never 0x10 or inf */
		char *s = cell[col[c]] + strspn(cell[col[c]], " ");
		size_t n = strlen(s);
		while (n && (s[n - 1] == ' ' || s[n - 1] == '\r'))
			n--;
		if (!sim_decimal_n(s, n, &num[c])) {
			snprintf(msg, mlen, "CSV line %d: %s must be a number, got '%.*s'", lineno,
				 col_names[c], (int)(n > 40 ? 40 : n), s);
			return -1;
		}
	}
	char *r = cell[col[COL_ROTATION]];
	r += strspn(r, " ");
	r[strcspn(r, " \r")] = '\0';
	if (strcmp(r, "cw") != 0 && strcmp(r, "ccw") != 0) {
		snprintf(msg, mlen, "CSV line %d: rotation must be cw or ccw, got '%.40s'", lineno, r);
		if (range)
			range->choices = sim_setting_find("rotation")->choices;
		return -1;
	}
	pt->beta = num[COL_BETA] * RAD_PER_DEG;
	pt->rotation = r[1] == 'w' ? SIM_CW : SIM_CCW;
	pt->v = num[COL_V];
	pt->sigma = num[COL_SIGMA];
	pt->line = lineno;
	return 0;
}

int fit_parse_csv(const char *text, fit_point **out, size_t *n, char *msg, size_t mlen,
		  fit_range *range)
{
	*out = NULL;
	*n = 0;
	if (range)
		*range = (fit_range){0};
	size_t len = strlen(text);
	char *buf = malloc(len + 1);
	fit_point *pts = malloc(sizeof *pts * FIT_MAX_POINTS);
	if (!buf || !pts) {
		free(buf);
		free(pts);
		snprintf(msg, mlen, "out of memory");
		return SIM_ENOMEM;
	}
	memcpy(buf, text, len + 1);
	int col[NCOLS], ncol = -1, lineno = 0, rc = SIM_OK;
	/* line by line, blank ones counted (strtok_r would skip them and the
	 * messages' line numbers with them) */
	for (char *line = buf, *next; line && rc == SIM_OK; line = next) {
		char *nl = strchr(line, '\n');
		next = nl ? nl + 1 : NULL;
		if (nl)
			*nl = '\0';
		lineno++;
		if (line[strspn(line, " \r\t")] == '\0' || line[0] == '#')
			continue;
		if (ncol < 0) {
			ncol = parse_header(line, strlen(line), col, msg, mlen);
			rc = ncol < 0 ? SIM_EPARAM : SIM_OK;
		} else if (*n >= FIT_MAX_POINTS) {
			snprintf(msg, mlen, "CSV line %d: more than %d points", lineno,
				 FIT_MAX_POINTS);
			if (range)
				*range = (fit_range){.has = 1, .min = 1, .max = FIT_MAX_POINTS};
			rc = SIM_EPARAM;
		} else if (parse_row(line, lineno, col, ncol, &pts[*n], msg, mlen, range) == 0) {
			(*n)++;
		} else {
			rc = SIM_EPARAM;
		}
	}
	free(buf);
	if (rc == SIM_OK && ncol < 0) {
		snprintf(msg, mlen, "CSV: no header line (beta,rotation,v[,sigma])");
		rc = SIM_EPARAM;
	}
	if (rc != SIM_OK) {
		free(pts);
		*n = 0;
		return rc;
	}
	*out = pts;
	return SIM_OK;
}

/* ---- the whole request -------------------------------------------------- */

#define FAIL(f, ...)                                         \
	do {                                                 \
		snprintf(field, flen, "%s", f);              \
		snprintf(msg, mlen, __VA_ARGS__);            \
		return SIM_EPARAM;                           \
	} while (0)

/* A value outside [lo, hi] (user unit): FAIL with the range. */
#define FAIL_RANGE(f, lo, hi, ...)                                             \
	do {                                                                   \
		if (range)                                                     \
			*range = (fit_range){.has = 1, .min = lo, .max = hi};  \
		FAIL(f, __VA_ARGS__);                                          \
	} while (0)

/* name: the field's ("points[2]"); who: the messages' ("CSV line 4") */
static int check_beta(double beta, int rotation, const char *name, const char *who, char *field,
		      size_t flen, char *msg, size_t mlen, fit_range *range)
{
	char f[48];
	snprintf(f, sizeof f, "%s.beta", name);
	if (!(isfinite(beta) && beta >= 0 && beta <= SIM_PI * (1 + 1e-12)))
		FAIL_RANGE(f, 0, 180, "%s: beta must be a finite number in [0, 180] deg", who);
	if (rotation != SIM_CW && rotation != SIM_CCW) {
		snprintf(f, sizeof f, "%s.rotation", name);
		FAIL(f, "%s: rotation must be cw or ccw", who);
	}
	return SIM_OK;
}

/* Point i as messages name it: its CSV line, else points[i]. */
static const char *point_name(const fit_request *r, size_t i, char *buf, size_t len)
{
	if (r->points[i].line > 0)
		snprintf(buf, len, "CSV line %d", r->points[i].line);
	else
		snprintf(buf, len, "points[%zu]", i);
	return buf;
}

static int check_points(const fit_request *r, char *field, size_t flen, char *msg, size_t mlen,
			fit_range *range)
{
	char name[32], who[32], f[48], other[32];
	int with_sigma = r->npoints && !isnan(r->points[0].sigma);
	for (size_t i = 0; i < r->npoints; i++) {
		const fit_point *p = &r->points[i];
		snprintf(name, sizeof name, "points[%zu]", i);
		point_name(r, i, who, sizeof who);
		if (check_beta(p->beta, p->rotation, name, who, field, flen, msg, mlen, range))
			return SIM_EPARAM;
		snprintf(f, sizeof f, "%s.v", name);
		if (!isfinite(p->v) || fabs(p->v) > 100)
			FAIL_RANGE(f, -100, 100, "%s: v must be a finite number in [-100, 100] m/s", who);
		snprintf(f, sizeof f, "%s.sigma", name);
		if (!isnan(p->sigma) && !(isfinite(p->sigma) && p->sigma > 0 && p->sigma <= 100))
			FAIL_RANGE(f, 0, 100, "%s: sigma must be a number in (0, 100] m/s", who);
		if (isnan(p->sigma) == with_sigma)
			FAIL(f, "%s: sigma must be given for every point or for none", who);
		for (size_t k = 0; k < i; k++)
			if (fabs(r->points[k].beta - p->beta) < 1e-9 &&
			    r->points[k].rotation == p->rotation)
				FAIL(name, "%s duplicates %s (beta %g deg, %s)", who,
				     point_name(r, k, other, sizeof other), p->beta * DEG_PER_RAD,
				     p->rotation == SIM_CW ? "cw" : "ccw");
	}
	return SIM_OK;
}

static int check_peaks(const fit_request *r, char *field, size_t flen, char *msg, size_t mlen,
		       fit_range *range)
{
	char name[32], f[48];
	for (int i = 0; i < r->npeaks; i++) {
		const fit_peak *p = &r->peaks[i];
		snprintf(name, sizeof name, "peaks[%d]", i);
		if (check_beta(p->beta, p->rotation, name, name, field, flen, msg, mlen, range))
			return SIM_EPARAM;
		snprintf(f, sizeof f, "%s.sigma", name);
		if (!isnan(p->sigma) && !(isfinite(p->sigma) && p->sigma > 0 && p->sigma <= SIM_PI))
			FAIL_RANGE(f, 0, 180, "%s: sigma must be a number in (0, 180] deg", name);
		if (isnan(p->sigma) != isnan(r->peaks[0].sigma))
			FAIL(f, "%s: sigma must be given for every peak or for none", name);
		for (int k = 0; k < i; k++)
			if (r->peaks[k].rotation == p->rotation &&
			    fabs(r->peaks[k].beta - p->beta) < 2 * r->peak_halfwidth)
				FAIL(name, "%s is within %g deg of peaks[%d] (%s): their scans "
					   "would overlap", name, 2 * r->peak_halfwidth * DEG_PER_RAD,
				     k, p->rotation == SIM_CW ? "cw" : "ccw");
	}
	return SIM_OK;
}

int fit_check(const fit_request *r, char *field, size_t flen, char *msg, size_t mlen)
{
	return fit_check_range(r, field, flen, msg, mlen, NULL);
}

int fit_check_range(const fit_request *r, char *field, size_t flen, char *msg, size_t mlen,
		    fit_range *range)
{
	if (range)
		*range = (fit_range){0};
	if (sim_validate(&r->p, &r->sc, &r->m, msg, mlen) != SIM_OK) {
		snprintf(field, flen, "params");
		return SIM_EPARAM;
	}
	if (!(r->t_end > r->sc.transient && r->t_end <= 600))
		FAIL_RANGE("t_end", r->sc.transient, 600, "t_end must exceed the scene's transient (%g s) and be at most 600 s",
		     r->sc.transient);
	if (r->nfree < 1)
		FAIL_RANGE("free", 1, FIT_MAX_FREE, "name at least one free parameter (e.g. e; 1 to %d)",
			   FIT_MAX_FREE);
	if (r->npoints && r->npeaks)
		FAIL("peaks", "give points or peaks, not both");
	if (!r->npoints && !r->npeaks)
		FAIL("points", "no data: give points (beta, rotation, v[, sigma]) or peaks");
	/* the data's count: at least one a free parameter, at most the
	 * table's (the API refuses more before it reads them) */
	size_t ndata = r->npoints ? r->npoints : (size_t)r->npeaks;
	int most = r->npoints ? FIT_MAX_POINTS : FIT_MAX_PEAKS;
	const char *kind = r->npoints ? "points" : "peaks";
	if (ndata > (size_t)most)
		FAIL_RANGE(kind, r->nfree, most, "%zu %s for %d free parameter%s: a fit takes %d to %d",
			   ndata, kind, r->nfree, r->nfree == 1 ? "" : "s", r->nfree, most);
	if (check_points(r, field, flen, msg, mlen, range) ||
	    check_peaks(r, field, flen, msg, mlen, range))
		return SIM_EPARAM;
	if (ndata < (size_t)r->nfree)
		FAIL_RANGE(kind, r->nfree, most,
			   "%zu data for %d free parameters: a fit needs at least as many data as "
			   "free parameters (%d to %d %s)", ndata, r->nfree, r->nfree, most, kind);
	for (int i = 0; i < r->nfree; i++) {
		const fit_free *f = &r->free[i];
		char at[32];
		snprintf(at, sizeof at, "free[%d].start", i);
		const sim_setting *t = sim_setting_find(f->name);
		double lo = sim_setting_from_si(t, f->lo), hi = sim_setting_from_si(t, f->hi);
		if (!(f->start >= f->lo && f->start <= f->hi))
			FAIL_RANGE(at, lo, hi, "the start of '%s' (%g) lies outside its bounds [%g, %g]",
				   f->name, sim_setting_from_si(t, f->start), lo, hi);
		/* a prior weighs against the data's residuals in units of their
		 * sigma: without it the two are on no common scale */
		if (fit_has_prior(&r->prior[i]) &&
		    isnan(r->npoints ? r->points[0].sigma : r->peaks[0].sigma)) {
			snprintf(at, sizeof at, "free[%d].prior", i);
			FAIL(at, "a prior (on '%s') needs the data's sigma, to weigh the two "
				 "against each other: give sigma with every %s", f->name,
			     r->npoints ? "point" : "peak");
		}
	}
	if (!(r->fd_rel > 0 && r->fd_rel <= 0.5))
		FAIL_RANGE("fd_step", 0, 0.5, "fd_step must be in (0, 0.5]");
	if (!(r->max_iter >= 1 && r->max_iter <= FIT_MAX_ITER))
		FAIL_RANGE("max_iter", 1, FIT_MAX_ITER, "max_iter must be in [1, %d]", FIT_MAX_ITER);
	if (!(r->starts >= 1 && r->starts <= FIT_MAX_STARTS))
		FAIL_RANGE("starts", 1, FIT_MAX_STARTS, "starts must be in [1, %d]", FIT_MAX_STARTS);
	if (!(r->curve_step == 0 || (r->curve_step >= 0.5 * RAD_PER_DEG &&
				     r->curve_step <= 90 * RAD_PER_DEG)))
		FAIL_RANGE("curve_step", 0, 90,
			   "curve_step must be 0 (no curve) or in [0.5, 90] deg");
	return SIM_OK;
}
