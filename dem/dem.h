/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * dem.h - the feed as a bed of spheres in LIGGGHTS, the DEM code, driven
 * by the deck of this project's machine.
 *
 * The coupling library of the conveyor simulator: it alone sees LIGGGHTS
 * (its C library, library.h) and MPI; core/ stays free of both. A bed
 * lives in the deck's frame: a periodic cell (x along the deck, the
 * transport direction; y across it; z up) over a fixed floor plane z = 0
 * (a wall/gran primitive), with the deck's acceleration applied to every
 * grain as a body force: g_eff = (-a_x, 0, -g - a_y). That is exact for a
 * translating deck (docs/dem.md "Frame"). The deck's motion is held
 * constant over each coupling interval (its mean acceleration there), so
 * that the grains' velocities relative to the deck are exact at the
 * interval's ends; or, for a deck known ahead, given as a formula of time
 * evaluated at every DEM step (dem_bed_advance_drive).
 *
 * Units SI. Positions and momenta are the bed's totals, in the deck frame.
 */
#ifndef CONVSIM_DEM_H
#define CONVSIM_DEM_H

#include <stddef.h>

#include "sim.h"

/* What a bed is made of. Contact law: linear spring (LIGGGHTS's
 * hooke/stiffness) with the stiffness of k_over_m times the mean grain's
 * mass, a viscous normal damper calibrated so that a grain dropped on the
 * floor rebounds with `restitution` (dem_restitution_damping), Coulomb
 * friction mu with a tangential spring (2/7 of the normal one; or, with
 * tangential_viscous, no spring but a viscous tangential force of the
 * normal damper's rate, capped by Coulomb: LIGGGHTS's no_history), and
 * rolling friction mu_roll (model cdt; 0: none). */
typedef struct dem_bed_spec {
	int grains;            /* number of spheres, >= 1 */
	double d_min, d_max;   /* m: diameters uniform in [d_min, d_max] */
	double density;        /* kg/m^3 */
	double cell_x, cell_y; /* m: the periodic cell (x along the deck) */
	double k_over_m;       /* 1/s^2: normal stiffness over the mean grain's mass */
	double restitution;    /* of a grain on the floor, (0, 1] */
	double mu;             /* Coulomb friction, grain-grain and grain-floor */
	double mu_roll;        /* rolling friction (cdt), 0 for none */
	int freeze_rotation;   /* 1: grains do not rotate (fix nve, not nve/sphere) */
	int tangential_viscous; /* 1: no tangential spring (tangential no_history) */
	unsigned seed;         /* packing: diameters and the lattice's jitter */
	double g;              /* m/s^2 gravity */
	double settle;         /* s of settling under gravity before t = 0 */
	/* the frame check (one grain): wiggle_period > 0 replaces the fixed
	 * floor plane by a floor mesh that LIGGGHTS moves in the lab frame,
	 * (wiggle_x, wiggle_z) sin(2 pi t / wiggle_period) from t = 0 (the
	 * grain then starts with the floor's velocity), the cell closed in x
	 * and y; the bed's frame is then the lab's (advance with a = 0) */
	double wiggle_x, wiggle_z, wiggle_period;
	/* A named material's contacts (hertz 1; docs/dem.md "The map"):
	 * Hertz-Mindlin (LIGGGHTS's hertz, tangential history) with Young's
	 * modulus `youngs` (Pa, the scaled one) and Poisson's ratio for the
	 * grains and the deck alike; restitution, Coulomb friction and
	 * rolling friction (model epsd2; 0: none) grain on grain (_pp) and
	 * grain on deck (_pw). Then k_over_m, restitution, mu and mu_roll
	 * are not used, and the step is the smaller of a tenth of the
	 * lightest grain's Rayleigh time and a fortieth of its Hertz contact
	 * on the deck at 1 m/s. */
	int hertz;
	double youngs, poisson;
	double e_pp, e_pw, mu_pp, mu_pw, roll_pp, roll_pw;
} dem_bed_spec;

/* The bed this project uses unless told otherwise: spheres 3.6-4.4 mm of
 * density 2500 kg/m^3 in a cell of 20 x 4 mean diameters, `depth` mean
 * diameters deep at packing 0.6 (at least one grain), with the column
 * model's contact numbers: k_c/m_n, R, mu; no rolling friction; seed 1;
 * settled 0.3 s (0.05 s for one grain). */
void dem_bed_spec_default(const sim_params *p, double depth, dem_bed_spec *b);
/* The mean grain's mass (kg) of a bed of spec s. */
double dem_bed_spec_mass_mean(const dem_bed_spec *s);
/* The DEM step (s) of a bed of spec s: a fiftieth of the floor contact's
 * period for the lightest grain, pi / sqrt(k / m_min) / 50 with k the
 * stiffness k_over_m gives the mean grain (dem_bed_dt is this). */
double dem_bed_spec_dt(const dem_bed_spec *s);
/* CPU seconds one grain's DEM step costs, measured: a coupled bed of 367
 * grains at k/m = 2e6 1/s^2 (DEM step 3.77e-5 s) took 3.15 CPU s a
 * simulated second (docs/dem.md "Admission and cost"; 92 grains 0.77,
 * 1467 grains 15.2, where this gives 0.78 and 12.5). */
#define DEM_CPU_PER_GRAIN_STEP 3.2e-7
/* The bed's expected CPU seconds per simulated second: grains / DEM step
 * times DEM_CPU_PER_GRAIN_STEP (one rank). */
double dem_bed_spec_cost(const dem_bed_spec *s);
/* Grains of mean diameter d_mean (m) that fill a cell_x x cell_y cell
 * (m) `depth` mean diameters deep at packing 0.6; at least 1. */
int dem_bed_grains(double cell_x, double cell_y, double d_mean, double depth);

typedef struct dem_bed dem_bed;

/* Open LIGGGHTS and build the bed: grains on a jittered lattice above the
 * floor, settled for spec->settle s on the resting deck. comm: NULL for a
 * serial instance, else a pointer to the MPI_Comm to run on (MPI must be
 * initialised by the caller). Returns NULL with a sentence in msg on
 * error (a bad spec, or LIGGGHTS refused a command). */
dem_bed *dem_bed_new(const dem_bed_spec *spec, const void *comm, char *msg, size_t msglen);
/* Close LIGGGHTS and free; NULL is accepted. */
void dem_bed_free(dem_bed *b);

/* The DEM step (s) of the bed: a fiftieth of the floor contact's
 * duration for the lightest grain. */
double dem_bed_dt(const dem_bed *b);

/* Advance the bed by `interval` s (a whole number of DEM steps of at most
 * dem_bed_dt each) with the deck's acceleration (ax, ay) (m/s^2,
 * horizontal and vertical) held constant. 0, or -1 with msg when
 * LIGGGHTS fails. */
int dem_bed_advance(dem_bed *b, double ax, double ay, double interval, char *msg, size_t msglen);

/* Advance the bed by `interval` s (a whole number of DEM steps of at most
 * dem_bed_dt each) with the deck's acceleration given as two formulas in
 * LIGGGHTS's syntax of `v_t`, the bed's time (s since its t = 0): ax, ay
 * (m/s^2, horizontal and vertical; numbers, + - * / ( ), sin, cos, exp,
 * sqrt), evaluated at every DEM step: no staircase, for a deck whose
 * motion is known ahead (motion.h). 0, or -1 with msg for a formula
 * outside that syntax. */
int dem_bed_advance_drive(dem_bed *b, const char *ax, const char *ay, double interval, char *msg,
			  size_t msglen);

/* The bed now, in the deck's frame. */
typedef struct dem_bed_state {
	double t;            /* s since t = 0 (the end of the settling) */
	double mass;         /* kg of all grains */
	double x_mean;       /* m: mass-weighted mean x, unwrapped across the cell */
	double z_mean;       /* m: mass-weighted mean height */
	double p_x, p_z;     /* kg m/s: momentum relative to the deck */
	double kinetic;      /* J: translational kinetic energy relative to the deck */
	double kinetic_rot;  /* J: the grains' rotational kinetic energy */
} dem_bed_state;
void dem_bed_get(const dem_bed *b, dem_bed_state *st);

/* The largest overlap now (m) between two grains (*pp) and of a grain
 * into the deck (*pw); NaN for a bed without hertz contacts. */
void dem_bed_overlap(const dem_bed *b, double *pp, double *pw);

/* CPU seconds of this process so far (CLOCK_PROCESS_CPUTIME_ID): the
 * cost figures of dem/ and its tools. */
double dem_cpu_now(void);

/* The viscous damping ratio of a linear contact (spring stiffness k,
 * mass m, force never attractive) that gives restitution e; found by
 * bisection on the integrated collision. >= 0, above 1 (overdamped) for
 * e < 0.135: 1.95 for e = 0.05. */
double dem_restitution_damping(double e);
/* The restitution of a linear contact with damping ratio zeta (the
 * collision integrated, force never attractive). */
double dem_restitution(double zeta);

#endif
