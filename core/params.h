/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * params.h - what an instance is made from: the physical parameters, the
 * scene (and the model reductions it allows) and the integrator choice
 * (docs/MODEL.md names, SI, angles in radians), and an integrator's
 * description. Part of the public interface (sim.h includes it); the
 * model's own headers (model.h, deck.h, ode.h through them) include this
 * one instead of sim.h.
 */
#ifndef CONVSIM_PARAMS_H
#define CONVSIM_PARAMS_H

#include <stddef.h>

/* Largest feed: columns K and layers L (settings table and array sizes). */
#define SIM_MAX_COLUMNS 64
#define SIM_MAX_LAYERS 64

/* Rotation sense of the unbalanced mass in the paper's words (docs/MODEL.md
 * "Rotation sense"): its clockwise is phi' > 0 in the model's axes
 * (clockwise seen from behind the drawing), its counter-clockwise phi' < 0.
 * The value is the sign of phi'. */
enum { SIM_CW = 1, SIM_CCW = -1 };
enum { SIM_DRIVE_MOTOR = 0, SIM_DRIVE_IDEAL = 1 };
enum { SIM_FRICTION_COULOMB = 0, SIM_FRICTION_REGULARISED = 1 };
/* How an instance starts (docs/MODEL.md "Start"): `rest`, the paper's run-up
 * from static equilibrium with the motor switched on at t = 0; `steady`,
 * the machine on its periodic forced response at the loaded motor speed
 * with the feed settled on the moving deck. */
enum { SIM_START_REST = 0, SIM_START_STEADY = 1 };
/* What carries the feed (scene setting `feed_model`): the paper's columns
 * of layers, integrated by the core; or a bed outside the core (the
 * setting's choice `liggghts`: dem/ couples a LIGGGHTS bed), which the
 * core sees only as a load on the deck that its caller sets each step
 * (sim_set_deck_load): no feed coordinates, the feed's weight on the deck
 * at the start. */
enum { SIM_FEED_COLUMN = 0, SIM_FEED_EXTERNAL = 1 };
/* The setting's third choice, `auto`: a request, never a running model.
 * The caller resolves it to one of the two (sim_feed_pick) before an
 * instance is made; sim_new refuses it. */
enum { SIM_FEED_AUTO = 2 };

/* Physical parameters, docs/MODEL.md names, SI (angles in radians). */
typedef struct sim_params {
	/* suspension */
	double l1, l2, h;         /* m: spring sets at (l1,-h), (-l2,-h) */
	double k_x, k_y;          /* N/m per spring set */
	double b_x, b_y;          /* N s/m per spring set */
	/* trough */
	double M_r, J_r;          /* kg, kg m^2 */
	/* vibrator */
	double m, e, J_w;         /* kg, m, kg m^2 */
	double w_x, w_y;          /* m: axle, body frame */
	double b_phi;             /* N m s^2: bearing drag b_phi*w|w| */
	double M_load;            /* N m: load torque on the rotor against its
				     turning (near standstill the motor's slip
				     slope times the speed: core/model.c) */
	/* motor (Kloss) */
	double M_ut;              /* N m breakdown torque */
	double omega_ss;          /* rad/s synchronous speed (>0) */
	double slip_ut;           /* rad/s omega_ss - omega_ut */
	int rotation;             /* SIM_CW or SIM_CCW */
	/* eliminators */
	double m1, m2;            /* kg */
	double k_s1, k_s2;        /* N/m */
	double b_s1, b_s2;        /* N s/m */
	double p1_x, p1_y, p2_x, p2_y; /* m guide points, body frame */
	double c;                 /* m offset of the mass along the guide */
	double beta;              /* rad, initial guide angle */
	double beta_rate;         /* rad/s slew rate of beta ramps */
	double beta_accel;        /* rad/s^2 bound on beta'' in ramps */
	/* feed */
	double m_n;               /* kg per element */
	double k_c;               /* contact stiffness k, N/m^p */
	double p;                 /* contact exponent */
	double R;                 /* restitution coefficient */
	double mu;                /* friction coefficient */
	double h_d;               /* m deck height above G */
	double column_span;       /* m columns at d_k evenly in [-span, span] */
	/* environment */
	double g;                 /* m/s^2 */
	double drive_accel;       /* rad/s^2 speed ramp of the ideal drive */
} sim_params;

/* Scene: what the user needs; the engine builds the cheapest model for it. */
typedef struct sim_scene {
	int feed;             /* 0: no feed degrees of freedom */
	int columns, layers;  /* K, L */
	int drive;            /* SIM_DRIVE_MOTOR (Kloss) or SIM_DRIVE_IDEAL */
	int trough_rotation;  /* 1: integrate alpha even on a symmetric machine;
				 0: the engine drops it there by itself */
	int mirror;           /* 1: sweeps derive (ccw, pi - beta) from (cw,
				 beta) where the machine allows it
				 (sim_mirror_plan); 0: every point is run */
	int feed_coupling;    /* 0: one-way (feed does not act on the trough) */
	int friction;         /* SIM_FRICTION_* */
	double friction_eps;  /* m/s, regularised friction width */
	int motor_on;         /* drive on at t = 0 */
	float model_tol;      /* m/s: feed_model auto's bound on the model error
				 (sim_feed_pick), 0 none; a float in motor_on's
				 padding, so the struct's size and offsets stay */
	double transient;     /* s: transport velocity ignores t < transient */
	int start;            /* SIM_START_REST or SIM_START_STEADY */
	int feed_model;       /* SIM_FEED_COLUMN or SIM_FEED_EXTERNAL (in start's
				 padding: the struct's size and the offsets after
				 it stay, and a zeroed old record reads column) */
	double settle;        /* s: `steady` start's settling before t = 0 */
} sim_scene;

/* The model reductions a scene may allow, as bits (sim_reduction_name). */
enum {
	SIM_RED_NO_FEED = 1 << 0,
	SIM_RED_SYMMETRIC = 1 << 1,
	SIM_RED_IDEAL_DRIVE = 1 << 2,
	SIM_RED_ONE_WAY = 1 << 3,
	SIM_RED_MIRROR = 1 << 4, /* of a sweep, never of an instance */
};

/* Integrator choice. dt: fixed step (or macro step) in s, 0 for the
 * default of the scene kind (sim_default_dt); rtol/atol for adaptive
 * methods; substeps: feed sub-steps per macro step (method "dem"), 0 for
 * sim_default_substeps(); feed_events (dem): slip reversals located inside
 * the feed's sub-steps and the deck yielding to the feed within the
 * machine's step (0: the former dem). */
typedef struct sim_method {
	char name[24];
	double dt;
	double rtol, atol;
	int substeps;
	int feed_events;
	double tol;   /* accuracy target of v (docs/MODEL.md's convention):
			 the default steps scale with it and sim_measure
			 refines until the estimated step error is within it */
} sim_method;

/* The fewest feed sub-steps a shadow runs beside (at half of them). */
#define SIM_SHADOW_SUBSTEPS 3
/* One integrator as its descriptor describes it (sim_methods lists them). */
typedef struct sim_method_info {
	const char *name;
	int order;        /* classical order on smooth problems */
	int adaptive;     /* 1 if rtol/atol drive the step */
	/* fixed-step methods: the largest h lambda for which a decaying mode
	 * y' = -lambda y stays bounded (the stability region's reach along
	 * the negative real axis); 0 for the adaptive ones */
	double real_limit;
	/* ... and the largest h |lambda| for which every mode of a linear
	 * damped oscillator (lambda its eigenvalue, any damping) stays
	 * bounded; 0 for the adaptive ones */
	double radius_limit;
	const char *doc;
	/* What the method can do; generic code asks these, never its name. */
	int substeps; /* steps the feed apart in sub-steps of the machine step
			 (sim_method.substeps): its energy is booked apart, its
			 step error modelled, the symmetric machine settles reduced */
	int shadow;   /* a shadow run at half the sub-steps measures the feed
			 step's error (shadow.c), from SIM_SHADOW_SUBSTEPS up */
	double dt_feed, dt_free; /* the default step with a feed and without,
				    s; 0: from the scene's time scales
				    (sim_default_dt), refined by sim_measure
				    until tol holds */
	double cost;  /* right-hand sides a step relative to RK4's four (the
			 daemon's CPU estimate) */
} sim_method_info;

#endif
