/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers.c - the benchmark's peers at the 1 % gate (`make bench`; peer.h).
 *
 *   peers check                    the harness's own sanity check: every
 *                                  peer against the core's rk4 on the
 *                                  machine-alone orbit (exit 1 if off)
 *   peers gate NAME RTOL... [--points LIST] [--budget S]
 *                                  the peer NAME at each tolerance, loosest
 *                                  first, over the gate's points, until one
 *                                  meets 1 % at all of them or a run fails
 *   peers ours [--points LIST]     the core's dem over the same points: the
 *                                  defaults and a few other steps
 *   peers report DIR CMD [--points LIST]
 *                                  DIR/peers.tsv (the rows of gate and ours)
 *                                  into DIR/peers.md and DIR/peers_summary.tsv
 *
 * One TSV row per (setting, point) on stdout: kind name setting beta
 * rotation v v_ref err cpu steps rejected rhs_evals status. The scene is
 * czubak2016 with its defaults (the steady start, v over [0, 4] s: what
 * `convsim sweep` measures), so v_ref and the convention are those of
 * tests/bench/accuracy.sh (docs/accuracy.md "Accuracy and speed"). CPU: process CPU
 * seconds of the whole point (shooting, settling, the 4-s window), the
 * least of up to three repeats while a point costs under a second.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "peer.h"
#include "peers.h"
#include "units.h"

/* czubak2016 with the point's beta and sense; exits on a refused value. */
static void point_scene(const pt *p, sim_params *sp, sim_scene *sc, sim_method *m)
{
	char msg[200], beta[32];
	sim_preset_czubak2016(sp, sc, m);
	snprintf(beta, sizeof beta, "%g", p->beta);
	if (sim_set_user_str(sp, sc, m, "beta", beta, msg, sizeof msg) != SIM_OK ||
	    sim_set_user_str(sp, sc, m, "rotation", p->rot, msg, sizeof msg) != SIM_OK) {
		fprintf(stderr, "peers: %s\n", msg);
		exit(2);
	}
}

static double run_budget; /* CPU s per peer run; 0: none */

/* One run of point p: the peer `name` at rtol, or (name NULL) the core's
 * dem at dt / substeps. Fills v, status, counters; returns CPU seconds. */
static double run_point(const char *name, double rtol, double dt, int substeps, const pt *p,
			double t_end, prow *r)
{
	sim_params sp;
	sim_scene sc;
	sim_method m;
	point_scene(p, &sp, &sc, &m);
	m.dt = dt;
	m.substeps = substeps;
	char msg[200] = "";
	int err = SIM_OK;
	double c0 = peer_cpu_now();
	peer_set_budget(name ? run_budget : 0);
	sim *s = name ? peer_sim_new(name, rtol, &sp, &sc, msg, sizeof msg)
		      : sim_new(&sp, &sc, &m, &err, msg, sizeof msg);
	if (s)
		err = sim_advance(s, t_end);
	double cpu = peer_cpu_now() - c0;
	sim_status st;
	r->v = NAN;
	r->steps = r->rejected = r->rhs = 0;
	if (s) {
		sim_get_status(s, &st);
		r->v = err == SIM_OK ? st.transport_velocity : NAN;
		r->rhs = s->sys.rhs_evals;
		r->steps = name ? peer_of(s)->steps : st.steps;
		r->rejected = name ? peer_of(s)->rejected : 0;
		/* a peer's own reason, else the engine's (its state check
		 * stops a diverging run without the peer saying why) */
		if (err != SIM_OK)
			snprintf(msg, sizeof msg, "%s",
				 name && peer_of(s)->msg[0] ? peer_of(s)->msg : sim_last_error(s));
		sim_free(s);
	} else if (err == SIM_OK) {
		err = SIM_ESTEP;
	}
	snprintf(r->status, sizeof r->status, "%s", err == SIM_OK ? "ok" : msg);
	return cpu;
}

/* Runs every point of the set with one setting, prints its rows; returns
 * the worst error by the convention (INFINITY when a run failed). */
static double run_set(const char *kind, const char *name, const char *setting, double rtol,
		      double dt, int substeps, const pset *ps)
{
	double worst = 0.0;
	for (int i = 0; i < ps->n; i++) {
		const pt *p = &ps->p[i];
		prow r;
		double cpu = run_point(kind[0] == 'p' ? name : NULL, rtol, dt, substeps, p, 4.0, &r);
		for (int rep = 1; rep < 3 && cpu < 1.0 && !strcmp(r.status, "ok"); rep++) {
			prow again;
			cpu = fmin(cpu, run_point(kind[0] == 'p' ? name : NULL, rtol, dt, substeps,
						  p, 4.0, &again));
		}
		double e = isfinite(r.v) ? pset_error(ps, p, r.v) : INFINITY;
		worst = fmax(worst, e);
		printf("%s\t%s\t%s\t%g\t%s\t%.9g\t%.9g\t%.6g\t%.6g\t%llu\t%llu\t%llu\t%s\n", kind,
		       name, setting, p->beta, p->rot, r.v, p->vref, e, cpu,
		       (unsigned long long)r.steps, (unsigned long long)r.rejected,
		       (unsigned long long)r.rhs, r.status);
		fflush(stdout);
		if (!isfinite(e))
			break; /* a failed run ends the setting */
	}
	return worst;
}

static int cmd_gate(const char *name, int nrtol, char **rtols, const pset *ps)
{
	if (!peer_doc(name)) {
		fprintf(stderr, "peers: unknown peer '%s'\n", name);
		return 2;
	}
	for (int i = 0; i < nrtol; i++) {
		double rtol = atof(rtols[i]);
		char setting[32];
		snprintf(setting, sizeof setting, "rtol=%g", rtol);
		double worst = run_set("peer", name, setting, rtol, 0, 0, ps);
		if (worst <= 0.01 || !isfinite(worst))
			break;
	}
	return 0;
}

static int cmd_ours(const pset *ps)
{
	static const struct {
		double dt;
		int substeps;
	} L[] = {{1e-3, 10}, {5e-4, 10}, {0, 0}, {2.5e-4, 20}, {1.25e-4, 20}};
	for (size_t i = 0; i < sizeof L / sizeof L[0]; i++) {
		char setting[48];
		if (L[i].dt == 0)
			snprintf(setting, sizeof setting, "default");
		else
			snprintf(setting, sizeof setting, "dt=%g,substeps=%d", L[i].dt,
				 L[i].substeps);
		run_set("ours", "dem", setting, 0, L[i].dt, L[i].substeps, ps);
	}
	return 0;
}

int main(int argc, char **argv)
{
	const char *points = NULL;
	double budget = 0;
	int na = 0;
	char *args[64];
	for (int i = 1; i < argc; i++) {
		if (!strcmp(argv[i], "--points") && i + 1 < argc)
			points = argv[++i];
		else if (!strcmp(argv[i], "--budget") && i + 1 < argc)
			budget = atof(argv[++i]);
		else if (na < 64)
			args[na++] = argv[i];
	}
	if (na >= 1 && !strcmp(args[0], "check"))
		return peers_check();
	pset ps;
	if (na >= 1 && pset_load(&ps, "tests/bench/results/vref.tsv", points) != 0)
		return 2;
	run_budget = budget;
	if (na >= 3 && !strcmp(args[0], "gate"))
		return cmd_gate(args[1], na - 2, args + 2, &ps);
	if (na >= 1 && !strcmp(args[0], "ours"))
		return cmd_ours(&ps);
	if (na >= 3 && !strcmp(args[0], "report"))
		return peers_report(args[1], args[2], ps.n, points ? points : "all");
	fprintf(stderr, "usage: peers check\n"
			"       peers gate NAME RTOL... [--points LIST] [--budget CPU_S]\n"
			"       peers ours [--points LIST]\n"
			"       peers report DIR CMD [--points LIST]\n");
	return 2;
}
