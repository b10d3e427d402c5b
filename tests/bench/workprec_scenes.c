/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * workprec_scenes.c - the benchmark's scenes: for each, the references
 * (trajectory: the finest runs of two different methods; transport
 * velocity: dem at its finest step, confirmed by Richardson extrapolation
 * of the three finest rk4 runs) and the ladders of integrator settings
 * measured against them, one TSV row a run (workprec_run.c).
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "workprec.h"

static const char *const S_NOFEED[] = {"feed", "false", NULL};
static const char *const S_FULL[] = {NULL};
static const char *const S_REDUCED[] = {"trough_rotation", "false", NULL};

static int quick; /* shorter horizons and ladders (wp_scene) */

static run_out *new_out(void)
{
	run_out *o = malloc(sizeof *o);
	if (!o) {
		fprintf(stderr, "workprec: out of memory\n");
		exit(1);
	}
	return o;
}

/* A ladder of runs against the given references. */
static void ladder(const char *scene, const char *const *sets, const run_spec *specs, int n,
		   const run_out *tref, double vref)
{
	run_out *o = new_out();
	for (int i = 0; i < n; i++) {
		wp_run(sets, &specs[i], o);
		wp_row("run", scene, "-", &specs[i], o, tref, vref);
	}
	free(o);
}

static void scene_nofeed(void)
{
	double H = quick ? 1.0 : 2.0;
	/* references: dopri5 at rtol 1e-12 and rk4 at 2.5e-6 s */
	run_spec ra = {"dopri5", 1e-4, 1, 1e-12, H}, rb = {"rk4", 2.5e-6, 1, 0, H};
	run_out *a = new_out(), *b = new_out();
	wp_run(S_NOFEED, &ra, a);
	wp_run(S_NOFEED, &rb, b);
	wp_row("ref", "nofeed", "trajectory", &ra, a, a, NAN);
	wp_row("refcheck", "nofeed", "trajectory", &rb, b, a, NAN);
	run_spec L[] = {
		{"rk4", 1.8e-3, 1, 0, H},    {"rk4", 1e-3, 1, 0, H},     {"rk4", 5e-4, 1, 0, H},
		{"rk4", 2.5e-4, 1, 0, H},    {"rk4", 1e-4, 1, 0, H},     {"rk4", 5e-5, 1, 0, H},
		{"rk4", 2.5e-5, 1, 0, H},    {"euler", 2e-4, 1, 0, H},   {"euler", 1e-4, 1, 0, H},
		{"euler", 5e-5, 1, 0, H},    {"euler", 2.5e-5, 1, 0, H}, {"euler", 1e-5, 1, 0, H},
		{"euler", 5e-6, 1, 0, H},    {"euler", 2.5e-6, 1, 0, H}, {"dem", 1.8e-3, 1, 0, H},
		{"dem", 1e-3, 1, 0, H},      {"dem", 5e-4, 1, 0, H},     {"dem", 2.5e-4, 1, 0, H},
		{"dem", 1e-4, 1, 0, H},      {"dopri5", 1e-4, 1, 1e-3, H}, {"dopri5", 1e-4, 1, 1e-4, H},
		{"dopri5", 1e-4, 1, 1e-5, H}, {"dopri5", 1e-4, 1, 1e-6, H}, {"dopri5", 1e-4, 1, 1e-7, H},
		{"dopri5", 1e-4, 1, 1e-8, H}, {"dopri5", 1e-4, 1, 1e-10, H},
	};
	int n = (int)(sizeof L / sizeof L[0]);
	ladder("nofeed", S_NOFEED, L, n, a, NAN);
	free(a);
	free(b);
}

/* Full and reduced scenes: the same ladders. */
static void scene_feed(const char *scene, const char *const *sets)
{
	double H = quick ? 3.0 : 6.0;
	/* dopri5 takes millions of floor steps (1e-7 s) per simulated second
	 * in the feed's sliding modes: capped to the trajectory window */
	double Hdp = quick ? 0.1 : 0.8;
	/* trajectory and velocity reference A: dem at h = 1e-6 s */
	run_spec ra = {"dem", 1e-5, 10, 0, H};
	run_out *a = new_out();
	wp_run(sets, &ra, a);
	/* rk4 ladder; its three finest runs give the Richardson check */
	run_spec rl[] = {{"rk4", 2e-5, 1, 0, H},   {"rk4", 1e-5, 1, 0, H},
			 {"rk4", 5e-6, 1, 0, H},   {"rk4", 2.5e-6, 1, 0, H},
			 {"rk4", 1.25e-6, 1, 0, H}, {"rk4", 6.25e-7, 1, 0, H},
			 {"rk4", 3.125e-7, 1, 0, H}};
	int nr = (int)(sizeof rl / sizeof rl[0]);
	if (quick)
		nr = 4;
	run_out *r = calloc((size_t)nr, sizeof *r);
	if (!r)
		exit(1);
	for (int i = 0; i < nr; i++)
		wp_run(sets, &rl[i], &r[i]);
	double v1 = r[nr - 3].v, v2 = r[nr - 2].v, v3 = r[nr - 1].v;
	double ratio = (v1 - v2) / (v2 - v3);
	double order = log(ratio) / log(2.0);
	double vrich = v3 - (v2 - v3) / (ratio - 1.0);
	double vref = a->v;
	/* the same extrapolation sample by sample for the trajectory, with
	 * the order observed on the trajectories' RMS differences */
	run_out *rt = new_out();
	*rt = r[nr - 1];
	double tp = log(wp_traj_rms(&r[nr - 3], &r[nr - 2]) / wp_traj_rms(&r[nr - 2], &r[nr - 1])) /
		    log(2.0);
	double fac = 1.0 / (pow(2.0, tp) - 1.0);
	for (int i = 0; i < rt->nsamp; i++) {
		rt->x[i] += (r[nr - 1].x[i] - r[nr - 2].x[i]) * fac;
		rt->y[i] += (r[nr - 1].y[i] - r[nr - 2].y[i]) * fac;
	}
	wp_row("ref", scene, "dem_finest", &ra, a, a, vref);
	printf("richardson\t%s\trk4\t%.9g\t%.4g\t%.9g\t%.6g\t%.6g\t%.4g\n", scene, v3, order,
	       vrich, fabs(vrich - vref) / vref, wp_traj_rms(rt, a) / wp_traj_amplitude(a), tp);
	free(rt);
	for (int i = 0; i < nr; i++)
		wp_row("run", scene, "-", &rl[i], &r[i], a, vref);
	free(r);
	run_spec L[] = {
		{"euler", 2e-5, 1, 0, H},        {"euler", 1e-5, 1, 0, H},
		{"euler", 5e-6, 1, 0, H},        {"euler", 2.5e-6, 1, 0, H},
		{"euler", 1.25e-6, 1, 0, H},     {"dem", 1.8e-3, 1, 0, H},
		{"dem", 1e-3, 1, 0, H},          {"dem", 5e-4, 1, 0, H},
		{"dem", 2.5e-4, 1, 0, H},        {"dem", 1e-4, 1, 0, H},
		{"dem", 5e-5, 1, 0, H},          {"dem", 2e-5, 1, 0, H},
		{"dem", 1.8e-3, 2, 0, H},        {"dem", 1.8e-3, 4, 0, H},
		{"dem", 1e-3, 2, 0, H},          {"dem", 1e-3, 4, 0, H},
		{"dem", 5e-4, 4, 0, H},          {"dem", 1e-4, 4, 0, H},
		{"dem", 5e-4, 5, 0, H},          {"dem", 1e-3, 10, 0, H},
		{"dem", 5e-4, 20, 0, H},         {"dem", 1.25e-3, 5, 0, H}, /* the default */
		{"dopri5", 1e-4, 1, 1e-3, Hdp},  {"dopri5", 1e-4, 1, 1e-4, Hdp},
		{"dopri5", 1e-4, 1, 1e-5, Hdp},
	};
	int n = (int)(sizeof L / sizeof L[0]);
	if (quick)
		n -= 1;
	ladder(scene, sets, L, n, a, vref);
	free(a);
}

/* Each reduction against the full model at equal integrator settings. */
static void scene_reductions(void)
{
	double H = quick ? 3.0 : 6.0;
	static const char *const v_full[] = {NULL};
	static const char *const v_sym[] = {"trough_rotation", "false", NULL};
	static const char *const v_ideal[] = {"drive", "ideal", NULL};
	static const char *const v_l4[] = {"layers", "4", NULL};
	static const char *const v_l4m[] = {"layers", "4", "m_n", "1", NULL};
	static const char *const v_oneway[] = {"feed_coupling", "false", NULL};
	static const char *const v_sym_ideal[] = {"trough_rotation", "false", "drive", "ideal",
						  NULL};
	static const char *const v_sym_l4[] = {"trough_rotation", "false", "layers", "4", NULL};
	static const char *const v_sym_ideal_l4[] = {"trough_rotation", "false", "drive", "ideal",
						     "layers", "4", NULL};
	struct {
		const char *name;
		const char *const *sets;
		int traj; /* trajectory comparable with the full model's */
	} V[] = {
		{"full", v_full, 1},
		{"symmetric", v_sym, 1},
		{"ideal_drive", v_ideal, 0},
		{"layers_4", v_l4, 1},
		{"layers_4_same_mass", v_l4m, 1},
		{"one_way", v_oneway, 1},
		{"symmetric+ideal", v_sym_ideal, 0},
		{"symmetric+layers_4", v_sym_l4, 1},
		{"symmetric+ideal+layers_4", v_sym_ideal_l4, 0},
	};
	int nv = (int)(sizeof V / sizeof V[0]);
	run_spec settings[] = {{"dem", 1e-4, 1, 0, H}, {"dem", 1e-3, 1, 0, H}};
	run_out *full = new_out(), *o = new_out();
	for (int si = 0; si < 2; si++) {
		for (int i = 0; i < nv; i++) {
			run_out *dst = i == 0 ? full : o;
			wp_run(V[i].sets, &settings[si], dst);
			/* repeat the cheap runs for a stable CPU time */
			double cpu = dst->cpu;
			for (int rep = 0; rep < 2; rep++) {
				run_out *tmp = new_out();
				wp_run(V[i].sets, &settings[si], tmp);
				cpu = fmin(cpu, tmp->cpu);
				free(tmp);
			}
			dst->cpu = cpu;
			wp_row("reduction", "reductions", V[i].name, &settings[si], dst,
			    V[i].traj ? full : NULL, full->v);
		}
	}
	free(full);
	free(o);
}

int wp_scene(const char *name, int quick_runs)
{
	quick = quick_runs;
	if (strcmp(name, "nofeed") == 0)
		scene_nofeed();
	else if (strcmp(name, "full") == 0)
		scene_feed("full", S_FULL);
	else if (strcmp(name, "reduced") == 0)
		scene_feed("reduced", S_REDUCED);
	else if (strcmp(name, "reductions") == 0)
		scene_reductions();
	else
		return -1;
	return 0;
}
