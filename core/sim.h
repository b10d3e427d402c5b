/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * sim.h - public interface of the conveyor simulation core.
 *
 * A `sim` is one simulation instance (one session): the machine of docs/MODEL.md
 * (trough, vibrator, two Frahm eliminators on guides at angle beta), the
 * optional feed (columns x layers of point masses with the paper's contact
 * law), the chosen integrator and the model reductions the scene allows.
 * The core uses libc and libm only, keeps no global mutable state, never
 * calls back into its caller and never aborts: any number of instances may
 * run in parallel threads, one thread per instance.
 *
 * Units are SI throughout this interface: angles in rad, rates in rad/s,
 * times in s. Degrees and other friendly units exist only in the settings
 * table (its unit and scale columns) and at the edges (CLI, API), which
 * convert once with the helpers of units.h.
 */
#ifndef CONVSIM_SIM_H
#define CONVSIM_SIM_H

#include <stddef.h>
#include <stdint.h>

/* Return codes (sim_err, SIM_OK, ...) and sim_strerror: errors.h. */
#include "errors.h"

/* ---- parameters ------------------------------------------------------ */

/* sim_params, sim_scene and sim_method: params.h (which the model includes
 * without the rest of this interface). */
#include "params.h"

/* Description of one named setting, for validation, docs and OpenAPI. */
typedef enum { SIM_KIND_REAL, SIM_KIND_INT, SIM_KIND_BOOL, SIM_KIND_ENUM } sim_kind;
typedef struct sim_setting {
	const char *name;     /* docs/MODEL.md name, e.g. "beta", "k_s1" */
	const char *group;    /* "params", "scene" or "integrator" */
	sim_kind kind;
	const char *unit;     /* as the user writes it: "deg", "N/m", ... */
	double scale;         /* SI value of one user unit (RAD_PER_DEG, else 1) */
	double min, max;      /* allowed closed range in user units */
	const char *choices;  /* SIM_KIND_ENUM: "cw|ccw" (index = value) */
	const char *doc;
} sim_setting;

/* The table of every named setting; *n receives its length. Static. */
const sim_setting *sim_settings(size_t *n);

/* The czubak2016 preset (docs/MODEL.md), default scene and default method. */
void sim_preset_czubak2016(sim_params *p, sim_scene *s, sim_method *m);

/* How far the scene's column model is from a DEM bed (docs/dem.md "Model
 * error"), from the DEM map compiled in (tests/bench/results/
 * model_check.csv). checked: 1 when the scene's settings (all but beta,
 * rotation and the ramps) are those of a map entry's calibrated column
 * model with its depth, and (beta, rotation), or its mirror image on a
 * symmetric machine, lies within the angles the entry measured in that
 * sense (bounds included). error (m/s): the expected |v - v_DEM| there,
 * |v_column - v_DEM| interpolated linearly in beta between the entry's
 * two nearest points plus the DEM's seed spread there; error_uncertainty
 * (m/s): that spread plus, between points, up to half the change of
 * |v_column - v_DEM| across them; both NaN unless checked. note: one plain
 * sentence, "DEM check: within +-E m/s here (...)" or why not checked and
 * the nearest checked point. */
typedef struct sim_model_error {
	int checked;
	double error, error_uncertainty;
	char note[200];
} sim_model_error;
/* Fill *out for the scene. Returns 1 checked, 0 not checked, -1 no column
 * model to check (no feed, or a LIGGGHTS feed; the note says so). Pure:
 * no I/O, no allocation. */
int sim_model_check(const sim_params *p, const sim_scene *sc, sim_model_error *out);

/* feed_model auto (docs/feed-models.md "feed_model=auto"): the cheapest
 * feed model whose model error is within the scene's model_tol. What the
 * caller knows of a LIGGGHTS bed here: whether one can run (else
 * `unavailable` says why, a clause), its expected cost in CPU s a
 * simulated second (NaN: not known to this caller, no limit checked) and
 * the caller's limit on it (INFINITY: none; `limit` names it). */
typedef struct sim_feed_liggghts {
	int available;
	const char *unavailable;
	double cost, max_cost;
	const char *limit;
} sim_feed_liggghts;
/* The pick: model SIM_FEED_COLUMN or SIM_FEED_EXTERNAL, or -1 when none
 * fits (field then names the setting to change, "model_tol"; min the
 * smallest model_tol the column model would meet here, NaN if none);
 * expected_cpu_s_per_s the LIGGGHTS bed's cost (NaN for column); why one
 * plain sentence, which model and why. */
typedef struct sim_feed_choice {
	int model;
	const char *field;
	double min;
	double expected_cpu_s_per_s;
	char why[480];
} sim_feed_choice;
/* Pick for the scene (its feed_model need not be auto): column where its
 * DEM check (sim_model_check) is within model_tol, model_error plus its
 * uncertainty; else LIGGGHTS where lg says one can run within its limit;
 * else none. Without a feed the pick is column; model_tol 0 picks none.
 * Returns 0 picked, -1 none. Pure: no I/O, no allocation. */
int sim_feed_pick(const sim_params *p, const sim_scene *sc, const sim_feed_liggghts *lg,
		  sim_feed_choice *out);

/* Names of known presets, NULL-terminated, static. Fill by name. */
extern const char *const sim_preset_names[];
int sim_preset(const char *name, sim_params *p, sim_scene *s, sim_method *m);

/* Set one named setting from a number in SI units (beta in rad; enum and
 * bool settings take their index 0/1/...). Checks the table's range (scaled
 * to SI) and finiteness. On error returns SIM_EPARAM or SIM_EUNKNOWN and,
 * if msg != NULL, writes a sentence naming the setting and its range (in
 * user units) into msg (msglen bytes); nothing is changed then. For user
 * units see sim_set_user() in units.h. */
int sim_set(sim_params *p, sim_scene *s, sim_method *m, const char *name,
	    double value, char *msg, size_t msglen);
/* The same for a string value: enum choices ("cw", "ideal", "rk4" for
 * the integrator "method"), true/false, or a plain decimal number in SI
 * units (decimal.h: not 0x1e, " 30" or "nan"). */
int sim_set_str(sim_params *p, sim_scene *s, sim_method *m, const char *name,
		const char *value, char *msg, size_t msglen);
/* Read one named setting in SI units; SIM_EUNKNOWN if no such name. */
int sim_get(const sim_params *p, const sim_scene *s, const sim_method *m,
	    const char *name, double *value);
/* The same for an entry t of sim_settings()' table, found without a
 * search by name. */
void sim_get_setting(const sim_params *p, const sim_scene *s, const sim_method *m,
		     const sim_setting *t, double *value);

/* The integrator step (s) that dt = 0 stands for: the default of method m
 * for the kind of scene: with or without feed, and, for dem, whether the
 * feed is light enough for its corrected coupling; never more than 0.7 of
 * the method's stability bound on the motor's slip mode (sim_max_dt), so
 * that the mode stays damped (czubak2016: 1.32e-3 s, the 1.25e-3-s default
 * holds; a smaller eccentricity or a steeper motor takes a shorter step). */
double sim_default_dt(const sim_params *p, const sim_scene *s, const sim_method *m);
/* The feed step (s) of the scene's defaults: at most 1/17 of the contact
 * period (sim_contact_period), 2.5e-4 s with m->feed_events (6.25e-5 s
 * without), both times tol / 1 % where tol < 1 %. */
double sim_default_feed_step(const sim_params *p, const sim_scene *s, const sim_method *m);
/* The feed sub-steps that substeps = 0 stands for with macro step dt (s):
 * as many as keep the feed's step within sim_default_feed_step (1 to
 * 1000). */
int sim_default_substeps(const sim_params *p, const sim_scene *s, const sim_method *m, double dt);
/* The contact's period (s): 2 pi sqrt(m_n / k_t), k_t the contact law's
 * tangent stiffness at the bottom of a settled column (k_c for p = 1). */
double sim_contact_period(const sim_params *p, const sim_scene *s);

/* The largest fixed step (s) method m keeps stable on the machine's
 * stiffest modes: the Kloss motor's slip (the method's real_limit over the
 * slip mode's decay rate, model_slip_rate) and the machine's oscillations
 * and dampers (its radius_limit over their largest |lambda|,
 * model_machine_rate), whichever is shorter; INFINITY for an adaptive
 * method. Above it the run blows up within a few seconds
 * (docs/integrators.md "Stability"). */
double sim_max_dt(const sim_params *p, const sim_scene *s, const sim_method *m);

/* The weights' bounds, where the divergence guards would trip at rest:
 * the least k_c (N/m^p; 0 without feed) on which the column rests less
 * than 5 cm into the deck, and the most m_n (kg; INFINITY without feed) a
 * disturbance may bring to the present k_c; the least eliminator spring
 * k_s1 (which 1) or k_s2 (2), N/m, on which it sits less than its 1-m
 * stroke down its guide at beta = 0 or 180 deg. */
double sim_k_c_least(const sim_params *p, const sim_scene *s);
double sim_m_n_most(const sim_params *p, const sim_scene *s);
double sim_k_s_least(const sim_params *p, int which);
/* The same, with each mode's own bound (s; INFINITY where it has none)
 * into *slip and *machine. */
double sim_max_dt_modes(const sim_params *p, const sim_scene *s, const sim_method *m,
			double *slip, double *machine);

/* Whole-set consistency checks (ranges, sizes, known integrator, dt within
 * the method's stability bound, sim_max_dt). Same error convention as
 * sim_set. */
int sim_validate(const sim_params *p, const sim_scene *s, const sim_method *m,
		 char *msg, size_t msglen);

/* ---- integrators ----------------------------------------------------- */

/* sim_method_info (one integrator's description): params.h. */
/* Registry of integrators, built from each method's own descriptor: an
 * array of *n pointers, all static. */
const sim_method_info *const *sim_methods(size_t *n);
/* The name of the default integrator (the presets'; the daemon guesses an
 * adaptive method's steps by its). Static. */
const char *sim_default_method(void);

/* ---- instances ------------------------------------------------------- */

typedef struct sim sim;

/* Create an instance in static equilibrium at t = 0 (feed settled). The
 * arguments are copied. Returns NULL on error and sets *err (may be NULL)
 * and msg as sim_validate does. The instance allocates its whole
 * workspace here; stepping never allocates. */
sim *sim_new(const sim_params *p, const sim_scene *s, const sim_method *m,
	     int *err, char *msg, size_t msglen);
/* sim_new, its steady start's settling stopped once the thread's CPU clock
 * (sim_thread_cpu: s, CLOCK_THREAD_CPUTIME_ID) passes cpu_deadline
 * (INFINITY: never), read every so many steps (about 2 ms or a step late
 * at most): NULL, *err SIM_ECPU, msg how far it settled. No estimate knows
 * an adaptive method's steps. *settled (may be NULL): simulated s settled. */
sim *sim_new_bounded(const sim_params *p, const sim_scene *s, const sim_method *m,
		     double cpu_deadline, double *settled, int *err, char *msg, size_t msglen);
double sim_thread_cpu(void);
/* Free an instance; NULL is accepted. */
void sim_free(sim *s);

/* Advance the observed time to t_end (s, >= current). The integrator takes
 * whole steps (fixed-step methods never shorten one to land on t_end) and
 * may stand up to one step ahead; the observed state at t_end comes from
 * the last step's interpolant (dense output for dopri5), so when and how
 * often a caller observes changes nothing. Returns SIM_OK, SIM_ETIME, or
 * SIM_EDIVERGED / SIM_ESTEP (the instance is then frozen; sim_last_error()
 * tells time and cause). */
int sim_advance(sim *s, double t_end);
/* sim_advance, stopped as sim_new_bounded's settling: SIM_ECPU a whole
 * step short of t_end, observed where the integrator stands, not frozen:
 * a later call goes on (a shadow behind catches up). */
int sim_advance_bounded(sim *s, double t_end, double cpu_deadline);
/* Why the instance froze (time and cause), "" while it runs; owned by s. */
const char *sim_last_error(const sim *s);

/* ---- checkpoints ------------------------------------------------------- */

/* Version of the checkpoint format (checkpoint.c); versions 2 (without the
 * measured step error's shadow) and 3 (without the feed's disturbances)
 * are still read, any other is refused. */
#define SIM_CHECKPOINT_VERSION 4

/* FNV-1a 64 of len bytes: the checkpoints' checksum, for callers that
 * frame their own files the same way. */
uint64_t sim_checksum(const void *buf, size_t len);

/* Bytes sim_checkpoint writes for this instance as it is now (more while
 * a shadow measures the step error: its checkpoint is nested). */
size_t sim_checkpoint_size(const sim *s);
/* Write everything that determines the instance's future (state, the
 * last step's start for the interpolant, times and step count, controls
 * with their ramps, the estimator with its records, energy baselines,
 * the integrator workspace's cached values, counters, a failure, the
 * measured step error and the shadow that measures it) into buf
 * (len >= sim_checkpoint_size), framed by a magic, the version, the
 * instance's layout and a checksum. Reads only. SIM_OK or SIM_EPARAM
 * (buffer too small). */
int sim_checkpoint(const sim *s, void *buf, size_t len);
/* An instance for p, sc, m (the set the checkpoint was taken of) in the
 * checkpoint's state: it continues bit for bit as the checkpointed one
 * would have (no equilibrium, no settling). buf is borrowed. NULL on
 * error with *err: sim_new's codes, or SIM_ECHECKPOINT when buf is cut
 * off, fails its checksum, has another version or another layout (msg
 * says which); never reads past len. */
sim *sim_restore(const sim_params *p, const sim_scene *sc, const sim_method *m, const void *buf,
		 size_t len, int *err, char *msg, size_t msglen);

/* ---- controls (take effect at sim_effective_time()) ------------------ */

/* Time (s) at which a control set now takes effect: the integrator's time. */
double sim_effective_time(const sim *s);
/* Ramp beta to beta (rad) at rate (rad/s; <= 0 keeps the current rate),
 * both within the settings table's ranges of "beta" and "beta_rate".
 * Returns SIM_OK or SIM_EPARAM (nothing changed). */
int sim_set_beta(sim *s, double beta, double rate);
/* As sim_set_beta, but the transport estimate goes on: a controller's
 * small steps of beta within one estimate (its whole periods keep
 * counting across them, and so does the measured step error's shadow,
 * which takes the same command). */
int sim_steer_beta(sim *s, double beta, double rate);
/* Sense of the unbalanced mass, SIM_CW or SIM_CCW; else SIM_EPARAM. */
int sim_set_rotation(sim *s, int rotation);
/* rad/s, within the table's range of "omega_ss"; SIM_OK or SIM_EPARAM. */
int sim_set_omega_ss(sim *s, double omega_ss);
/* Disturb the column feed mid-run (docs/MODEL.md "Disturbances"): its
 * element mass m_n (kg) and friction coefficient mu from
 * sim_effective_time() on; NaN keeps either. Every element keeps its
 * horizontal position and its velocities; where m_n changes, each closed
 * contact's compression is scaled by (m_n / m_n_before)^(1/p), the
 * layers above moving with it, so that a settled column stays settled
 * under the new load (open gaps kept). The stored energy's jump this
 * makes is booked as input (status e_input), so the balance closes
 * across it; the transport estimate starts over. The steps stay those of
 * the start. SIM_EPARAM (nothing changed) without a column feed (no feed,
 * feed_model external), on a failed instance, or for a value outside its
 * range: the settings table's, for m_n narrowed by sim_feed_mass_range. */
int sim_set_feed(sim *s, double m_n, double mu);
/* The m_n (kg) a running instance of p, sc, m takes (lo, hi written,
 * closed): the settings table's range, narrowed where the split method
 * with sub-steps couples a light feed with its corrector (feed mass at
 * most 0.2 of the machine's, docs/integrators.md "Integrators") to the masses
 * that keep it light, and where it couples a heavy feed without, to
 * those that keep it heavy. */
void sim_feed_mass_range(const sim_params *p, const sim_scene *sc, const sim_method *m,
			 double *lo, double *hi);
/* Switch the drive on (on != 0) or off; always SIM_OK. */
int sim_set_drive_on(sim *s, int on);
/* An external feed's load on the deck (feed_model = SIM_FEED_EXTERNAL):
 * force (fx, fy) in N, global axes, at the centre deck point (body point
 * (0, h_d)) and moment (N m, counter-clockwise) about it, held constant
 * from sim_effective_time() until the next call. Its work enters the
 * status's e_input (input = drive work + the load's work), so the energy
 * balance closes. At sim_new the load is the feed's weight, -K L m_n g
 * vertically; under feed_coupling = false the load is not applied.
 * SIM_EPARAM (nothing changed) for a non-finite value or a scene whose
 * feed_model is not external. */
int sim_set_deck_load(sim *s, double fx, double fy, double moment);

/* Place the feed at the observed time (which must equal the integrator's:
 * true after sim_new, and wherever a step ended exactly there): xi, eta,
 * xi', eta' of integrated column k, layer j at [k*L + j] (any array may be
 * NULL to keep it). The energy terms restart from zero and the transport
 * estimator from the new state; feed displacements still count from the
 * start. SIM_EPARAM if a value is not finite, SIM_ETIME if the integrator
 * stands ahead, SIM_ENOMEM; on error nothing changed. */
int sim_place_feed(sim *s, const double *xi, const double *eta, const double *xi_dot,
		   const double *eta_dot);

/* ---- observables at the observed time -------------------------------- */

/* The reductions' bits, SIM_RED_*: params.h. */
/* Name of reduction bit i (0..4), NULL past the end. */
const char *sim_reduction_name(int bit);

/* What reduction bit i leaves out, with its speed-up and the relative
 * change of the transport velocity against the full model, as measured by
 * `make bench` on the czubak2016 start with the default method
 * (tests/bench/results/reductions.tsv; for symmetric_alpha and mirror the
 * 74-point curve of tests/bench/results/accuracy.md, the change over the
 * peak; NaN where it does not apply). NULL past the end. Static. */
typedef struct sim_reduction_info {
	const char *name;
	const char *drops;
	double speedup;
	double v_error;
} sim_reduction_info;
const sim_reduction_info *sim_reduction(int bit);

typedef struct sim_status {
	double t;                 /* s observed time */
	double t_int;             /* s integrator time */
	double beta, beta_dot;    /* rad, rad/s now */
	double beta_target;       /* rad */
	int rotation;             /* SIM_CW / SIM_CCW commanded */
	int drive_on;
	double omega_ss;          /* rad/s commanded */
	double m_n, mu;           /* the feed's element mass (kg) and friction
				     coefficient now (sim_set_feed) */
	double q[6], qd[6];       /* x y alpha phi s1 s2 and rates */
	double rotor_speed;       /* rad/s, phi' - alpha' */
	double motor_torque;      /* N m on the rotor */
	double power;             /* W, torque * rotor_speed */
	double deck[2], deck_vel[2]; /* centre deck point displacement, m, m/s */
	double feed_displacement; /* m, mean over all elements since t = 0 */
	double transport_velocity;/* m/s: slope of feed_displacement over the
				     whole excitation periods since the
				     estimator start (scene.transient or the
				     last sim_restart_transport or control); NaN before
				     one whole period */
	double transport_periods; /* whole periods the estimate spans */
	double transport_velocity_uncertainty; /* m/s: the estimate's error bar
				     (scatter over the window, the drift
				     between its halves, and for dem the
				     step's calibrated error); NaN with
				     fewer than 4 batches of periods */
	int steady;               /* 1 when the estimate spans at least 8
				     periods and shows no drift beyond its
				     scatter */
	double step_error;        /* m/s: the steps' part of the uncertainty:
				     the feed step's error measured on the run
				     (the shadow's Richardson estimate, shadow.c)
				     plus the machine step's a-priori term;
				     before a shadow has finished (or where none
				     runs) the calibrated term of the preset */
	double machine_error;     /* m/s: the machine step's term within it */
	double tol;               /* the accuracy target in use (sim_method.tol) */
	double tol_allowed;       /* m/s: the error tol allows at this v:
				     tol |v| where |v| >= 0.3 v_peak, else tol
				     v_peak, v_peak estimated from the trough's
				     vibration speed */
	int tol_met;              /* 1 when the whole uncertainty is within
				     tol_allowed */
	double rotor_speed_mean;  /* rad/s, motor_torque_mean N m, power_mean W:
				     means over the same whole periods as
				     transport_velocity; NaN before one */
	double motor_torque_mean, power_mean;
	double feed_velocity;     /* m/s: mean over the last whole period (NaN
				     before one); for reversal detection */
	double period;            /* s: length of the last whole period */
	double e_input, e_kinetic, e_potential, e_dissipated; /* J */
	double e_residual;        /* J: stored change + dissipated - input */
	double e_disturb;         /* J: the part of e_input that the feed's
				     disturbances brought (sim_set_feed) */
	uint64_t steps, rhs_evals;
	double dt;                /* s: the integrator's (first) step in use */
	int substeps;             /* feed sub-steps per step in use (dem) */
	unsigned reductions;      /* SIM_RED_* bits */
	int n_dof;                /* integrated machine + feed coordinates */
	int settle_columns;       /* feed columns the steady start's settling
				     integrates (sim.c): one where it settles
				     the symmetric reduction's column, else
				     every integrated one; 0 without feed */
	double feed_mass_ratio;   /* the feed's mass over the machine's where
				     the feed acts on it (0 one-way or
				     without feed); above 0.2 dem holds the
				     feed's reaction a step (docs/
				     integrators.md) */
} sim_status;

/* Copy the status at the observed time into *st (SI units). Reading never
 * changes the instance, its counters included. */
void sim_get_status(const sim *s, sim_status *st);
/* What sim_new would build for this set, without building it: the
 * integrator's step and feed sub-steps in use, the reductions, the
 * integrated coordinates and what its settling integrates (st's dt,
 * substeps, reductions, n_dof, settle_columns and feed_mass_ratio as
 * sim_new's status reports them; the rest of *st zero) and sim_columns /
 * sim_layers (*columns, *layers), from the set validated and the
 * workspace sized but nothing settled: what a caller decides from (the
 * daemon's CPU estimate) before paying for the start. Returns SIM_OK, or
 * sim_new's error before its start with the same *msg. */
int sim_preview(const sim_params *p, const sim_scene *s, const sim_method *m,
		sim_status *st, int *columns, int *layers, char *msg, size_t msglen);

/* Restart the transport-velocity estimator at the next period boundary
 * (for example after a beta change, to measure the new steady state). */
void sim_restart_transport(sim *s);
/* Free the running shadow of the step error (shadow.c), if any, as its
 * window's end would without its estimate: the step error keeps the term
 * it had. For a copy that measures what the instance costs once its start
 * (40 periods after each estimate's start) is over. */
void sim_drop_shadow(sim *s);

/* A measurement of the transport velocity: the status fields of the same
 * names at the end of a run. */
typedef struct sim_measurement {
	double transport_velocity, uncertainty; /* m/s */
	int steady;
	double periods;                         /* whole periods spanned */
	double rotor_speed_mean;                /* rad/s */
	double cpu_seconds;                     /* of this thread */
	double step_error;                      /* m/s, sim_status's */
	int tol_met;                            /* sim_status's */
	double dt;                              /* s: the machine step chosen */
	int substeps;                           /* feed sub-steps chosen */
	int refinements;                        /* runs repeated at finer steps */
} sim_measurement;

/* Create a fresh instance, run it to t_end (s) and fill *out (NaN fields
 * where undefined); msg as sim_new, or the failure's cause. Where the
 * steps are the engine's (dem, dt = 0 and substeps = 0) and the
 * uncertainty is beyond what m->tol allows because of the steps' error,
 * the run is repeated at finer steps (at most 3 times; *out says which
 * steps and how many repeats). Returns sim_new's or sim_advance's code.
 * v is smooth in the parameters (the window is fixed): for fits and their
 * bands' finite differences. For sweeps (thread-safe). */
int sim_measure(const sim_params *p, const sim_scene *s, const sim_method *m, double t_end,
		sim_measurement *out, char *msg, size_t msglen);
/* sim_measure, its settlings and runs stopped as sim_new_bounded's: SIM_ECPU. */
int sim_measure_bounded(const sim_params *p, const sim_scene *s, const sim_method *m,
			double t_end, double cpu_deadline, sim_measurement *out, char *msg,
			size_t msglen);
/* Simulated s sim_measure's first run integrates to t_end after its
 * settling, at most: the run and a shadow over the window's first part
 * (counted whole where one runs at about 0.8 of the run's cost, and where
 * none does: dem with fewer than 3 sub-steps, the other methods); the
 * refinements it may repeat at finer steps not counted. What a caller
 * estimates its cost from. */
double sim_measure_span(const sim_scene *s, double t_end);
/* A sweep's point: sim_measure, but where a shadow measures the step
 * error (dem with feed events) each run stops before t_end at the first
 * check after the shadow's window whose bar is within tol, steady, at most
 * a quarter scatter and 28 whole periods long (out->periods says how long
 * it measured), or whose step error alone is beyond tol; a refinement
 * starts from the first run's settled start and takes the run before it
 * as its shadow (its own shadow run afterwards only where that bar misses
 * tol), and one that can neither meet tol nor refine further stops at its
 * shadow's end where its scatter is small. About half the cost of
 * sim_measure at czubak2016's defaults; v then depends on where the run
 * stopped, a step in the parameters, so fits keep sim_measure. */
int sim_measure_point(const sim_params *p, const sim_scene *s, const sim_method *m, double t_end,
		      sim_measurement *out, char *msg, size_t msglen);

/* Feed geometry of the instance. */
/* Physical columns K and layers L; 0 without feed. */
int sim_columns(const sim *s);
int sim_layers(const sim *s);
/* Per column k: mean feed displacement xi_bar_k(t) - xi_bar_k(0), m.
 * out has sim_columns() entries. Zeros when there is no feed. */
void sim_column_displacement(const sim *s, double *out);
/* Deck points: out[2k], out[2k+1] = displacement (x, y) of column k's deck
 * point from its rest position, m. sim_columns() pairs. */
void sim_deck_points(const sim *s, double *out);
/* Feed elements: xi[k*L + j], eta[k*L + j] (layer j = 0 bottom), absolute, m.
 * Either may be NULL. */
void sim_feed_state(const sim *s, double *xi, double *eta);

#endif
