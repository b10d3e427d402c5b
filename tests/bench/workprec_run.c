/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * workprec_run.c - one run of the work-precision benchmark: the preset with
 * a scene's settings and one integrator setting, timed in CPU seconds,
 * the trough's (x, y) sampled every SAMPLE_DT over the first NSAMP samples,
 * and its row of the TSV the report reads back.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim.h"
#include "units.h"
#include "workprec.h"

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void apply(sim_params *p, sim_scene *sc, sim_method *m, const char *const *sets)
{
	char msg[200];
	for (int i = 0; sets && sets[i]; i += 2)
		if (sim_set_user_str(p, sc, m, sets[i], sets[i + 1], msg, sizeof msg) != SIM_OK) {
			fprintf(stderr, "workprec: %s=%s: %s\n", sets[i], sets[i + 1], msg);
			exit(2);
		}
}

/* Runs the preset with the scene's settings `sets` (NULL-terminated
 * name/value pairs) and the method of rs. */
void wp_run(const char *const *sets, const run_spec *rs, run_out *o)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	/* the paper's scene, the same for every method: the run-up from rest,
	 * the full model unless a scene drops alpha, v over [2, 6] s */
	sc.start = SIM_START_REST;
	sc.trough_rotation = 1;
	sc.transient = 2.0;
	apply(&p, &sc, &m, sets);
	snprintf(m.name, sizeof m.name, "%s", rs->method);
	m.dt = rs->dt;
	m.substeps = rs->substeps > 0 ? rs->substeps : 1;
	if (rs->rtol > 0) {
		m.rtol = rs->rtol;
		m.atol = 1e-3 * rs->rtol;
	}
	memset(o, 0, sizeof *o);
	o->v = NAN;
	int err;
	sim *s = sim_new(&p, &sc, &m, &err, o->msg, sizeof o->msg);
	if (!s) {
		o->err = err;
		return;
	}
	double c0 = cpu_now();
	sim_status st;
	for (int i = 0; i < NSAMP && (i + 1) * SAMPLE_DT <= rs->horizon + 1e-12; i++) {
		o->err = sim_advance(s, (i + 1) * SAMPLE_DT);
		if (o->err)
			break;
		sim_get_status(s, &st);
		o->x[i] = st.q[0];
		o->y[i] = st.q[1];
		o->nsamp = i + 1;
	}
	if (!o->err)
		o->err = sim_advance(s, rs->horizon);
	o->cpu = cpu_now() - c0;
	if (o->err)
		snprintf(o->msg, sizeof o->msg, "%s", sim_last_error(s));
	sim_get_status(s, &st);
	o->t = st.t;
	o->v = st.transport_velocity;
	o->e_res = st.e_residual;
	o->e_in = st.e_input;
	o->steps = (unsigned long long)st.steps;
	sim_free(s);
}

/* RMS distance of two trough trajectories over their common samples. */
double wp_traj_rms(const run_out *a, const run_out *b)
{
	int n = a->nsamp < b->nsamp ? a->nsamp : b->nsamp;
	double s = 0.0;
	for (int i = 0; i < n; i++) {
		double dx = a->x[i] - b->x[i], dy = a->y[i] - b->y[i];
		s += dx * dx + dy * dy;
	}
	return n > 0 ? sqrt(s / n) : NAN;
}

double wp_traj_amplitude(const run_out *a)
{
	double s = 0.0;
	for (int i = 0; i < a->nsamp; i++)
		s += a->x[i] * a->x[i] + a->y[i] * a->y[i];
	return a->nsamp > 0 ? sqrt(s / a->nsamp) : NAN;
}

static void setting_label(const run_spec *rs, char *buf, size_t n)
{
	if (strcmp(rs->method, "dopri5") == 0)
		snprintf(buf, n, "rtol=%g", rs->rtol);
	else if (strcmp(rs->method, "dem") == 0)
		snprintf(buf, n, "dt=%g,substeps=%d", rs->dt, rs->substeps);
	else
		snprintf(buf, n, "dt=%g", rs->dt);
}

/* TSV row: kind scene variant method setting horizon cpu_per_s rtf
 * traj_rms traj_rel v v_rel e_res e_res_rel steps err */
void wp_row(const char *kind, const char *scene, const char *variant, const run_spec *rs,
		const run_out *o, const run_out *tref, double vref)
{
	char lab[64];
	setting_label(rs, lab, sizeof lab);
	double cps = o->t > 0 ? o->cpu / o->t : NAN;
	double tr = tref && o->nsamp > 0 ? wp_traj_rms(o, tref) : NAN;
	double amp = tref ? wp_traj_amplitude(tref) : NAN;
	double vrel = isfinite(vref) && isfinite(o->v) ? fabs(o->v - vref) / fabs(vref) : NAN;
	printf("%s\t%s\t%s\t%s\t%s\t%g\t%.6g\t%.6g\t%.6g\t%.6g\t%.9g\t%.6g\t%.6g\t%.6g\t%llu\t%s\n",
	       kind, scene, variant, rs->method, lab, rs->horizon, cps, cps > 0 ? 1.0 / cps : NAN,
	       tr, tr / amp, o->v, vrel, o->e_res, o->e_in > 0 ? fabs(o->e_res) / o->e_in : NAN,
	       o->steps, o->err ? o->msg : "ok");
	fflush(stdout);
}
