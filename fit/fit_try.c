/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_try.c - the fit's evaluations that may fail: a batch of parameter
 * sets where one set cannot be evaluated (a run fails, a peak is not
 * found, the request's veto) is not the end. The evaluator stops a whole
 * batch at its first failure; the sets of a failed batch are then run one
 * by one to find which fail, and those are flagged (ok = 0, with the
 * reason and the parameter values in the fit's `why`) for the driver
 * (fit.c) to reject as steps or to step around in a Jacobian.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fit_int.h"
#include "units.h"

/* The free values x as "e = 0.0201 m, mu = 0.3" (user units). */
static void describe_x(const fit_ctx *c, const double *x, char *buf, size_t len)
{
	size_t at = 0;
	for (int j = 0; j < c->p && at < len; j++) {
		const sim_setting *t = sim_setting_find(c->req->free[j].name);
		at += (size_t)snprintf(buf + at, len - at, "%s%s = %.6g%s%s", j ? ", " : "", t->name,
				       sim_setting_from_si(t, x[j]), *sim_unit_shown(t) ? " " : "",
				       sim_unit_shown(t));
	}
}

/* Set s of a batch cannot be evaluated: ok[s] = 0 and the reason in c->why. */
static void set_failed(fit_ctx *c, const double *x, const char *reason, int *ok)
{
	char at[120];
	describe_x(c, x, at, sizeof at);
	snprintf(c->why, FIT_MSG, "at %.100s: %.120s", at, reason);
	*ok = 0;
}

/* Clear the evaluator's failure (the batch is over), so that the next
 * batch runs; its reason into reason. */
static void clear_failure(fit_ctx *c, char *reason, size_t len)
{
	pthread_mutex_lock(&c->ev.lock);
	snprintf(reason, len, "%s", c->ev.error);
	c->ev.failed = 0;
	c->ev.error[0] = '\0';
	pthread_mutex_unlock(&c->ev.lock);
}

/* Set x's failure from the evaluator: cleared, ok = 0, c->why. */
static void take_failure(fit_ctx *c, const double *x, int *ok)
{
	char reason[FIT_MSG];
	clear_failure(c, reason, sizeof reason);
	set_failed(c, x, reason, ok);
}

int fit_evaluate(fit_ctx *c, size_t nsets, const double *xs, double *out, double *out_u, int *ok)
{
	const fit_request *r = c->req;
	size_t p = (size_t)c->p, n = c->n, nrun = 0;
	double *xr = malloc(sizeof *xr * nsets * p), *vr = malloc(sizeof *vr * nsets * n),
	       *ur = malloc(sizeof *ur * nsets * n);
	size_t *set = malloc(sizeof *set * nsets);
	int rc = xr && vr && ur && set ? 0 : -1;
	for (size_t s = 0; rc == 0 && s < nsets; s++) {
		ok[s] = 1;
		if (r->veto && r->veto(r->ctx, xs + s * p)) {
			set_failed(c, xs + s * p, "vetoed by the caller", &ok[s]);
			continue;
		}
		memcpy(xr + nrun * p, xs + s * p, sizeof *xr * p);
		set[nrun++] = s;
	}
	if (rc == 0 && nrun && fit_eval_data(&c->ev, nrun, xr, vr, ur) != 0) {
		/* a failure stops the whole batch: find the sets that fail alone */
		if (c->ev.failed != 1)
			rc = -1;
		else if (nrun == 1)
			take_failure(c, xr, &ok[set[0]]);
		for (size_t k = 0; rc == 0 && nrun > 1 && k < nrun; k++) {
			char ignored[FIT_MSG];
			if (k == 0)
				clear_failure(c, ignored, sizeof ignored);
			if (fit_eval_data(&c->ev, 1, xr + k * p, vr + k * n, ur + k * n) == 0)
				continue;
			if (c->ev.failed != 1)
				rc = -1;
			else
				take_failure(c, xr + k * p, &ok[set[k]]);
		}
	}
	for (size_t k = 0; rc == 0 && k < nrun; k++) {
		memcpy(out + set[k] * n, vr + k * n, sizeof *out * n);
		if (out_u)
			memcpy(out_u + set[k] * n, ur + k * n, sizeof *out_u * n);
	}
	for (size_t s = 0; rc == 0 && s < nsets; s++)
		for (size_t i = 0; !ok[s] && i < n; i++) {
			out[s * n + i] = NAN;
			if (out_u)
				out_u[s * n + i] = NAN;
		}
	if (!xr || !vr || !ur || !set) {
		snprintf(c->ev.error, FIT_MSG, "out of memory");
		c->ev.failed = 1;
	}
	free(xr);
	free(vr);
	free(ur);
	free(set);
	return rc;
}
