/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * phase.c - the feed's motion over one vibration period, averaged by the
 * rotor's angle: where in the period two settings part (docs/accuracy.md "Targets",
 * the feed step's remaining error). Not part of `make bench`; build and
 * run it against the core library:
 *
 *   cc -O2 -Icore -o build/bench/phase tests/bench/phase.c build/libcore.a -lm
 *   build/bench/phase 35 ccw substeps=5 > a.txt
 *   build/bench/phase 35 ccw substeps=64 > b.txt
 *
 * Arguments: beta (deg), rotation, then NAME=VALUE settings (user units,
 * as `convsim --set`). From the steady start, over [1, 6] s, at every
 * machine step the state is binned by phi mod 2 pi into 64 bins; per bin
 * the means of: the bottom and top layer's horizontal velocity, the
 * column's mean horizontal velocity, the deck point's velocity (x, y),
 * the share of samples with the bottom contact closed, the bottom layer's
 * vertical velocity and its compression (m/s, m). The layers' velocities
 * are dem's, those of the last feed sub-step's middle, half a feed step
 * before the sample: in contact they differ from the deck's at the sample
 * by its acceleration times h/2, so compare settings there by positions
 * or in flight.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "deck.h"
#include "model.h"
#include "sim.h"
#include "sim_int.h"
#include "units.h"

#define NBINS 64
#define TWO_PI 6.283185307179586
enum { BOTTOM, TOP, MEAN, DECK_X, DECK_Y, CLOSED, BOTTOM_VY, COMPRESSION, NQTY };

static int setting(sim_params *p, sim_scene *sc, sim_method *m, const char *name,
		   const char *value)
{
	char msg[256];
	if (sim_set_user_str(p, sc, m, name, value, msg, sizeof msg) == SIM_OK)
		return 0;
	fprintf(stderr, "phase: %s=%s: %s\n", name, value, msg);
	return -1;
}

int main(int argc, char **argv)
{
	if (argc < 3) {
		fprintf(stderr, "usage: phase BETA_DEG cw|ccw [NAME=VALUE ...]\n");
		return 2;
	}
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	if (setting(&p, &sc, &m, "beta", argv[1]) || setting(&p, &sc, &m, "rotation", argv[2]))
		return 2;
	for (int i = 3; i < argc; i++) {
		char name[64];
		const char *eq = strchr(argv[i], '=');
		if (!eq || (size_t)(eq - argv[i]) >= sizeof name) {
			fprintf(stderr, "phase: %s: not NAME=VALUE\n", argv[i]);
			return 2;
		}
		memcpy(name, argv[i], (size_t)(eq - argv[i]));
		name[eq - argv[i]] = '\0';
		if (setting(&p, &sc, &m, name, eq + 1))
			return 2;
	}
	char msg[256];
	int err;
	sim *s = sim_new(&p, &sc, &m, &err, msg, sizeof msg);
	if (!s || sim_start(s, msg, sizeof msg) != SIM_OK) {
		fprintf(stderr, "phase: %s\n", msg);
		return 1;
	}
	const model *md = &s->md;
	const int L = md->L;
	double sum[NBINS][NQTY] = {{0}};
	long count[NBINS] = {0};
	for (double t = s->cfg.dt; t < 6.0; t += s->cfg.dt) {
		if (sim_advance(s, t) != SIM_OK) {
			fprintf(stderr, "phase: the run failed at t = %g s\n", t);
			return 1;
		}
		if (t < 1.0 || L < 1)
			continue;
		double q[NQ_FULL], qd[NQ_FULL], dp[2], dv[2];
		model_full_coords(md, &s->ctl, s->t_int, s->y, q, qd);
		deck_rot R = deck_rotation(q);
		deck_point(&md->dk, md->dk.d[0], &R, q, qd, dp, dv);
		const double *eta = s->y + md->nq + md->nf;
		const double *xid = s->y + md->npos + md->nq, *etad = xid + md->nf;
		double mean = 0.0;
		for (int j = 0; j < L; j++)
			mean += xid[j];
		int b = (int)(fmod(fabs(q[Q_PHI]), TWO_PI) / TWO_PI * NBINS) % NBINS;
		double *a = sum[b];
		a[BOTTOM] += xid[0];
		a[TOP] += xid[L - 1];
		a[MEAN] += mean / L;
		a[DECK_X] += dv[0];
		a[DECK_Y] += dv[1];
		a[CLOSED] += dp[1] - eta[0] > 0.0;
		a[BOTTOM_VY] += etad[0];
		a[COMPRESSION] += dp[1] - eta[0];
		count[b]++;
	}
	printf("bin bottom_vx top_vx mean_vx deck_vx deck_vy closed bottom_vy compression\n");
	for (int b = 0; b < NBINS; b++) {
		printf("%d", b);
		for (int k = 0; k < NQTY; k++)
			printf(" %.7g", count[b] ? sum[b][k] / count[b] : NAN);
		printf("\n");
	}
	sim_free(s);
	return 0;
}
