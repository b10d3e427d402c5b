/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * vref.c - transport velocity over consecutive windows, for the converged
 * reference v_ref(beta, rotation) and for the accuracy gate.
 *
 * For every point of a beta grid and every rotation it creates one
 * instance of the czubak2016 scene (with --set overrides), runs it once and
 * restarts the transport-velocity estimator at each window edge, so one
 * run yields v over [w0, w1], [w1, w2], ... (whole excitation periods
 * within each window). Points run on a thread pool; output is one TSV row
 * per point, in grid order:
 *
 *   beta_deg  rotation  v_1 ... v_n  cpu_s
 *
 * Usage: vref [--beta FROM:TO:STEP] [--rotation cw,ccw] [--windows a,b,c...]
 *             [--threads N] [--set NAME=VALUE ...]
 * Values of --set are in the settings table's user units (beta in deg).
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim.h"
#include "units.h"

enum { MAX_WIN = 16, MAX_SET = 32, MAX_PTS = 1024 };

typedef struct point {
	double beta;
	int rotation;
	double v[MAX_WIN];
	double cpu;
	int err;
	char msg[200];
} point;

static struct {
	const char *set_name[MAX_SET], *set_value[MAX_SET];
	int nset;
	double win[MAX_WIN + 1];
	int nwin;
	point pts[MAX_PTS];
	int npts, next;
	pthread_mutex_t lock;
} g = {.lock = PTHREAD_MUTEX_INITIALIZER};

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
	return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

static void run_point(point *pt)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset("czubak2016", &p, &sc, &m);
	for (int i = 0; i < g.nset; i++)
		if (sim_set_user_str(&p, &sc, &m, g.set_name[i], g.set_value[i], pt->msg,
				sizeof pt->msg) != SIM_OK) {
			pt->err = 1;
			return;
		}
	char num[32];
	snprintf(num, sizeof num, "%.17g", pt->beta);
	sim_set_user_str(&p, &sc, &m, "beta", num, NULL, 0);
	sim_set_user_str(&p, &sc, &m, "rotation", pt->rotation == SIM_CW ? "cw" : "ccw", NULL, 0);
	sc.transient = g.win[0];
	double c0 = cpu_now();
	int err;
	sim *s = sim_new(&p, &sc, &m, &err, pt->msg, sizeof pt->msg);
	if (!s) {
		pt->err = 1;
		return;
	}
	for (int w = 0; w < g.nwin; w++) {
		if (w > 0)
			sim_restart_transport(s);
		if (sim_advance(s, g.win[w + 1]) != SIM_OK) {
			snprintf(pt->msg, sizeof pt->msg, "%s", sim_last_error(s));
			pt->err = 1;
			break;
		}
		sim_status st;
		sim_get_status(s, &st);
		pt->v[w] = st.transport_velocity;
	}
	pt->cpu = cpu_now() - c0;
	sim_free(s);
}

static void *worker(void *arg)
{
	(void)arg;
	for (;;) {
		pthread_mutex_lock(&g.lock);
		int i = g.next++;
		pthread_mutex_unlock(&g.lock);
		if (i >= g.npts)
			return NULL;
		run_point(&g.pts[i]);
	}
}

static int parse_list(const char *s, double *out, int max)
{
	int n = 0;
	char *end;
	while (*s && n < max) {
		out[n++] = strtod(s, &end);
		if (end == s)
			return -1;
		s = *end == ',' ? end + 1 : end;
	}
	return n;
}

int main(int argc, char **argv)
{
	double b0 = 0, b1 = 180, db = 5;
	const char *rot = "cw,ccw";
	int threads = 2;
	g.nwin = parse_list("16,24,32", g.win, MAX_WIN + 1) - 1;
	for (int i = 1; i < argc; i++) {
		const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (!v)
			goto usage;
		if (!strcmp(a, "--beta") && sscanf(v, "%lf:%lf:%lf", &b0, &b1, &db) == 3 && db > 0)
			;
		else if (!strcmp(a, "--rotation"))
			rot = v;
		else if (!strcmp(a, "--windows"))
			g.nwin = parse_list(v, g.win, MAX_WIN + 1) - 1;
		else if (!strcmp(a, "--threads"))
			threads = atoi(v);
		else if (!strcmp(a, "--set") && strchr(v, '=') && g.nset < MAX_SET) {
			char *eq = strchr(v, '=');
			*eq = '\0';
			g.set_name[g.nset] = v;
			g.set_value[g.nset++] = eq + 1;
		} else
			goto usage;
		i++;
	}
	if (g.nwin < 1 || threads < 1)
		goto usage;
	for (double b = b0; b <= b1 + 1e-9 && g.npts < MAX_PTS; b += db)
		for (const char *r = rot; *r;) {
			int cw = !strncmp(r, "cw", 2);
			g.pts[g.npts].beta = b;
			g.pts[g.npts++].rotation = cw ? SIM_CW : SIM_CCW;
			r = strchr(r, ',');
			if (!r)
				break;
			r++;
		}
	pthread_t th[64];
	if (threads > 64)
		threads = 64;
	for (int t = 0; t < threads; t++)
		pthread_create(&th[t], NULL, worker, NULL);
	for (int t = 0; t < threads; t++)
		pthread_join(th[t], NULL);
	int bad = 0;
	for (int i = 0; i < g.npts; i++) {
		point *pt = &g.pts[i];
		if (pt->err) {
			fprintf(stderr, "vref: beta %g %s: %s\n", pt->beta,
				pt->rotation == SIM_CW ? "cw" : "ccw", pt->msg);
			bad = 1;
			continue;
		}
		printf("%g\t%s", pt->beta, pt->rotation == SIM_CW ? "cw" : "ccw");
		for (int w = 0; w < g.nwin; w++)
			printf("\t%.10g", pt->v[w]);
		printf("\t%.3f\n", pt->cpu);
	}
	return bad;
usage:
	fprintf(stderr, "usage: vref [--beta FROM:TO:STEP] [--rotation cw,ccw] "
			"[--windows a,b,...] [--threads N] [--set NAME=VALUE ...]\n");
	return 2;
}
