/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers_check.c - the peers harness's own sanity check (peers.h): a wrong
 * wrapper (a state copied wrongly, a restart from the wrong state, the
 * wrong right-hand side) must not produce a pretty table. On the machine alone, whose right-hand
 * side is smooth, every peer at rtol = 1e-10 must follow the core's rk4 at
 * dt = 1e-5 s (itself within about 1e-9 of the orbit: docs/accuracy.md
 * "Work-precision benchmark") from the steady start, its settling included.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include "peer.h"
#include "peers.h"
#include "units.h"

enum { CHECK_SAMPLES = 250 }; /* every 2 ms over 0.5 s */
#define CHECK_DT 2e-3
#define CHECK_RTOL 1e-10
#define CHECK_MAX_REL 1e-6

/* The trough's x, y at the samples into xy (2 per sample); 0 or -1. */
static int orbit(const char *peer, double *xy, char *msg, size_t msglen)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	if (sim_set_user_str(&p, &sc, &m, "feed", "false", msg, msglen) != SIM_OK)
		return -1;
	m.dt = 1e-5;
	int err;
	sim *s = peer ? peer_sim_new(peer, CHECK_RTOL, &p, &sc, msg, msglen)
		      : sim_new(&p, &sc, &m, &err, msg, msglen);
	if (!s)
		return -1;
	sim_status st;
	for (int i = 0; i < CHECK_SAMPLES; i++) {
		if (sim_advance(s, (i + 1) * CHECK_DT) != SIM_OK) {
			snprintf(msg, msglen, "%s", peer ? peer_of(s)->msg : sim_last_error(s));
			sim_free(s);
			return -1;
		}
		sim_get_status(s, &st);
		xy[2 * i] = st.q[0];
		xy[2 * i + 1] = st.q[1];
	}
	sim_free(s);
	return 0;
}

int peers_check(void)
{
	static double ref[2 * CHECK_SAMPLES], xy[2 * CHECK_SAMPLES];
	char msg[200];
	if (orbit(NULL, ref, msg, sizeof msg) != 0) {
		fprintf(stderr, "peers check: rk4: %s\n", msg);
		return 1;
	}
	double amp = 0.0;
	for (int i = 0; i < 2 * CHECK_SAMPLES; i++)
		amp += ref[i] * ref[i];
	amp = sqrt(amp / CHECK_SAMPLES);
	int bad = 0;
	for (const char *const *name = peer_names; *name; name++) {
		if (orbit(*name, xy, msg, sizeof msg) != 0) {
			printf("check\t%s\tFAILED: %s\n", *name, msg);
			bad++;
			continue;
		}
		double d = 0.0;
		for (int i = 0; i < 2 * CHECK_SAMPLES; i++)
			d += (xy[i] - ref[i]) * (xy[i] - ref[i]);
		double rel = sqrt(d / CHECK_SAMPLES) / amp;
		int ok = rel <= CHECK_MAX_REL;
		bad += !ok;
		printf("check\t%s\tmachine-alone orbit at rtol %g against rk4 dt 1e-5: relative RMS "
		       "%.3g (limit %g) %s\n",
		       *name, CHECK_RTOL, rel, CHECK_MAX_REL, ok ? "ok" : "FAILED");
	}
	return bad ? 1 : 0;
}
