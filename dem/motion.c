/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * motion.c - the deck's prescribed motion (motion.h): the machine run
 * one-way, its centre deck point fitted by a few harmonics of the mean
 * rotor speed (least squares, GSL), and a DEM bed driven by
 * that motion over whole periods.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <gsl/gsl_errno.h>
#include <gsl/gsl_multifit.h>

#include "motion.h"

/* The basis at t: 1, cos(h w t), sin(h w t), h = 1..H. */
static void motion_basis(double omega, int harmonics, double t, double *phi)
{
	phi[0] = 1;
	for (int h = 1; h <= harmonics; h++) {
		phi[2 * h - 1] = cos(h * omega * t);
		phi[2 * h] = sin(h * omega * t);
	}
}

/* The harmonic series of the deck's motion (dx, dy at t, n samples, the
 * rotor's mean speed omega) by least squares for x and y on the same
 * basis (GSL's SVD solver) into out's coefficients. 1 when out of memory
 * or singular. */
static int fit_series(const double *t, const double *dx, const double *dy, long n, double omega,
		      int harmonics, dem_motion *out)
{
	int nb = 2 * harmonics + 1;
	double phi[2 * DEM_MAX_HARMONICS + 1], chisq;
	memset(out, 0, sizeof *out);
	gsl_matrix *X = gsl_matrix_alloc((size_t)n, (size_t)nb);
	gsl_vector *obs = gsl_vector_alloc((size_t)n), *coef = gsl_vector_alloc((size_t)nb);
	gsl_matrix *cov = gsl_matrix_alloc((size_t)nb, (size_t)nb);
	gsl_multifit_linear_workspace *ws = gsl_multifit_linear_alloc((size_t)n, (size_t)nb);
	int bad = !X || !obs || !coef || !cov || !ws;
	for (long i = 0; i < n && !bad; i++) {
		motion_basis(omega, harmonics, t[i], phi);
		for (int r = 0; r < nb; r++)
			gsl_matrix_set(X, (size_t)i, (size_t)r, phi[r]);
	}
	for (int axis = 0; axis < 2 && !bad; axis++) {
		for (long i = 0; i < n; i++)
			gsl_vector_set(obs, (size_t)i, axis ? dy[i] : dx[i]);
		bad = gsl_multifit_linear(X, obs, coef, cov, &chisq, ws) != GSL_SUCCESS;
		for (int r = 0; r < nb && !bad; r++)
			(axis ? out->b : out->a)[r] = gsl_vector_get(coef, (size_t)r);
	}
	gsl_multifit_linear_free(ws);
	gsl_matrix_free(cov);
	gsl_vector_free(coef);
	gsl_vector_free(obs);
	gsl_matrix_free(X);
	return bad;
}

int dem_motion_fit(const sim_params *p, const sim_scene *sc, const sim_method *m, double t0,
		   double t1, int harmonics, dem_motion *out, char *msg, size_t msglen)
{
	if (harmonics < 1 || harmonics > DEM_MAX_HARMONICS || !(t1 > t0) || !(t0 >= 0)) {
		snprintf(msg, msglen, "deck motion: harmonics must be in [1, %d] and 0 <= t0 < t1",
			 DEM_MAX_HARMONICS);
		return SIM_EPARAM;
	}
	sim_scene one_way = *sc;
	one_way.feed_coupling = 0;
	int err = SIM_OK;
	sim *s = sim_new(p, &one_way, m, &err, msg, msglen);
	if (!s)
		return err;
	gsl_set_error_handler_off(); /* GSL's errors come back as codes */
	/* samples: 64 a period of the synchronous speed, at least */
	long n = (long)ceil((t1 - t0) * p->omega_ss / (2 * M_PI) * 64) + 1;
	double *t = malloc((size_t)n * sizeof *t), *dx = malloc((size_t)n * sizeof *dx),
	       *dy = malloc((size_t)n * sizeof *dy);
	double omega = 0;
	if (!t || !dx || !dy) {
		snprintf(msg, msglen, "deck motion: out of memory");
		err = SIM_ENOMEM;
		goto fail;
	}
	for (long i = 0; i < n; i++) {
		t[i] = t0 + (t1 - t0) * (double)i / (double)(n - 1);
		if ((err = sim_advance(s, t[i])) != SIM_OK) {
			snprintf(msg, msglen, "deck motion: %s", sim_last_error(s));
			goto fail;
		}
		sim_status st;
		sim_get_status(s, &st);
		dx[i] = st.deck[0];
		dy[i] = st.deck[1];
		omega += fabs(st.rotor_speed) / (double)n;
	}
	int nb = 2 * harmonics + 1;
	double phi[2 * DEM_MAX_HARMONICS + 1];
	int bad = fit_series(t, dx, dy, n, omega, harmonics, out);
	if (bad) {
		snprintf(msg, msglen, "deck motion: the fit failed (out of memory or singular)");
		err = SIM_ENOMEM;
		goto fail;
	}
	out->omega = omega;
	out->harmonics = harmonics;
	double res = 0, amp = 0;
	for (long i = 0; i < n; i++) {
		motion_basis(omega, harmonics, t[i], phi);
		double fx = 0, fy = 0;
		for (int r = 0; r < nb; r++) {
			fx += out->a[r] * phi[r];
			fy += out->b[r] * phi[r];
		}
		res += (dx[i] - fx) * (dx[i] - fx) + (dy[i] - fy) * (dy[i] - fy);
		amp += (dx[i] - out->a[0]) * (dx[i] - out->a[0]) + (dy[i] - out->b[0]) * (dy[i] - out->b[0]);
	}
	out->residual = sqrt(res / (double)n);
	out->amplitude = sqrt(amp / (double)n);
fail:
	free(t);
	free(dx);
	free(dy);
	sim_free(s);
	return err;
}

int dem_motion_sample(const sim_params *p, const sim_scene *sc, const sim_method *m, int steps,
		      double t_end, double **acc, long *n, double *interval, char *msg, size_t msglen)
{
	sim_scene one_way = *sc;
	one_way.feed_model = SIM_FEED_EXTERNAL;
	one_way.feed_coupling = 0;
	int err = SIM_OK;
	*acc = NULL;
	sim *s = sim_new(p, &one_way, m, &err, msg, msglen);
	if (!s)
		return err;
	sim_status st;
	sim_get_status(s, &st);
	double dt = st.dt, H = steps * dt, v0[2] = {st.deck_vel[0], st.deck_vel[1]};
	long k, count = (long)floor(t_end / H + 1e-9);
	double *a = malloc((size_t)(count > 0 ? count : 1) * 2 * sizeof *a);
	if (!a) {
		snprintf(msg, msglen, "deck motion: out of memory");
		sim_free(s);
		return SIM_ENOMEM;
	}
	for (k = 0; k < count; k++) {
		/* the time as the coupled run computes it (couple.c) */
		if ((err = sim_advance(s, (double)((k + 1) * steps) * dt)) != SIM_OK) {
			snprintf(msg, msglen, "deck motion: %s", sim_last_error(s));
			free(a);
			sim_free(s);
			return err;
		}
		sim_get_status(s, &st);
		a[2 * k] = (st.deck_vel[0] - v0[0]) / H;
		a[2 * k + 1] = (st.deck_vel[1] - v0[1]) / H;
		v0[0] = st.deck_vel[0];
		v0[1] = st.deck_vel[1];
	}
	sim_free(s);
	*acc = a;
	*n = count;
	*interval = H;
	return SIM_OK;
}

void dem_motion_velocity(const dem_motion *mo, double t, double vel[2])
{
	vel[0] = vel[1] = 0;
	for (int h = 1; h <= mo->harmonics; h++) {
		double w = h * mo->omega, c = cos(w * t), s = sin(w * t);
		vel[0] += w * (-mo->a[2 * h - 1] * s + mo->a[2 * h] * c);
		vel[1] += w * (-mo->b[2 * h - 1] * s + mo->b[2 * h] * c);
	}
}

/* The fit's acceleration along one axis (c: a or b) as a LIGGGHTS formula
 * of v_t: -sum (h w)^2 (c[2h-1] cos(h w t) + c[2h] sin(h w t)). */
static void motion_formula(const dem_motion *mo, const double *c, char *f, size_t len)
{
	size_t used = (size_t)snprintf(f, len, "0");
	for (int h = 1; h <= mo->harmonics && used < len; h++) {
		double w = h * mo->omega;
		used += (size_t)snprintf(f + used, len - used, "-(%.17g*cos(%.17g*v_t)+%.17g*sin(%.17g*v_t))",
					 w * w * c[2 * h - 1], w, w * w * c[2 * h], w);
	}
}

int dem_run_prescribed(dem_bed *b, const dem_motion *mo, double t_end, double transient,
		       int intervals, dem_prescribed *out, char *msg, size_t msglen)
{
	if (intervals < 0 || !(mo->omega > 0) || !(t_end > transient) || !(transient >= 0)) {
		snprintf(msg, msglen, "prescribed run: intervals >= 0 and 0 <= transient < t_end");
		return -1;
	}
	/* intervals 0: the fit's acceleration at every DEM step, a period a run */
	char fx[1400], fy[1400];
	if (intervals == 0) {
		motion_formula(mo, mo->a, fx, sizeof fx);
		motion_formula(mo, mo->b, fy, sizeof fy);
	}
	/* a hertz bed's overlaps: sampled after each of 40 runs a period */
	double ov_pp, ov_pw;
	dem_bed_overlap(b, &ov_pp, &ov_pw);
	int sampled = intervals == 0 && !isnan(ov_pp);
	int per = intervals ? intervals : sampled ? 40 : 1; /* runs a period */
	double period = 2 * M_PI / mo->omega, dt = period / per;
	long first = (long)ceil(transient / period - 1e-9), last = (long)floor(t_end / period + 1e-9);
	if (last <= first) {
		snprintf(msg, msglen, "prescribed run: no whole period between the transient and the end");
		return -1;
	}
	long mid = first + (last - first) / 2;
	double cpu0 = dem_cpu_now(), x_first = 0, x_mid = 0, x_last = 0;
	dem_bed_state st;
	dem_bed_get(b, &st);
	out->mass = st.mass;
	out->bed_height = 2 * st.z_mean;
	out->overlap_pp = out->overlap_pw = NAN;
	if (sampled)
		out->overlap_pp = out->overlap_pw = 0;
	for (long k = 0; k <= last * per; k++) {
		long n = k / per;
		if (k % per == 0 && (n == first || n == mid || n == last)) {
			dem_bed_get(b, &st);
			*(n == first ? &x_first : n == mid ? &x_mid : &x_last) = st.x_mean;
		}
		if (sampled && k > 0) {
			dem_bed_overlap(b, &ov_pp, &ov_pw);
			out->overlap_pp = fmax(out->overlap_pp, ov_pp);
			out->overlap_pw = fmax(out->overlap_pw, ov_pw);
		}
		if (k == last * per)
			break;
		double v0[2], v1[2];
		dem_motion_velocity(mo, k * dt, v0);
		dem_motion_velocity(mo, (k + 1) * dt, v1);
		if (intervals ? dem_bed_advance(b, (v1[0] - v0[0]) / dt, (v1[1] - v0[1]) / dt, dt, msg, msglen)
			      : dem_bed_advance_drive(b, fx, fy, dt, msg, msglen))
			return -1;
	}
	out->periods = (double)(last - first);
	out->transport_velocity = (x_last - x_first) / (out->periods * period);
	out->v_first_half = (x_mid - x_first) / ((double)(mid - first) * period);
	out->v_second_half = (x_last - x_mid) / ((double)(last - mid) * period);
	out->cpu_seconds = dem_cpu_now() - cpu0;
	out->dt = dem_bed_dt(b);
	return 0;
}
