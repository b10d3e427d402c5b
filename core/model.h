/*
 * model.h - internal: the equations of motion of the conveyor (MODEL.md).
 *
 * The model owns the parameters, the scene after reduction, the control
 * ramps and the layout of the state vector y that the integrators advance:
 *
 *   y = [ q_r (nq) | xi (nf) | eta (nf) |  q_r' (nq) | xi' (nf) | eta' (nf) | acc (ACC_N) ]
 *        \______________ npos _______/     \_______________ npos ______/
 *
 * q_r are the integrated machine coordinates; the full q = (x, y, alpha,
 * phi, s1, s2) is q = T q_r + q_p(t) (T selects/combines, q_p holds the
 * prescribed motions: alpha = 0 in the symmetric reduction, phi = alpha +
 * psi(t) for the ideal drive). acc are energy accumulators integrated with
 * the state. Not part of the public interface.
 */
#ifndef CONVSIM_MODEL_H
#define CONVSIM_MODEL_H

#include <math.h>

#include "sim.h"

enum { Q_X, Q_Y, Q_ALPHA, Q_PHI, Q_S1, Q_S2, NQ_FULL };
enum { ACC_IN, ACC_DAMP, ACC_FRIC, ACC_CONTACT, ACC_N };

/* A C1 motion with piecewise-constant second derivative: segments that
 * start at ts[i] with value b[i], rate v[i], and constant acceleration a[i];
 * after the last segment the motion continues at rate v_end from b_end. */
typedef struct ramp {
	int n;
	double ts[4], b[4], v[4], a[4];
	double t_end, b_end, v_end;
} ramp;

void ramp_hold(ramp *r, double t, double value, double rate);
void ramp_eval(const ramp *r, double t, double *b, double *bd, double *bdd);
/* Time-optimal move from the state at t to rest at target, |rate| <= vmax,
 * |accel| <= amax. */
void ramp_to_position(ramp *r, double t, double target, double vmax, double amax);
/* Change the rate to v_target at |accel| = amax, then keep it. */
void ramp_to_rate(ramp *r, double t, double v_target, double amax);

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
	/* feed */
	int K, L, nf;                 /* integrated columns, layers, elements */
	double col_weight;            /* how many physical columns one stands for */
	double d[64];                 /* body x of each integrated column */
	/* layout */
	int npos, n;
	/* preload of the suspension (vertical, N) at P1 and P2 */
	double F0[2];
	/* controls */
	ramp beta_ramp;               /* beta, rad */
	ramp psi_ramp;                /* ideal drive: phi - alpha, rad */
	int rotation;                 /* SIM_CW / SIM_CCW */
	double omega_ss;
	int drive_on;
	uint64_t rhs_evals;
} model;

/* Everything a full evaluation yields besides dy. */
typedef struct model_eval {
	double q[NQ_FULL], qd[NQ_FULL], qdd[NQ_FULL];
	double beta, beta_dot;
	double torque;        /* N m on the rotor (motor, or ideal drive's) */
	double rotor_speed;   /* phi' - alpha' */
	double deck[2], deck_vel[2]; /* centre deck point displacement */
} model_eval;

/* The feed's mass over the machine's (trough, vibrator and eliminator
 * masses): the added-mass ratio of the machine-feed coupling. */
double model_feed_mass_ratio(const sim_params *p, const sim_scene *sc);
/* Largest ratio for which dem corrects its coupling (README "dem"). */
#define MODEL_CORRECTOR_MAX_RATIO 0.2

/* Build the reduced model from parameters and scene (validated already). */
void model_init(model *md, const sim_params *p, const sim_scene *sc);
/* Fill y (length md->n) with the static equilibrium with the feed settled. */
void model_equilibrium(model *md, double *y);

/* dy = f(t, y). ev may be NULL. Never allocates. */
void model_rhs(model *md, double t, const double *y, double *dy, model_eval *ev);

/* Pieces for split (multirate) methods.
 * model_machine_rhs: machine part of dy only (positions, velocities and
 * ACC_IN/ACC_DAMP), with the feed replaced by the generalized force Qfeed. */
void model_machine_rhs(model *md, double t, const double *y, const double Qfeed[NQ_FULL],
		       double *dy, model_eval *ev);
/* The trough's rotation R(alpha) of a machine state, computed once and
 * passed to the deck-point functions. */
typedef struct model_rot {
	double c, s;
} model_rot;
static inline model_rot model_rotation(const double q[NQ_FULL])
{
	model_rot r = {1.0, 0.0};
	if (q[2] != 0.0) {
		r.c = cos(q[2]);
		r.s = sin(q[2]);
	}
	return r;
}
/* Deck point kinematics of integrated column k for a machine state. */
void model_deck(const model *md, int k, const model_rot *R, const double q[NQ_FULL],
		const double qd[NQ_FULL], double pos[2], double vel[2]);
/* Add to Q the generalized force of the forces F[k] (N) at every integrated
 * column's deck point, times scale. Mirrored columns k and K-1-k are
 * summed together first, so that the moments of a symmetric motion cancel
 * exactly despite round-off. */
void model_deck_forces(const model *md, const model_rot *R, const double (*F)[2],
		       double scale, double Q[NQ_FULL]);
/* Full coordinates from y at time t. */
void model_full_coords(const model *md, double t, const double *y, double q[NQ_FULL],
		       double qd[NQ_FULL]);

/* Normal contact force of the paper's law (eq. 7) for compression delta > 0
 * and its rate: loading k delta^p for rate >= 0, unloading R^2 k delta^p. */
double model_contact_force(const model *md, double delta, double delta_dot);

/* Stored energy (kinetic + potential) of the state; contact work and the
 * other accumulators are in y. */
double model_energy_stored(model *md, double t, const double *y, double *kinetic,
			   double *potential);

#endif
