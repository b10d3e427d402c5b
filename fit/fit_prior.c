/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit_prior.c - Gaussian priors on free parameters (fit.h "priors").
 *
 * A prior is one more residual beside the data's, r = (x - mean) / sd, or
 * on a log-normal prior r = (ln x - ln mean) / ln factor, so that the
 * least-squares cost is chi2 plus the priors' r^2: minus twice the log of
 * the posterior, up to a constant, and its minimum the maximum a
 * posteriori estimate. Its row of the Jacobian has one entry, dr/dx, and
 * the covariance from (J^T J)^-1 over all rows is the posterior's
 * (linearised). The data's residuals must be weighted by their sigma for
 * the two kinds of row to be on one scale (fit_check).
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "fit.h"
#include "units.h"

int fit_has_prior(const fit_prior *pr)
{
	return pr->sd > 0;
}

double fit_prior_residual(const fit_prior *pr, double x)
{
	if (!fit_has_prior(pr))
		return 0;
	return pr->log ? (log(x) - log(pr->mean)) / pr->sd : (x - pr->mean) / pr->sd;
}

double fit_prior_slope(const fit_prior *pr, double x)
{
	if (!fit_has_prior(pr))
		return 0;
	return pr->log ? 1.0 / (x * pr->sd) : 1.0 / pr->sd;
}

double fit_prior_cost(const fit_request *req, const double *x)
{
	double cost = 0;
	for (int j = 0; j < req->nfree; j++) {
		double r = fit_prior_residual(&req->prior[j], x[j]);
		cost += r * r;
	}
	return cost;
}

/* A member of the prior outside [lo, hi]: its name and range. */
static void out_of(const char *name, double lo, double hi, const char **member,
		   fit_range *range)
{
	if (member)
		*member = name;
	if (range)
		*range = (fit_range){.has = 1, .min = lo, .max = hi};
}

int fit_set_prior(fit_request *req, const char *name, double mean, double sd, double factor,
		  char *msg, size_t mlen, const char **member, fit_range *range)
{
	if (member)
		*member = NULL;
	if (range)
		*range = (fit_range){0};
	fit_free *f = NULL;
	fit_prior *pr = NULL;
	for (int j = 0; j < req->nfree && !f; j++)
		if (strcmp(req->free[j].name, name) == 0) {
			f = &req->free[j];
			pr = &req->prior[j];
		}
	const sim_setting *t = sim_setting_find(name);
	if (!f || !t) {
		snprintf(msg, mlen, "a prior on '%s', which is not a free parameter: name it in free "
			 "first", name);
		return SIM_EPARAM;
	}
	if (fit_has_prior(pr)) {
		snprintf(msg, mlen, "'%s' has a prior already", name);
		return SIM_EPARAM;
	}
	int log_normal = isnan(sd);
	if (log_normal == isnan(factor)) {
		snprintf(msg, mlen, "the prior on '%s' takes a mean with either sd (normal) or factor "
			 "(log-normal), one of them", name);
		return SIM_EPARAM;
	}
	double lo = sim_setting_from_si(t, f->lo), hi = sim_setting_from_si(t, f->hi);
	if (!(isfinite(mean) && mean >= lo && mean <= hi) || (log_normal && !(mean > 0))) {
		out_of("mean", lo, hi, member, range);
		snprintf(msg, mlen, "the prior's mean of '%s' must lie within its bounds [%g, %g] %s%s",
			 name, lo, hi, sim_unit_shown(t), log_normal ? " and be positive" : "");
		return SIM_EPARAM;
	}
	if (log_normal ? !(isfinite(factor) && factor > 1 && factor <= 1e6)
		       : !(isfinite(sd) && sd > 0 && sd <= 10 * (hi - lo))) {
		if (log_normal) {
			out_of("factor", 1, 1e6, member, range);
			snprintf(msg, mlen, "the prior's factor of '%s' must be in (1, 1e6]", name);
		} else {
			out_of("sd", 0, 10 * (hi - lo), member, range);
			snprintf(msg, mlen, "the prior's sd of '%s' must be in (0, %g] %s (ten times "
				 "its range)", name, 10 * (hi - lo), sim_unit_shown(t));
		}
		return SIM_EPARAM;
	}
	if (log_normal && !(f->lo > 0)) {
		/* ln x at the bound 0 is no residual */
		snprintf(msg, mlen, "a log-normal prior on '%s' needs a positive lower bound: free it "
			 "as %s:MIN:MAX with MIN > 0", name, name);
		return SIM_EPARAM;
	}
	pr->mean = sim_setting_to_si(t, mean);
	pr->log = log_normal;
	pr->sd = log_normal ? log(factor) : sim_setting_to_si(t, sd);
	return SIM_OK;
}
