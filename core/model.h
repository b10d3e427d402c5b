/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * model.h - internal: the machine of docs/MODEL.md (trough, vibrator, two
 * eliminators on guides at beta(t), suspension, drive) and the layout of
 * the state vector y that the integrators advance:
 *
 *   y = [ q_r (nq) | xi (nf) | eta (nf) |  q_r' (nq) | xi' (nf) | eta' (nf) | acc (ACC_N) ]
 *        \______________ npos _______/     \_______________ npos ______/
 *
 * q_r are the integrated machine coordinates; the full q = (x, y, alpha,
 * phi, s1, s2) is q = T q_r + q_p(t) (T selects/combines, q_p holds the
 * prescribed motions: alpha = 0 in the symmetric reduction, phi = alpha +
 * psi(t) for the ideal drive). acc are energy accumulators integrated with
 * the state.
 *
 * Like MuJoCo's const mjModel beside mjData, what never changes during a
 * run (parameters, scene, geometry, reduced layout, preload: `model`,
 * const after model_init) is apart from what does (the controls:
 * `model_ctl`). The machine knows nothing of the feed: its reaction comes
 * in as a generalized force (dynamics.c couples the two). Not part of the
 * public interface.
 */
#ifndef CONVSIM_MODEL_H
#define CONVSIM_MODEL_H

#include "deck.h"
#include "ramp.h"
#include "params.h"

/* Energy accumulators (J): the drive's input, the machine's damping, the
 * feed's friction and contact work; with dem only (else zero), the feed's
 * energy change and the deck's work on the feed (docs/energy.md). */
enum { ACC_IN, ACC_DAMP, ACC_FRIC, ACC_CONTACT, ACC_FEED, ACC_DECK, ACC_N };

/* The solve's layouts (model_solve.c): general, or the trough's
 * coordinates first (x, y, alpha, or x, y with alpha fixed) and the point
 * masses' own ones (phi, s1, s2) after them. */
enum { MODEL_LAYOUT_GENERAL, MODEL_LAYOUT_TROUGH3, MODEL_LAYOUT_TROUGH2 };

/* Constant during a run. */
/* A periodic motion of the trough's x, y (m) and alpha (rad): the mean,
 * cos and sin parts of each in the rotor's phase theta = sense (phi -
 * alpha - psi0), first harmonic only; sense 0: none. */
typedef struct trough_orbit {
	double xya[3][3];
	double psi0;
	int sense;
} trough_orbit;

typedef struct model {
	sim_params p;
	sim_scene sc;
	unsigned reductions;
	/* reduced machine coordinates */
	int nq;
	double T[NQ_FULL][NQ_FULL];  /* T[i][r]: d q_i / d q_r (0 or 1) */
	int ncol[NQ_FULL];            /* full coordinates that reduced r moves */
	int col[NQ_FULL][2];          /* ... and which (at most two) */
	int alpha_fixed, phi_prescribed;
	/* the solve's layout (model_solve_layout): the reduced coordinates of
	 * the trough (x, y, alpha), and the inverse constant inertia of each
	 * point mass's own coordinate (phi, s1, s2; 0 for the trough's) */
	int n_body, body[3];
	int selection;                /* each reduced coordinate one full one, none prescribed */
	int sel[NQ_FULL];             /* ... and then each full one's reduced one, -1 for none */
	int layout;                   /* MODEL_LAYOUT_*: a solve of constant sizes, or the general */
	double own_inv[NQ_FULL];
	double own_m[NQ_FULL];        /* ... and that inertia, by full coordinate */
	/* feed */
	int L, nf;                    /* layers, integrated elements */
	double col_weight;            /* how many physical columns one stands for */
	deck dk;                      /* integrated columns (dk.K) and their deck points */
	/* layout */
	int npos, n;
	/* preload of the suspension (vertical, N) at P1 and P2 */
	double F0[2];
	/* the `steady` start's settling: the damping it adds per spring set
	 * in x and y (N s/m; the trough's critical damping on its
	 * suspension), relative to the forced response's motion
	 * (dynamics_steady_start sets it) */
	double settle_damping[2];
	trough_orbit settle_orbit;
} model;

/* The controls: changed between steps by sim_set_* (SI units). */
typedef struct model_ctl {
	ramp beta_ramp;               /* beta, rad */
	ramp psi_ramp;                /* ideal drive: phi - alpha, rad */
	double beta_rate;             /* rad/s, slew rate of the next beta ramp */
	int rotation;                 /* SIM_CW / SIM_CCW */
	double omega_ss;              /* rad/s */
	int drive_on;
	/* the `steady` start's settling (sim.c): before t = 0 the suspension
	 * carries settle_b (0 or 1) times model.settle_damping more damping,
	 * faded out to none over [settle_t0, 0] */
	double settle_b, settle_t0;
	/* an external feed's load on the deck (sim_set_deck_load): fx, fy (N)
	 * at the centre deck point, moment (N m) about it; zero for the
	 * column model */
	double deck_load[3];
} model_ctl;

/* Everything an evaluation yields besides dy. */
typedef struct model_eval {
	double q[NQ_FULL], qd[NQ_FULL], qdd[NQ_FULL];
	double beta, beta_dot;
	double torque;        /* N m on the rotor (motor, or ideal drive's) */
	double rotor_speed;   /* phi' - alpha' */
	deck_rot R;           /* R(alpha), deck_rotation(q) */
	double M[NQ_FULL][NQ_FULL]; /* the mass matrix as the layout's solve reads it (lower half;
				     * both for the general layout; model.c, trough2_held) */
} model_eval;

/* 1 when the machine is symmetric about the vertical through G: h = 0,
 * l1 = l2, the axle at G, the eliminators mirror images of each other
 * (mass, spring, damper, guide point); what the symmetric_alpha reduction
 * needs (the columns are mirrored by construction). setup.c */
int model_machine_symmetric(const sim_params *p);

/* The feed's mass over the machine's (trough, vibrator and eliminator
 * masses): the added-mass ratio of the machine-feed coupling. */
double model_feed_mass_ratio(const sim_params *p, const sim_scene *sc);
/* Add each reduced coordinate's value qr[r] (a position, rate or
 * acceleration) to the full coordinates it moves: full[i] += qr[r]. */
static inline void model_add_reduced(const model *md, const double *qr, double full[NQ_FULL])
{
	for (int r = 0; r < md->nq; r++)
		for (int a = 0; a < md->ncol[r]; a++)
			full[md->col[r][a]] += qr[r];
}

/* The full coordinates of the reduced values qr: zero plus
 * model_add_reduced, to the same bits (the reduced scene's layout with its
 * indices as constants). model.c */
void model_reduced_to_full(const model *md, const double *qr, double full[NQ_FULL]);

/* Largest ratio for which dem corrects its coupling (docs/integrators.md "Integrators"). */
#define MODEL_CORRECTOR_MAX_RATIO 0.2

/* The decay rate (1/s) of the Kloss motor's slip mode, the machine's
 * stiffest: a change of the rotor's relative speed omega relaxes at
 * lambda = |dM/domega| e^T M^-1 e, with |dM/domega| the drive's steepest
 * slope (the Kloss curve's at zero slip, 2 M_ut / slip_ut, plus the
 * bearing drag's 2 b_phi omega_ss) and e^T M^-1 e the inverse inertia
 * that a torque on phi against alpha meets (the largest over the
 * rotor's angle and over beta). 0 under the ideal drive. setup.c */
double model_slip_rate(const sim_params *p, const sim_scene *sc);

/* The largest |lambda| (1/s) of the machine's linear modes about rest
 * (the springs and dampers of suspension and eliminators over the masses
 * they move, the settling's damper included; the feed and the motor's
 * slip apart): the spectral radius of the Jacobian of model_machine_rhs,
 * the largest over beta and over the rotor's angle as model_slip_rate.
 * czubak2016: about the eliminators' 157 rad/s. setup.c */
double model_machine_rate(const sim_params *p, const sim_scene *sc);

/* Build the reduced model (with its suspension preload) and the initial
 * controls from parameters and scene (validated already). setup.c */
void model_init(model *md, model_ctl *ctl, const sim_params *p, const sim_scene *sc);

/* Fill the solve's layout (n_body, body, own_inv, own_m) from nq, ncol,
 * col and the parameters; model_init calls it, and so must whoever changes
 * those. model_solve.c */
void model_solve_layout(model *md);

/* Solve the reduced system T^t M T qr'' = T^t (rhs - M qp'') (M: symmetric,
 * both halves filled; qp'': the prescribed accelerations) for qr'' into
 * br (NaN if M is not positive definite). model_solve.c */
void model_reduced_solve(const model *md, const double M[NQ_FULL][NQ_FULL],
			 const double rhs[NQ_FULL], const double qpdd[NQ_FULL], double br[NQ_FULL]);

/* The same without prescribed accelerations for nrhs right-hand sides
 * rhs[i] into br[i], sharing one factorisation where the layout allows
 * (the results are model_reduced_solve's to the last bit). model_solve.c */
void model_reduced_solves(const model *md, const double M[NQ_FULL][NQ_FULL], int nrhs,
			  const double (*rhs)[NQ_FULL], double (*br)[NQ_FULL]);

/* Static strokes s1, s2 (m) of the eliminators at rest at the initial
 * beta (written). setup.c */
void model_static_strokes(const sim_params *p, double s[2]);

/* m: how far a column's top element rests below its deck point under the
 * column's weight (each contact carries the elements above it: the sum of
 * (i m_n g / k_c)^(1/p) over i = 1..layers); 0 without feed. Where it
 * reaches MODEL_SAG_MAX, the feed's divergence guard (sim_check.h: an
 * element 5 cm into the deck) trips at rest: sim_validate refuses k_c
 * below sim_k_c_least, the stiffness at which it would. setup.c */
#define MODEL_SAG_MAX 0.05
/* m: the eliminators' largest stroke (sim_check.h's guard). At rest an
 * eliminator i sits m_i g cos(beta) / k_si down its guide: sim_validate
 * refuses a spring on which it would sit that far at beta = 0 or 180 deg
 * (any beta a session may be turned to), sim_k_s_least the least one. */
#define MODEL_STROKE_MAX 1.0
double model_column_sag(const sim_params *p, const sim_scene *sc);

/* Full coordinates from y at time t. */
void model_full_coords(const model *md, const model_ctl *ctl, double t, const double *y,
		       double q[NQ_FULL], double qd[NQ_FULL]);

/* Machine part of dy = f(t, y) (positions' rates, accelerations and the
 * ACC_IN/ACC_DAMP powers) with the feed's reaction given as the generalized
 * force Qfeed (NULL: none). ev may be NULL. Never allocates, counts nothing. */
void model_machine_rhs(const model *md, const model_ctl *ctl, double t, const double *y,
		       const double Qfeed[NQ_FULL], double *dy, model_eval *ev);

/* The reduced accelerations (qrdd, nq values) that the generalized force Q
 * alone gives the machine in state y at t: (T^t M T)^-1 T^t Q. */
void model_force_response(const model *md, const model_ctl *ctl, double t, const double *y,
			  const double Q[NQ_FULL], double *qrdd);
/* Kinetic and potential energy (J) of the machine alone in state y at t
 * (written); the potential includes gravity, springs and preload. */
void model_machine_energy(const model *md, const model_ctl *ctl, double t, const double *y,
			  double *kinetic, double *potential);

#endif
