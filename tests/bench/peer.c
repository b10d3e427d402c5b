/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peer.c - what the benchmark's peers share (peer.h): their names and
 * set-ups, a sim stepped by a peer (sim_alloc, the peer's descriptor in
 * place of the core's, then sim_start), the CPU budget, the tolerance
 * vector and the forward-difference Jacobian.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "peer.h"

const char *const peer_names[] = {"gsl-rk8pd",   "gsl-rkf45",  "gsl-msadams", "gsl-msbdf",
				  "cvode-adams", "cvode-bdf",  "arkode-erk",  NULL};

static const struct {
	const char *name;
	const ode_method *ode;
	const char *doc;
} peers[] = {
	{"gsl-rk8pd", &peer_gsl,
	 "GSL odeiv2 rk8pd: Prince-Dormand 8(9), explicit, standard control (evolve_apply)"},
	{"gsl-rkf45", &peer_gsl, "GSL odeiv2 rkf45: Runge-Kutta-Fehlberg 4(5), explicit"},
	{"gsl-msadams", &peer_gsl,
	 "GSL odeiv2 msadams: variable-order Adams 1-12, functional iteration"},
	{"gsl-msbdf", &peer_gsl,
	 "GSL odeiv2 msbdf: variable-order BDF 1-5, Newton, forward-difference Jacobian"},
	{"cvode-adams", &peer_sundials,
	 "SUNDIALS CVODE Adams-Moulton 1-12, fixed-point iteration"},
	{"cvode-bdf", &peer_sundials,
	 "SUNDIALS CVODE BDF 1-5, Newton with the dense direct solver, CVODE's "
	 "difference-quotient Jacobian"},
	{"arkode-erk", &peer_sundials,
	 "SUNDIALS ARKODE ERKStep, its default 4th-order explicit table (Zonneveld 5-3-4)"},
};

static const ode_method *peer_find(const char *name, const char **doc)
{
	for (size_t i = 0; i < sizeof peers / sizeof peers[0]; i++)
		if (strcmp(peers[i].name, name) == 0) {
			if (doc)
				*doc = peers[i].doc;
			return peers[i].ode;
		}
	return NULL;
}

const char *peer_doc(const char *name)
{
	const char *doc = NULL;
	peer_find(name, &doc);
	return doc;
}

sim *peer_sim_new(const char *name, double rtol, const sim_params *p, const sim_scene *sc,
		  char *msg, size_t msglen)
{
	const ode_method *ode = peer_find(name, NULL);
	if (!ode) {
		snprintf(msg, msglen, "unknown peer '%s'", name);
		return NULL;
	}
	/* a core method to pass validation; its workspace is replaced */
	sim_method m = {.name = "rk4", .dt = 0.0, .rtol = rtol, .atol = 1e-3 * rtol,
			.substeps = 1};
	int err;
	sim *s = sim_alloc(p, sc, &m, &err, msg, msglen);
	if (!s)
		return NULL;
	s->ode->free(s->ws);
	snprintf(s->cfg.name, sizeof s->cfg.name, "%s", name);
	s->ode = ode;
	s->ws = ode->alloc(&s->md, &s->cfg);
	if (!s->ws) {
		snprintf(msg, msglen, "%s: workspace allocation failed", name);
		s->ode = &ode_rk4; /* sim_free frees nothing of it: ws is NULL */
		sim_free(s);
		return NULL;
	}
	if (sim_start(s, msg, msglen) != SIM_OK) {
		size_t used = strlen(msg);
		snprintf(msg + used, msglen - used, " (%s)", peer_of(s)->msg);
		sim_free(s);
		return NULL;
	}
	return s;
}

const peer_ws *peer_of(const sim *s)
{
	return s->ws;
}

static double budget_end; /* process CPU time; 0: none */

double peer_cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

void peer_set_budget(double cpu_seconds)
{
	budget_end = cpu_seconds > 0 ? peer_cpu_now() + cpu_seconds : 0.0;
}

int peer_budget_check(peer_ws *w, double t)
{
	/* the clock is read every 64 steps: a step costs microseconds */
	if (budget_end <= 0 || (w->steps & 63) != 0 || peer_cpu_now() < budget_end)
		return SIM_OK;
	snprintf(w->msg, sizeof w->msg, "CPU budget exhausted at t = %.6g s after %llu steps", t,
		 (unsigned long long)w->steps);
	return SIM_ESTEP;
}

void peer_atol_vector(const peer_ws *w, double *atol)
{
	/* the accumulators (energies, J) are outside the error control */
	for (int i = 0; i < w->n; i++)
		atol[i] = i < w->nerr ? w->atol : 1e30;
}

void peer_fd_jacobian(peer_ws *w, double t, const double *y, const double *f0, double *J,
		      double *work)
{
	const int n = w->n;
	double *yp = work, *fp = work + n;
	memcpy(yp, y, sizeof(double) * (size_t)n);
	for (int j = 0; j < n; j++) {
		/* the usual increment: sqrt(eps) relative, the atol scale absolute */
		double d = 1.4901161193847656e-08 * fmax(fabs(y[j]), j < w->nerr ? 1e-3 : 1.0);
		yp[j] = y[j] + d;
		d = yp[j] - y[j];
		dyn_rhs(w->sys, t, yp, fp);
		for (int i = 0; i < n; i++)
			J[i * n + j] = (fp[i] - f0[i]) / d;
		yp[j] = y[j];
	}
}

void peer_no_interpolation(void *ws, double t, double *out)
{
	(void)ws;
	(void)out;
	fprintf(stderr, "peer: interpolation at t = %.9g s requested, but steps land on every "
			"target\n", t);
	abort();
}

void peer_reset(void *ws)
{
	peer_ws *w = ws;
	w->need_init = 1;
}
