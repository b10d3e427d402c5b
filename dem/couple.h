/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * couple.h - LIGGGHTS as the feed model of a session (feed_model =
 * liggghts): the machine from the core (sim.h, an external feed), the bed
 * in LIGGGHTS (dem.h), coupled every `steps` machine steps.
 *
 * One coupling interval [t, t + H], H = steps x the machine's step:
 *   1. the machine advances over H under the load the bed gave over the
 *      interval before (held; the core's sim_set_deck_load);
 *   2. the deck's mean acceleration there, (v_D(t + H) - v_D(t)) / H,
 *      drives the bed over the same H (the deck's frame, dem.h);
 *   3. the floor's impulse on the grains over H, from their momentum:
 *      J = dP_rel + M (a_D + g e_y) H, scaled by the feed's mass over
 *      the cell's, K L m_n / M, gives the next load: -J s / H.
 * A staggered, explicit scheme: the load lags one interval. The periodic
 * cell stands for a bed spread evenly over the deck, so the load acts at
 * the centre deck point with no moment about it.
 */
#ifndef CONVSIM_DEM_COUPLE_H
#define CONVSIM_DEM_COUPLE_H

#include "dem.h"
#include "feed.h"
#include "sim.h"

/* The machine's step when the method's dt is 0 (the scene's default):
 * coupled every step, the staggered scheme's energy error is about 1.3 %
 * at 3.125e-4 s, 2.6 % at 6.25e-4 s and 4 % at the core's default
 * 1.25e-3 s, at nearly the same cost (the DEM's step dominates); 10-ms
 * intervals reach 78 % (docs/dem.md "Coupling interval"). The CLI and the
 * daemon both take it, so that they couple the same sequence. */
#define DEM_COUPLED_DT 3.125e-4

typedef struct dem_coupled dem_coupled;

/* What a coupled run shows (the feed's scale: K L m_n over the cell's
 * mass; energies and impulses scaled to the feed). */
typedef struct dem_coupled_status {
	double t;                    /* s */
	double interval;             /* s: the coupling interval H */
	double scale;                /* the feed's mass over the cell's */
	double transport_velocity;   /* m/s: least-squares slope of the grains' mean x over t >= transient */
	double load[2];              /* N: the load on the deck now (x, y) */
	double load_mean_y;          /* N: the vertical load's mean over t >= transient */
	double weight;               /* N: the feed's weight K L m_n g */
	double impulse_machine[2];   /* N s: the load's impulse on the machine since t = 0 */
	double impulse_bed[2];       /* N s: the floor's impulse on the bed since t = 0 (scaled) */
	double work_machine;         /* J: the load's work on the machine since t = 0 */
	double work_bed;             /* J: the floor's work on the bed (deck's mean velocity per interval) */
	double bed_energy;           /* J: the bed's energy change since t = 0 (kinetic, absolute
					frame, translation and rotation, + potential; scaled) */
	double machine_residual;     /* J: the core's energy residual (status e_residual) */
	double dem_cpu_seconds;      /* s of the DEM's CPU since the coupling began (the
					bed's process for a remote bed) */
	double displacement;         /* m: the grains' mean x since the coupling began */
	double bed_velocity;         /* m/s: their mean velocity relative to the deck */
	int grains;
	long intervals;              /* since t = 0 (a restored machine's before included) */
} dem_coupled_status;

/* Whether sc and m can be coupled every `steps` machine steps: feed on,
 * feed_model liggghts, a fixed-step method (euler, rk4 or dem), steps in
 * [1, 100000], transient >= 0. 0, or -1 with the reason in msg. */
int dem_coupled_check(const sim_scene *sc, const sim_method *m, int steps, double transient,
		      char *msg, size_t msglen);
/* Couple machine (feed_model = SIM_FEED_EXTERNAL, a fixed step; borrowed,
 * or owned when own_machine: freed with the coupling) to bed (owned from
 * here, freed on failure too) every `steps` machine steps from the
 * machine's time now (0, or a restored machine's, which must end a whole
 * interval: the bed is new there). The transport velocity counts from
 * `transient` s. The feed's size (K L m_n) is p's and sc's. NULL with
 * msg on error. */
dem_coupled *dem_coupled_attach(sim *machine, int own_machine, dem_feed *bed,
				const sim_params *p, const sim_scene *sc, int steps,
				double transient, char *msg, size_t msglen);
/* A coupled run of p, sc, m with a bed of spec in this process
 * (dem_feed_local: LIGGGHTS linked, feed_local.c). comm: NULL (serial) or
 * an MPI_Comm * for LIGGGHTS. NULL with msg on error. */
dem_coupled *dem_coupled_new(const sim_params *p, const sim_scene *sc, const sim_method *m,
			     const dem_bed_spec *spec, int steps, double transient, const void *comm,
			     char *msg, size_t msglen);
void dem_coupled_free(dem_coupled *c);
/* The bed (borrowed). */
const dem_feed *dem_coupled_bed(const dem_coupled *c);

/* Advance whole coupling intervals while t < t_end (s). 0, or -1 with
 * msg (the machine froze, LIGGGHTS failed). Every interval's deck
 * acceleration (a_x, a_y) is written to deck_out when it is not NULL, one
 * line each: what `convsim-dem --deck-in` replays. */
int dem_coupled_advance(dem_coupled *c, double t_end, FILE *deck_out, char *msg, size_t msglen);

void dem_coupled_get(const dem_coupled *c, dem_coupled_status *st);
/* The machine (borrowed). */
const sim *dem_coupled_machine(const dem_coupled *c);
/* Restart the transport velocity's estimate (and the mean vertical load)
 * from now: the grains' mean x from here on (after a change of the
 * machine, to measure the new steady state, as sim_restart_transport). */
void dem_coupled_restart_transport(dem_coupled *c);
/* The end of the first coupling interval at or after t (s): where the
 * machine stops when asked to reach t (a caller that steps to sample
 * times which are no multiple of the interval rounds up with this). */
double dem_coupled_interval_end(const dem_coupled *c, double t);

/* The transport velocity's estimator, shared with the replay so that both
 * give the same number for the same bed: a least-squares line through
 * (t, x) samples. */
typedef struct dem_slope {
	double n, st, sx, stt, stx;
} dem_slope;
void dem_slope_add(dem_slope *s, double t, double x);
double dem_slope_value(const dem_slope *s);

/* Drive bed b (in this process: feed_local.c) with n deck accelerations a[2i], a[2i+1] (m/s^2), each over
 * interval s, and measure the transport velocity from transient s as the
 * coupled run does. 0, or -1 with msg. */
int dem_replay(dem_bed *b, const double *a, long n, double interval, double transient,
	       double *v, char *msg, size_t msglen);

#endif
