/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * control_shaping.c - does shaping the beta command settle the feed
 * faster? (docs/control.md "Measured on the preset"). On the czubak2016
 * preset, the two beta changes of the closed loop's setpoint steps (their
 * feedforward: 55.2 -> 107 deg, +0.10 -> -0.08 m/s; 107 -> 70 deg, -0.08
 * -> +0.05 m/s), each from a steady feed (3 s at the first beta), commanded
 * three ways with the core's functions alone:
 *
 *  - a plain step (the core ramps beta at the preset's beta_rate);
 *  - an overdrive: 10 deg beyond the new beta until the ramp would have
 *    ended, plus a pulse time, then the new beta;
 *  - a zero-vibration (ZV) shaped ramp: the ramp convolved with two
 *    impulses of one half each, half a ringing period Tr apart (commanded
 *    every 0.01 s).
 *
 * The feed velocity is sampled as the closed loop samples it (the mean over
 * each excitation period); over 3 s after the command: the 90 % reversal
 * time and the 2 % settling time against the run's own steady velocity
 * (the mean over its last second), and the settling time over the plain
 * step's reversal time (the target's ratio). Markdown on stdout.
 *
 *   make bench-control-shaping
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "sim.h"

#define DEG (M_PI / 180)
#define SETTLE 3.0  /* s at the first beta */
#define WATCH 3.0   /* s watched after the command */
#define NMAX 400    /* samples */
#define CMAX 200    /* beta commands of a shape */

typedef struct cmd {
	double t, beta; /* s after the command, deg */
} cmd;

typedef struct resp {
	double reversal, settling; /* s */
} resp;

/* From b0 steady, the commands c[0..n): the response's times. */
static int respond(double b0, const cmd *c, int n, resp *out)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	p.beta = b0 * DEG;
	int err;
	char msg[200];
	sim *s = sim_new(&p, &sc, &m, &err, msg, sizeof msg);
	if (!s) {
		fprintf(stderr, "control_shaping: %s\n", msg);
		return -1;
	}
	sim_status st;
	sim_advance(s, SETTLE);
	sim_get_status(s, &st);
	double t0 = st.t, period = 2 * M_PI / st.omega_ss;
	double lt = st.t, lx = st.feed_displacement, lp = st.q[3] - st.q[2];
	double t[NMAX], v[NMAX], tn = t0 + period;
	int k = 0, ns = 0;
	while (st.t < t0 + WATCH && ns < NMAX) {
		double tc = k < n ? t0 + c[k].t : INFINITY, target = fmin(tn, tc);
		if (sim_advance(s, target) != SIM_OK)
			break;
		sim_get_status(s, &st);
		if (target == tc)
			sim_set_beta(s, c[k++].beta * DEG, -1);
		if (target == tn) {
			double psi = st.q[3] - st.q[2], dt = st.t - lt;
			v[ns] = (st.feed_displacement - lx) / dt, t[ns++] = st.t - t0;
			if (fabs(psi - lp) > 0.1)
				period = 2 * M_PI * dt / fabs(psi - lp);
			lt = st.t, lx = st.feed_displacement, lp = psi, tn = st.t + period;
		}
	}
	sim_free(s);
	double sum = 0;
	int q = 0;
	for (int i = 0; i < ns; i++)
		if (t[i] > WATCH - 1)
			sum += v[i], q++;
	if (q == 0)
		return -1;
	double r = sum / q, from = v[0], band = 0.02 * fabs(r);
	out->reversal = out->settling = NAN;
	double settled = 0;
	for (int i = 0; i < ns; i++) {
		if (isnan(out->reversal) && (r - from) * (v[i] - from - 0.9 * (r - from)) >= 0)
			out->reversal = t[i];
		if (fabs(v[i] - r) > band)
			settled = i + 1 < ns ? t[i + 1] : NAN;
	}
	out->settling = settled;
	return 0;
}

/* The ZV-shaped ramp from b0 to b1 at rate (deg/s), Tr the ringing period. */
static int zv_ramp(double b0, double b1, double rate, double tr, cmd *c)
{
	double a = fabs(b1 - b0), sg = b1 > b0 ? 1 : -1, ramp = a / rate;
	int n = 0;
	for (double t = 0; t < ramp + tr / 2 + 0.02 && n < CMAX; t += 0.01) {
		double r1 = fmin(rate * t, a), r2 = t > tr / 2 ? fmin(rate * (t - tr / 2), a) : 0;
		c[n].t = t, c[n++].beta = b0 + sg * 0.5 * (r1 + r2);
	}
	return n;
}

static void row(const char *change, const char *shape, const resp *r, double plain_rev)
{
	printf("| %s | %s | %.3f | %.3f | %.2f |\n", change, shape, r->reversal, r->settling,
	       r->settling / plain_rev);
}

int main(void)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	double rate = p.beta_rate / DEG;
	const double steps[2][2] = {{55.2, 107}, {107, 70}};
	const char *names[2] = {"55.2° → 107° (+0.10 → −0.08 m/s)", "107° → 70° (−0.08 → +0.05 m/s)"};
	printf("β commands from a steady feed, sampled once a period for %g s (β ramped at %g °/s; "
	       "times against the run's own steady velocity; ratio: settling over the plain step's "
	       "reversal):\n\n", WATCH, rate);
	printf("| β change | command | 90 %% reversal (s) | 2 %% settling (s) | ratio |\n");
	printf("|---|---|---|---|---|\n");
	for (int i = 0; i < 2; i++) {
		double b0 = steps[i][0], b1 = steps[i][1], sg = b1 > b0 ? 1 : -1;
		double ramp = fabs(b1 - b0) / rate;
		cmd c[CMAX] = {{0, b1}};
		resp plain, r;
		if (respond(b0, c, 1, &plain) != 0)
			return 1;
		row(names[i], "plain step", &plain, plain.reversal);
		for (double pulse = 0.05; pulse < 0.21; pulse += 0.075) {
			cmd o[2] = {{0, b1 + 10 * sg}, {ramp + pulse, b1}};
			char what[64];
			snprintf(what, sizeof what, "overdrive 10° until the ramp's end + %.3f s", pulse);
			if (respond(b0, o, 2, &r) == 0)
				row(names[i], what, &r, plain.reversal);
		}
		for (double tr = 0.24; tr < 0.41; tr += 0.08) {
			char what[64];
			snprintf(what, sizeof what, "ZV-shaped ramp, Tr %.2f s", tr);
			if (respond(b0, c, zv_ramp(b0, b1, rate, tr, c), &r) == 0)
				row(names[i], what, &r, plain.reversal);
		}
	}
	return 0;
}
