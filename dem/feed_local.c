/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * feed_local.c - a bed in this process (feed.h's "local"): bed.c's
 * LIGGGHTS instance behind the feed descriptor, the CLI's coupled run
 * built on it (dem_coupled_new), and the replay of a recorded deck motion
 * (convsim-dem --motion machine). Needs LIGGGHTS: the daemon never links
 * this file.
 */
#include <stdio.h>
#include <stdlib.h>

#include "couple.h"

typedef struct local {
	dem_feed base;
	dem_bed *bed;
} local;

static int local_advance(dem_feed *f, double ax, double ay, double interval, char *msg,
			 size_t msglen)
{
	local *l = (local *)f;
	double cpu0 = dem_cpu_now();
	int rc = dem_bed_advance(l->bed, ax, ay, interval, msg, msglen);
	dem_bed_get(l->bed, &f->state);
	f->cpu += dem_cpu_now() - cpu0;
	return rc;
}

static void local_free(dem_feed *f)
{
	dem_bed_free(((local *)f)->bed);
	free(f);
}

static const struct dem_feed_ops local_ops = {"local", local_advance, local_free};

dem_feed *dem_feed_local(const dem_bed_spec *spec, const void *comm, char *msg, size_t msglen)
{
	local *l = calloc(1, sizeof *l);
	if (!l) {
		snprintf(msg, msglen, "dem bed: out of memory");
		return NULL;
	}
	l->base.ops = &local_ops;
	l->base.grains = spec->grains;
	if (!(l->bed = dem_bed_new(spec, comm, msg, msglen))) {
		free(l);
		return NULL;
	}
	dem_bed_get(l->bed, &l->base.state);
	return &l->base;
}

dem_coupled *dem_coupled_new(const sim_params *p, const sim_scene *sc, const sim_method *m,
			     const dem_bed_spec *spec, int steps, double transient, const void *comm,
			     char *msg, size_t msglen)
{
	int err = SIM_OK;
	if (dem_coupled_check(sc, m, steps, transient, msg, msglen))
		return NULL;
	sim *machine = sim_new(p, sc, m, &err, msg, msglen);
	if (!machine)
		return NULL;
	dem_feed *bed = dem_feed_local(spec, comm, msg, msglen);
	if (!bed) {
		sim_free(machine);
		return NULL;
	}
	return dem_coupled_attach(machine, 1, bed, p, sc, steps, transient, msg, msglen);
}

int dem_replay(dem_bed *b, const double *a, long n, double interval, double transient,
	       double *v, char *msg, size_t msglen)
{
	dem_slope s = {0};
	dem_bed_state st;
	if (transient <= 0) {
		dem_bed_get(b, &st);
		dem_slope_add(&s, 0.0, st.x_mean);
	}
	for (long k = 0; k < n; k++) {
		if (dem_bed_advance(b, a[2 * k], a[2 * k + 1], interval, msg, msglen))
			return -1;
		double t1 = (double)(k + 1) * interval;
		if (t1 >= transient - 1e-12 * interval) {
			dem_bed_get(b, &st);
			dem_slope_add(&s, t1, st.x_mean);
		}
	}
	*v = dem_slope_value(&s);
	return 0;
}
