/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sweep_plan.c - the mirror reduction of a sweep's points
 * (sim_mirror_plan): a point that is the mirror image of another is no
 * job of its own, and is filled, velocity negated, when the other is over.
 */
#include <stdio.h>
#include <stdlib.h>

#include "sweep_int.h"

/* The mirror reduction's plan of the sweep's points: which are mirror
 * images of which (sw->image, sw->jobs, each point's `mirrored`). The
 * plan depends only on the request, so a restart makes it again. 0, or
 * -1 when out of memory. */
int srv_sweep_plan(srv_sweep *sw)
{
	size_t n = sw->total;
	double *beta = malloc(sizeof *beta * (n ? n : 1));
	int *rot = malloc(sizeof *rot * (n ? n : 1));
	long *source = malloc(sizeof *source * (n ? n : 1));
	sw->image = malloc(sizeof *sw->image * (n ? n : 1));
	int rc = beta && rot && source && sw->image ? 0 : -1;
	for (size_t i = 0; rc == 0 && i < n; i++) {
		beta[i] = sw->pt[i].beta.si;
		rot[i] = sw->pt[i].rotation;
		sw->image[i] = -1;
	}
	if (rc == 0) {
		sw->jobs = sim_mirror_plan(&sw->req.spec.params, &sw->req.spec.scene, n, beta,
					   rot, source);
		for (size_t i = 0; i < n; i++) {
			sw->pt[i].mirrored = source[i] >= 0;
			if (source[i] >= 0)
				sw->image[source[i]] = (long)i;
		}
	}
	free(beta);
	free(rot);
	free(source);
	return rc;
}

/* Point i is over (done or failed): its mirror image, if it has one, is
 * too (lock held). */
void srv_sweep_fill_image(srv_sweep *sw, size_t i)
{
	long j = sw->image[i];
	if (j < 0 || sw->pt[j].state >= 2)
		return;
	const api_sweep_point *src = &sw->pt[i];
	api_sweep_point *p = &sw->pt[j];
	p->state = src->state;
	sim_mirror_measurement(&src->m, &p->m);
	if (src->state == 3)
		sim_mirror_failure(p->error, sizeof p->error, src->beta.user, src->rotation,
				   src->error);
	sw->done++;
}
