/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim_mirror.h - the mirror reduction of a sweep (mirror.c): which points
 * of a sweep are the mirror images of others, and their measurements.
 */
#ifndef CONVSIM_SIM_MIRROR_H
#define CONVSIM_SIM_MIRROR_H

#include <stddef.h>

#include "sim.h"

/* 1 when a sweep of this scene may take the mirror reduction: sc->mirror
 * and a machine symmetric about the vertical through G (h = 0, l1 = l2,
 * the axle at G, mirrored eliminators, c = 0; the columns are mirrored by
 * construction). Then (ccw, pi - beta) moves as the mirror image of (cw,
 * beta) (docs/accuracy.md "Checks with known answers"): x, alpha and phi'
 * change sign, y stays, the eliminators swap with their strokes negated,
 * and the transport velocity changes sign. */
int sim_mirror_applies(const sim_params *p, const sim_scene *sc);

/* Plan a sweep of n points (beta[i] in rad, rotation[i] SIM_CW/SIM_CCW) on
 * the model p, sc: source[i] = -1 for a point to be measured, else the
 * index j < i of a measured point whose mirror image point i is (the other
 * sense, beta_j within 1e-9 rad of pi - beta_i). Without the reduction
 * every source is -1. Returns the number of points to measure. */
size_t sim_mirror_plan(const sim_params *p, const sim_scene *sc, size_t n, const double *beta,
		       const int *rotation, long *source);

/* The measurement of src's mirror image into *dst: transport velocity and
 * mean rotor speed negated; error bar, steady flag and periods taken over
 * (they do not depend on the sense); no CPU time (nothing was run). */
void sim_mirror_measurement(const sim_measurement *src, sim_measurement *dst);

/* The failure of a mirror image whose source point (beta_deg in degrees,
 * rotation SIM_CW/SIM_CCW) failed with why: "mirror image of B deg cw:
 * WHY" into out (len bytes), the cause cut at 118 characters. */
void sim_mirror_failure(char *out, size_t len, double beta_deg, int rotation, const char *why);

#endif
