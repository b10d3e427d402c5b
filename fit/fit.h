/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fit.h - calibration: least-squares fits of model parameters to measured
 * transport velocities v(beta), or to the positions of the v(beta) peaks.
 *
 * Its own floor beside the engine: it calls the core (sim_measure, the
 * settings table) and GSL (gsl_multifit_nlinear, Levenberg-Marquardt in a
 * trust region), never cJSON or libmicrohttpd, and this header shows no GSL
 * type, so the CLI and api/ see plain structs. Every model evaluation is a
 * fresh sim_measure (a steady start and a window of t_end seconds); the
 * evaluations of one Jacobian (or one residual vector) run in parallel
 * through a caller's map function, or on the library's own threads.
 *
 * Units: SI inside (beta in rad, free parameters in their SI value);
 * fit_check and the parsers take and report user units as the settings
 * table gives them (beta in deg), converting once.
 */
#ifndef CONVSIM_FIT_H
#define CONVSIM_FIT_H

#include <stddef.h>

#include "pmap.h"
#include "sim.h"

#define FIT_MAX_FREE 8
#define FIT_MAX_POINTS 1000
#define FIT_MAX_PEAKS 8
#define FIT_MAX_WARNINGS 8
#define FIT_MSG 240
#define FIT_MAX_STARTS 32
#define FIT_MAX_ITER 1000

/* The range a refused value had to lie in, in its user unit, for answers
 * that give it (the API's min and max): fit_check_range, fit_add_free and fit_set_prior fill it (when
 * not NULL), has 0 for a refusal of another kind. An open end is given as
 * its limit: (0, 0.5] is min 0, max 0.5. A refused choice (a CSV row's
 * rotation) has its choices instead ("cw|ccw", the settings table's),
 * else choices is NULL. */
typedef struct fit_range {
	int has;
	double min, max;
	const char *choices;
} fit_range;

/* One measured point: beta (rad), rotation SIM_CW / SIM_CCW, v (m/s) and
 * its standard deviation sigma (m/s; NaN when not given); line: its line
 * in a CSV file (fit_parse_csv), 0 when it comes from elsewhere, so that
 * fit_check's messages name the line (the field stays points[i]). */
typedef struct fit_point {
	double beta;
	int rotation;
	double v, sigma;
	int line;
} fit_point;

/* One measured peak of v(beta) (the fastest transport in one direction):
 * its beta (rad) for a rotation, sigma (rad; NaN when not given). The
 * model's peak is located by a scan of v(beta) over a fixed grid around
 * the measured beta and a least-squares parabola through the scan's
 * largest |v| and two neighbours each side. */
typedef struct fit_peak {
	double beta;
	int rotation;
	double sigma;
} fit_peak;

/* A free parameter: a real setting of group "params" (fit_free_param), its
 * bounds and start (SI). */
typedef struct fit_free {
	char name[24];
	double lo, hi;
	double start;
} fit_free;

/* A Gaussian prior on a free parameter (fit_set_prior): one more residual,
 * (x - mean) / sd, or with log (ln x - ln mean) / sd, sd = ln of the
 * factor; none unless sd > 0. mean SI. (Beside fit_free, not in it: a
 * sweep's record holds fit_free as it is.) */
typedef struct fit_prior {
	double mean, sd;
	int log;
} fit_prior;

/* Progress reports (from the thread that runs fit_run). */
typedef struct fit_progress {
	const char *phase;   /* "fitting", "covariance", "curve", "done" */
	int iteration;
	long evaluations;    /* model evaluations (sim_measure runs) so far */
	double cost;         /* sum of squared (weighted) residuals; NaN before one */
	double x[FIT_MAX_FREE];
} fit_progress;

/* A fit's batches run on a map (pmap.h): the caller's (the daemon's pool)
 * or the library's threads. */
typedef pmap_job fit_job;
typedef pmap_fn fit_map_fn;

typedef struct fit_request {
	sim_params p;          /* the model; the free parameters' values are */
	sim_scene sc;          /* replaced, beta and rotation set per point */
	sim_method m;
	double t_end;          /* s simulated per evaluation (> sc.transient) */
	int nfree;
	fit_free free[FIT_MAX_FREE];
	fit_prior prior[FIT_MAX_FREE]; /* free[j]'s prior, if any */
	size_t npoints;        /* points or peaks, not both */
	fit_point *points;     /* borrowed */
	int npeaks;
	fit_peak peaks[FIT_MAX_PEAKS];
	double peak_halfwidth; /* rad: the scan covers beta_peak +- this */
	double peak_step;      /* rad: its spacing */
	double curve_step;     /* rad: the fitted curve's grid on [0, 180] deg; 0: none */
	int max_iter;
	int starts;            /* Levenberg-Marquardt runs, 1..FIT_MAX_STARTS: the
				* start, then points of a Halton design over
				* the bounds; the lowest cost wins */
	double fd_rel;         /* finite-difference step relative to the scale */
	double xtol;           /* convergence: relative step in the parameters */
	int threads;           /* own threads when map is NULL */
	fit_map_fn map;        /* NULL: the library's threads */
	void *map_ctx;
	void (*progress)(void *ctx, const fit_progress *pr); /* may be NULL */
	int (*cancelled)(void *ctx); /* may be NULL; nonzero stops the fit */
	/* may be NULL; nonzero: the model counts as failing at the free
	 * values x (SI), as when a run fails or a peak is not found: a
	 * constraint the caller knows, and how the tests plant a failure */
	int (*veto)(void *ctx, const double *x);
	void *ctx;
} fit_request;

/* Defaults: model of the czubak2016 preset, t_end = transient + 4 s,
 * peaks scanned over +-10 deg every 2 deg, curve every 5 deg, 30
 * iterations, fd_rel 0.05, xtol 1e-3, 2 threads, no data. */
void fit_request_init(fit_request *r);

enum { FIT_CONVERGED = 0, FIT_MAXITER, FIT_CANCELLED, FIT_FAILED };
/* "converged", "max-iterations", "cancelled", "failed". */
const char *fit_status_name(int status);

/* One Levenberg-Marquardt run of a multi-start fit. */
typedef struct fit_start {
	double x0[FIT_MAX_FREE];    /* SI: where it started */
	double x[FIT_MAX_FREE];     /* SI: where it ended (its best point) */
	double chi2;                /* the cost there; NaN: not even the start evaluated */
	int status;                 /* FIT_* */
	int iterations;
} fit_start;

typedef struct fit_result {
	int status;                 /* FIT_* */
	char error[FIT_MSG];        /* FIT_FAILED: why */
	int nfree;
	double x[FIT_MAX_FREE];     /* SI; fitted values (FIT_FAILED: the best
				     * point seen, the start when none was) */
	double x0[FIT_MAX_FREE];    /* the request's start */
	double se[FIT_MAX_FREE];    /* standard errors, SI; NaN: not determined */
	double corr[FIT_MAX_FREE * FIT_MAX_FREE]; /* row-major, NaN where undefined */
	double cov[FIT_MAX_FREE * FIT_MAX_FREE]; /* SI, row-major; NaN where undefined */
	int at_bound[FIT_MAX_FREE]; /* -1 lower, +1 upper, 0 inside */
	int sigma_given;            /* 1: se from (J^T W J)^-1; 0: times s2 */
	double chi2;                /* sum of squared weighted residuals (the data's) */
	double chi2_prior;          /* the priors' share of the cost (0 without) */
	double s2;                  /* chi2 / dof (the residual variance) */
	int dof;                    /* data - free parameters */
	double cond;                /* condition number of J (columns scaled) */
	int iterations;
	long evaluations;
	int rejected;               /* trial points that could not be evaluated */
	int nstarts, best_start;    /* the runs (starts[best_start] gave x) */
	fit_start starts[FIT_MAX_STARTS];
	double cpu_seconds;         /* of the threads that evaluated */
	double wall_seconds;
	/* per datum (npoints or npeaks): the model at the fit */
	size_t ndata;
	double *model;              /* v (m/s) or the peak's beta (rad) */
	double *model_u;            /* its uncertainty (same unit) */
	double *model_start;        /* at the start */
	/* the curves on the grid, per rotation: v at the fit and at the start */
	size_t ncurve;              /* grid points per rotation */
	int nrot, rotations[2];
	double *curve_beta;         /* rad, ncurve */
	double *curve_fit, *curve_fit_u, *curve_start; /* [rot * ncurve + k] */
	/* the 95 % band of the fitted curve from the parameters' covariance
	 * (delta method: v +- q sqrt(g^T cov g + u^2), g = dv/dx by forward
	 * differences, u = curve_fit_u, q the normal or, with the residual
	 * variance, Student's quantile); NaN without a covariance */
	double *band_lo, *band_hi;  /* [rot * ncurve + k], m/s */
	double band_quantile;       /* q */
	int nwarn;
	char warnings[FIT_MAX_WARNINGS][FIT_MSG];
} fit_result;

/* Run the fit (blocking; thread-safe, no global state but GSL's error
 * handler, which is switched off). The request must have passed
 * fit_check. Fills *res (free it with fit_result_free). Returns
 * res->status. */
int fit_run(const fit_request *req, fit_result *res);
void fit_result_free(fit_result *res);

/* A standard normal deviate from the state *seed (nonzero; advanced):
 * xorshift64* (Marsaglia 2003; Vigna 2016) and Box-Muller. The band's
 * check draws with it, the tests make their noise with it. */
double fit_normal(unsigned long long *seed);

/* The check of res's band (fit_band.c): nsamples parameter sets drawn
 * from the fit's covariance (N(res->x, cov), scaled to res's band
 * quantile, clamped to the bounds; fixed seed), their curves on res's
 * grid, and at each grid point the 2.5 and 97.5 percentiles into lo and
 * hi ([rot * ncurve + k], m/s; the caller's arrays). req is the request
 * res answers. 0, or -1: no curve or covariance, a failed run, out of
 * memory. Costs nsamples curves. */
int fit_band_sampled(const fit_request *req, const fit_result *res, int nsamples,
		     unsigned long long seed, double *lo, double *hi);

/* The 97.5 % quantile of a band: the normal's when every datum had its
 * sigma, Student's t with dof degrees of freedom when the covariance
 * comes from the residual variance; NaN when dof < 1. */
double fit_band_quantile(int sigma_given, int dof);

/* The delta method's half-width at one curve point (the one piece of it
 * that the fit's band and a study's bands share): q sqrt(g^T cov g + u^2)
 * with g_j = (vp[j] - v) / h[j], the forward difference of v over the
 * step h[j] of parameter j (vp[j]: v with x_j + h_j), cov p x p row-major
 * (SI), u the point's own error bar (m/s; NaN: none). */
double fit_delta_half(int p, const double *cov, double q, double v, const double *vp,
		      const double *h, double u);

/* The forward-difference step of parameter f at x (SI): fd_rel max(|x|,
 * 1e-3 of its range), at most a quarter of the range, backwards where x +
 * h passes the upper bound. The Jacobian's, the band's and a study's. */
double fit_step(const fit_free *f, double fd_rel, double x);

/* ---- bands on other curves (fit_source.c): a fit's parameters with
 * their uncertainties, for a study over other settings ---------------- */

typedef struct fit_band_source {
	int nfree;
	fit_free free[FIT_MAX_FREE];          /* name, bounds (SI) */
	double x[FIT_MAX_FREE];               /* SI: the fitted values */
	double cov[FIT_MAX_FREE * FIT_MAX_FREE]; /* SI, row-major */
	double quantile;                      /* q of the fit's band */
	double fd_rel;                        /* the step (fit_step) */
} fit_band_source;

/* The source from `convsim fit`'s JSON result (fit_result_json's text,
 * whitespace anywhere): "parameters" (name, value, standard_error, min,
 * max, in user units), "correlation", "dof", "standard_errors_from" and
 * "status"; the covariance is corr_ab se_a se_b in SI and the step the
 * fit's default. SIM_OK, or SIM_EPARAM with what is wrong in msg. */
int fit_band_source_parse(const char *json, fit_band_source *src, char *msg, size_t len);

/* Prepare a study's model for bands from src: skip[j] = 1 where the
 * study varies parameter j (its name among the nvaried names of varied),
 * the others' fitted values set on p, s, m, and the mirror reduction off
 * (s->mirror = 0) where a parameter's step would break the machine's
 * symmetry that the images' bands rely on. SIM_OK or sim_set's code with
 * msg. */
int fit_band_source_prepare(const fit_band_source *src, const char *const *varied, size_t nvaried,
			    int *skip, sim_params *p, sim_scene *s, sim_method *m, char *msg,
			    size_t len);

/* The 95 % band of a study's point (thread-safe): at its measurement `at`
 * on the model p, s, m (the source's values applied, the point's
 * settings set), v is measured again with x_j + h_j for each parameter j
 * of the source not skipped (skip[j]: the study varies it; it drops out
 * of the covariance), and [lower, upper] = v -+ fit_delta_half. t_end as
 * sim_measure's. SIM_OK, or the failing run's code with msg. */
int fit_band_point(const fit_band_source *src, const int *skip, const sim_params *p,
		   const sim_scene *s, const sim_method *m, double t_end,
		   const sim_measurement *at, double *lower, double *upper, char *msg,
		   size_t len);

/* ---- priors (fit_prior.c) ----------------------------------------------- */

/* A Gaussian prior on free parameter `name` of req (already free), in its
 * user unit: normal with mean and sd (factor NaN), or log-normal with
 * median mean and factor (sd NaN): ln x ~ N(ln mean, ln factor), so that
 * mean / factor .. mean x factor is one standard deviation. The fit then
 * minimises chi2 plus the priors' squared residuals (a maximum a
 * posteriori estimate), and the covariance is the posterior's. The
 * problem into msg; a value outside its range ("mean", "sd" or "factor",
 * into *member when not NULL) with *range. SIM_OK or SIM_EPARAM. */
int fit_set_prior(fit_request *req, const char *name, double mean, double sd, double factor,
		  char *msg, size_t mlen, const char **member, fit_range *range);
/* Whether pr is a prior; its residual at x (SI) and the residual's slope
 * d r / d x there (0 without one). */
int fit_has_prior(const fit_prior *pr);
double fit_prior_residual(const fit_prior *pr, double x);
double fit_prior_slope(const fit_prior *pr, double x);
/* The priors' share of the cost at x (SI, one value a free parameter). */
double fit_prior_cost(const fit_request *req, const double *x);

/* ---- checks and parsers (user units in messages) ---------------------- */

/* The setting for a free-parameter name: a real setting of group "params"
 * that the steady state depends on (not beta, which each point sets, nor
 * the ramp limits beta_rate, beta_accel, drive_accel). NULL with a
 * message (and *err SIM_EUNKNOWN or SIM_EPARAM) otherwise. */
const sim_setting *fit_free_param(const char *name, int *err, char *msg, size_t len);

/* Set free parameter i of req by name with the bounds of its setting's
 * range (or lo/hi in user units when finite) and the model's current
 * value as its start; the problem into field ("name", or "min" or "max"
 * for a bound outside the setting's range or not below max, with *range)
 * and msg. SIM_OK or an error. */
int fit_add_free(fit_request *req, const char *name, double lo_user, double hi_user,
		 char *field, size_t flen, char *msg, size_t mlen, fit_range *range);

/* Parse CSV text (header beta,rotation,v[,sigma], any column order, beta
 * in deg) into a malloc'd array (*out, *n; caller frees). A number is a
 * plain decimal one (decimal.h; spaces around a cell allowed, not 0x10,
 * inf or nan). Returns SIM_OK, or SIM_EPARAM with a message naming the
 * line and column; for more than FIT_MAX_POINTS data rows, with *range
 * (when not NULL) the counts a CSV may hold, 1 to FIT_MAX_POINTS; for a
 * rotation neither cw nor ccw, with range->choices. */
int fit_parse_csv(const char *text, fit_point **out, size_t *n, char *msg, size_t len,
		  fit_range *range);

/* Whole-request checks: data present (points or peaks, not both), beta
 * finite in [0, 180] deg, rotation known, v and sigma finite (sigma in
 * (0, 100] m/s for points, (0, 180] deg for peaks, given for every datum
 * or none), no duplicate (beta, rotation), at least as many data as free
 * parameters, starts within bounds, 1 to FIT_MAX_STARTS runs, 1 to
 * FIT_MAX_ITER iterations, t_end after the transient, the model valid. On
 * error returns SIM_EPARAM with the field ("points[3].beta", "free",
 * "t_end", ...) and the message. */
int fit_check(const fit_request *req, char *field, size_t flen, char *msg, size_t mlen);
/* The same, with the range of a value refused for lying outside one in
 * *range (may be NULL). */
int fit_check_range(const fit_request *req, char *field, size_t flen, char *msg, size_t mlen,
		    fit_range *range);

/* ---- results as text (user units: beta in deg, parameters in their
 * setting's unit; numbers round-trip, core/table.h's printer) ---------- */

/* The CSV columns of a result: one row per free parameter (kind
 * "parameter": model = fitted value, uncertainty = standard error, start),
 * per point or peak (measured, sigma, model, uncertainty, residual = model
 * - measured, start = the model at the start) and per curve point (model,
 * uncertainty and start = v at the fit and at the start, band_lower and
 * band_upper = the 95 % band of the fitted curve). */
#define FIT_CSV_HEADER                                                                  \
	"kind,name,beta,rotation,measured,sigma,model,uncertainty,residual,start,band_lower," \
	"band_upper"

/* The result as JSON (an object) or CSV: malloc'd text, NULL when out of
 * memory. req is the request the result answers. */
char *fit_result_json(const fit_request *req, const fit_result *res);
char *fit_result_csv(const fit_request *req, const fit_result *res);

#endif
