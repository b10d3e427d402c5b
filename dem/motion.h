/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * motion.h - the deck's prescribed motion for a DEM bed: a harmonic fit
 * of the centre deck point's displacement on the machine run one-way
 * (feed_coupling = false), and a bed driven by it over whole periods with
 * the transport velocity measured as the column model measures it.
 */
#ifndef CONVSIM_DEM_MOTION_H
#define CONVSIM_DEM_MOTION_H

#include "dem.h"
#include "sim.h"

#define DEM_MAX_HARMONICS 8

/* x(t) = a[0] + sum_h a[2h-1] cos(h omega t) + a[2h] sin(h omega t), the
 * same for y (b): m, t in s since the machine's t = 0. */
typedef struct dem_motion {
	double omega;                       /* rad/s, the mean rotor speed */
	int harmonics;                      /* H */
	double a[2 * DEM_MAX_HARMONICS + 1];
	double b[2 * DEM_MAX_HARMONICS + 1];
	double residual;                    /* m: rms of the fit's residual (x and y) */
	double amplitude;                   /* m: rms deck displacement about its mean */
} dem_motion;

/* Run the machine of p, sc, m (the scene taken one-way: feed_coupling =
 * 0) to t1 s and fit `harmonics` harmonics of the mean rotor speed over
 * [t0, t1] to the centre deck point's displacement (64 samples a period).
 * SIM_OK, or a core error with msg. */
int dem_motion_fit(const sim_params *p, const sim_scene *sc, const sim_method *m, double t0,
		   double t1, int harmonics, dem_motion *out, char *msg, size_t msglen);

/* The one-way machine's own deck (p, sc with feed_model external and
 * feed_coupling = 0, as a coupled run builds it): the centre deck point's
 * mean acceleration over each interval of `steps` machine steps up to
 * t_end, into *acc (a_x, a_y pairs, malloc'd: the caller frees), *n
 * intervals of *interval s. SIM_OK or a core error with msg. */
int dem_motion_sample(const sim_params *p, const sim_scene *sc, const sim_method *m, int steps,
		      double t_end, double **acc, long *n, double *interval, char *msg, size_t msglen);

/* The fit's deck velocity (m/s) at t. */
void dem_motion_velocity(const dem_motion *mo, double t, double vel[2]);

/* What a prescribed-motion run measured. */
typedef struct dem_prescribed {
	double transport_velocity; /* m/s: mean x of the grains over whole periods after the transient */
	double periods;            /* whole periods measured */
	double cpu_seconds;        /* of the DEM, this process */
	double dt;                 /* s DEM step */
	double mass;               /* kg of the bed */
	double bed_height;         /* m: twice the mean height of the grains at t = 0 */
	/* m/s: the transport velocity over the first and the second half of
	 * the measured periods (the middle period's start splits them) */
	double v_first_half, v_second_half;
	/* m: the largest overlaps grain on grain and grain into the deck
	 * from t = 0 on, sampled 40 times a period (hertz beds; else NaN) */
	double overlap_pp, overlap_pw;
} dem_prescribed;

/* Drive bed b with motion mo from its t = 0 to t_end, in coupling
 * intervals of 1/intervals of a period, each under the mean acceleration
 * of the deck over it (the velocity's change over the interval), or with
 * intervals 0 under the fit's own acceleration evaluated at every DEM
 * step (dem_bed_advance_drive, a period a run: no staircase); the
 * transport velocity is measured over the whole periods after transient
 * (s), and over each half of them. A bed with hertz contacts runs a
 * period in 40 runs (intervals 0) and samples its overlaps after each.
 * 0, or -1 with msg. */
int dem_run_prescribed(dem_bed *b, const dem_motion *mo, double t_end, double transient,
		       int intervals, dem_prescribed *out, char *msg, size_t msglen);

#endif
