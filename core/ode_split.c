/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ode_split.c - split (multirate) method for the non-smooth feed, in the
 * manner of discrete-element codes coupled to a rigid machine:
 *
 *  1. the machine takes one classical RK4 macro step dt with the feed's
 *     reaction held at its mean over the previous macro step (a staggered,
 *     momentum-conserving coupling: every impulse the feed gives the deck
 *     reaches the machine, one macro step late);
 *  2. the feed takes `substeps` sub-steps along the deck motion, which is
 *     interpolated by cubic Hermite polynomials of the machine's start and
 *     end states; the sub-steps are staggered as leapfrog (impulse bounds
 *     from the compressions at a sub-step's start, velocities of its
 *     middle, positions advanced with those), and each solves the normal
 *     and Coulomb friction impulses of a column implicitly (an exact
 *     active-set solve of the layer chain), so sticking layers stick
 *     exactly and friction does not chatter (Moreau's velocity-level
 *     treatment of dry friction; see Acary & Brogliato, Numerical Methods
 *     for Nonsmooth Dynamical Systems, 2008, ch. 10);
 *
 *  3. with more than one sub-step, the machine's step is corrected for the
 *     feed's mean reaction of this very step (the difference to the held
 *     one, through the mass matrix; the feed is not stepped again), which
 *     removes most of the one-step lag. Like every partitioned coupling it
 *     suffers from added mass: with the feed heavier than about 30 % of the
 *     machine a perturbation grows by ~1.5 per step (measured), so the
 *     corrector is used only up to 20 % (MODEL_CORRECTOR_MAX_RATIO);
 *     heavier feeds keep the lagged coupling, which is stable.
 *
 * With feed_events (the default) two first-order errors of that scheme
 * are removed, which quarters the sub-steps the 1 % gate needs (a feed
 * step of 2.5e-4 s instead of 6.25e-5 s; the default is 5 of them per
 * 1.25e-3-s machine step):
 *
 *  - slip reversals inside a feed sub-step are located (feed.c,
 *    friction_events), not given the end's friction for the whole
 *    sub-step;
 *  - the deck yields to the feed's impulses within the machine's step:
 *    in step 2 the deck velocity the feed sees is moved, sub-step by
 *    sub-step, by the machine's inverse mass matrix at the deck points
 *    (its compliance, from the corrector's mass matrix of the step
 *    before) times the impulses the columns have given so far less what
 *    the held reaction accounts for (the interface Jacobian of
 *    partitioned fluid-structure coupling, e.g. Degroote, Bathe and
 *    Vierendeels, Computers & Structures 87, 2009). Without it the feed
 *    sees a deck that ignores the feed's own reaction until the
 *    corrector, which costs up to 1 % of v at a 1e-3-s step (20 deg cw).
 *
 * Without feed it is exactly RK4 on the machine. Its user-visible name is
 * "dem" (the `method` setting, kept for the API and the CLI); it is not the
 * LIGGGHTS coupling of dem/.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "feed.h"
#include "ode.h"

typedef struct split {
	int n, substeps, have_q;
	int nmodes; /* feed elements with a normal and a tangential mode each */
	int correct; /* corrector on: feed light enough (added mass) */
	double dt;
	double Qfeed[NQ_FULL];
	double *k1, *k2, *k3, *k4, *tmp;
	signed char *modes;
	double (*deck_pos)[2], (*deck_vel)[2]; /* the columns' deck tracks, per sub-step */
	double (*hermite)[4]; /* the tracks' cubic weights, per sub-step: positions, velocities */
	double (*cubic)[2][2]; /* the deck's cubics at x = 0 and per metre of x, per sub-step:
				* positions (substeps), velocities (substeps + 1) */
	double hermite_H;     /* ... for this step (0: none yet); they depend on it alone */
	int events;        /* slip reversals located inside the feed's sub-steps */
	int couple;        /* the deck yields to the feed's impulses within the step */
	int have_yield;    /* yield holds the step before's compliance and reaction */
	int K;             /* integrated columns */
	feed_yield *yield;
	/* the feed's kinetic and gravitational energy (J) at the last step's
	 * end, where have_feed_energy: the next step's start, since whoever
	 * places a state anew does so with a fresh workspace (as for Qfeed);
	 * forgotten on reset and load, and then computed again from y, to the
	 * same bits */
	int have_feed_energy;
	double feed_energy;
} split;

static void split_free(void *p)
{
	split *w = p;
	if (!w)
		return;
	free(w->k1);
	free(w->modes);
	free(w->deck_pos);
	free(w->hermite);
	free(w->cubic);
	free(w->yield);
	free(w);
}

static void *split_alloc(const model *md, const sim_method *cfg)
{
	split *w = calloc(1, sizeof *w);
	if (!w)
		return NULL;
	w->n = md->n;
	w->dt = cfg->dt;
	w->substeps = cfg->substeps > 0 ? cfg->substeps : 1;
	w->correct = w->substeps > 1 && md->sc.feed_coupling &&
		     model_feed_mass_ratio(&md->p, &md->sc) <= MODEL_CORRECTOR_MAX_RATIO;
	size_t nf = (size_t)(md->nf > 0 ? md->nf : 1);
	w->nmodes = (int)nf;
	w->k1 = calloc(5 * (size_t)md->n, sizeof(double));
	w->modes = calloc(2 * nf, 1);
	int K = md->dk.K > 0 ? md->dk.K : 1;
	w->K = md->dk.K;
	w->deck_pos = calloc((size_t)K * (2 * (size_t)w->substeps + 1), sizeof *w->deck_pos);
	w->hermite = calloc(2 * ((size_t)w->substeps + 1), sizeof *w->hermite);
	w->cubic = calloc(2 * (size_t)w->substeps + 1, sizeof *w->cubic);
	w->events = cfg->feed_events && md->nf > 0;
	w->couple = w->correct && w->events;
	if (w->couple)
		w->yield = calloc(1, sizeof *w->yield);
	if (!w->k1 || !w->modes || !w->deck_pos || !w->hermite || !w->cubic ||
	    (w->couple && !w->yield)) {
		split_free(w);
		return NULL;
	}
	w->k2 = w->k1 + md->n;
	w->k3 = w->k2 + md->n;
	w->k4 = w->k3 + md->n;
	w->tmp = w->k4 + md->n;
	w->deck_vel = w->deck_pos + (size_t)K * w->substeps;
	return w;
}

/* Machine entries of y: reduced positions, velocities, and the machine's
 * two energy accumulators. */
static void machine_axpy(const model *md, double *out, const double *y, double h,
			 const double *k)
{
	for (int r = 0; r < md->nq; r++) {
		out[r] = y[r] + h * k[r];
		out[md->npos + r] = y[md->npos + r] + h * k[md->npos + r];
	}
	for (int a = ACC_IN; a <= ACC_DAMP; a++)
		out[2 * md->npos + a] = y[2 * md->npos + a] + h * k[2 * md->npos + a];
}

/* ode_hermite's weights of p0, v0, p1, v1 at u over H (w[4])... */
static void hermite_weights(double u, double H, double w[4])
{
	double u2 = u * u, u3 = u2 * u;
	w[0] = 2 * u3 - 3 * u2 + 1;
	w[1] = (u3 - 2 * u2 + u) * H;
	w[2] = -2 * u3 + 3 * u2;
	w[3] = (u3 - u2) * H;
}

/* ... and its sum with them: ode_hermite (p0, v0, p1, v1, H, u) to the
 * last bit. */
static inline double hermite_sum(const double w[4], double p0, double v0, double p1, double v1)
{
	return w[0] * p0 + w[1] * v0 + w[2] * p1 + w[3] * v1;
}

/* One classical RK4 step of the machine's entries of y over H, with the
 * feed's reaction held at w->Qfeed; ev0 receives the start evaluation,
 * evm and ev3 (where not NULL) the third and the last stage's. */
static void machine_rk4(split *w, dyn *sys, double t, double H, double *y, model_eval *ev0,
			model_eval *evm, model_eval *ev3)
{
	const model *md = sys->md;
	/* tmp's machine entries only: the machine's evaluation reads no other */
	dyn_machine_rhs(sys, t, y, w->Qfeed, w->k1, ev0);
	machine_axpy(md, w->tmp, y, 0.5 * H, w->k1);
	dyn_machine_rhs(sys, t + 0.5 * H, w->tmp, w->Qfeed, w->k2, NULL);
	machine_axpy(md, w->tmp, y, 0.5 * H, w->k2);
	dyn_machine_rhs(sys, t + 0.5 * H, w->tmp, w->Qfeed, w->k3, evm);
	machine_axpy(md, w->tmp, y, H, w->k3);
	dyn_machine_rhs(sys, t + H, w->tmp, w->Qfeed, w->k4, ev3);
	for (int r = 0; r < md->nq; r++) {
		int v = md->npos + r;
		y[r] += H / 6.0 * (w->k1[r] + 2.0 * (w->k2[r] + w->k3[r]) + w->k4[r]);
		y[v] += H / 6.0 * (w->k1[v] + 2.0 * (w->k2[v] + w->k3[v]) + w->k4[v]);
	}
	for (int a = ACC_IN; a <= ACC_DAMP; a++) {
		int i = 2 * md->npos + a;
		y[i] += H / 6.0 * (w->k1[i] + 2.0 * (w->k2[i] + w->k3[i]) + w->k4[i]);
	}
}

/* 3. The corrector: the machine's step as if taken with the feed's
 * reaction of this very step. The reaction's change dQ enters the
 * machine's accelerations linearly, through M^-1 at the step's middle, so
 * the RK4 step taken again would differ by H^2/2 M^-1 dQ in the positions
 * and H M^-1 dQ in the rates, up to terms (omega H)^2 smaller (the
 * machine's frequencies omega <= 160 rad/s: 2.5 % of the correction at
 * 1e-3 s); the energy accumulators keep the predictor's values. M is the
 * one RK4's third stage formed (evm: at t + H/2 on y + H/2 k2, the step's
 * middle to O(H^2) like the mean of its ends), so the corrector costs
 * back-substitutions only: no configuration, mass matrix or factorisation
 * of its own. */
static void correct(split *w, const model *md, double H, double *y, const double Qold[NQ_FULL],
		    const model_eval *evm, const deck_rot *R1)
{
	double Q[4][NQ_FULL], a[4][NQ_FULL];
	for (int i = 0; i < NQ_FULL; i++)
		Q[0][i] = w->Qfeed[i] - Qold[i];
	/* with the deck yielding, the same mass matrix's response to unit
	 * forces on x, y (and alpha): the next step's compliance (the rows
	 * cleared one by one: a few vector stores, not a string instruction) */
	int nb = w->couple ? (md->alpha_fixed ? 2 : 3) : 0;
	for (int c = 0; c < nb; c++) {
		memset(Q[1 + c], 0, sizeof Q[1 + c]);
		Q[1 + c][c] = 1.0; /* Q_X, Q_Y, Q_ALPHA */
	}
	model_reduced_solves(md, (const double(*)[NQ_FULL])evm->M, 1 + nb,
			     (const double(*)[NQ_FULL])Q, a);
	for (int r = 0; r < md->nq; r++) {
		y[r] += 0.5 * H * H * a[0][r];
		y[md->npos + r] += H * a[0][r];
	}
	if (nb > 0)
		feed_yield_compliance(md, nb, (const double(*)[NQ_FULL])(a + 1), R1, w->yield);
}

/* The deck's motion over the step for the feed's sub-steps: each column's
 * deck point at the sub-steps' starts (w->deck_pos) and its velocity at
 * their middles (w->deck_vel), from the cubic Hermite of the step's ends
 * ev0, ev1; the end's rotation into *R1. */
static void deck_track(split *w, const model *md, double H, const model_eval *e_0,
		       const model_eval *e_1, deck_rot *R1_out)
{
	const int ns = w->substeps;
	const deck *dk = &md->dk;
	deck_rot R0 = e_0->R, R1 = w->events ? deck_rotation(e_1->q) : e_1->R;
	*R1_out = R1;
	/* the cubic's four weights at each sub-step's start (positions) and
	 * middle (velocities), the same for every column: ode_hermite's
	 * terms, operation for operation */
	double(*wp)[4] = w->hermite, (*wv)[4] = w->hermite + ns + 1;
	if (H != w->hermite_H) {
		for (int i = 0; i <= ns; i++) {
			hermite_weights((double)i / ns, H, wp[i]);
			hermite_weights(((double)i - 0.5) / ns, H, wv[i]);
		}
		w->hermite_H = H;
	}
	/* a deck point's data are affine in its body x (deck_point_affine),
	 * and so is their cubic: that of the point at x = 0 and that of the
	 * rate per metre of x give every column's, two cubics for any number
	 * of columns; where the deck does not turn the rate is (1, 0) in
	 * position and 0 in velocity throughout, and one cubic does */
	double e0[3][2][2], e1[3][2][2];
	deck_point_affine(dk, &R0, e_0->q, e_0->qd, e_0->qdd, e0);
	deck_point_affine(dk, &R1, e_1->q, e_1->qd, e_1->qdd, e1);
	const int turns = !md->alpha_fixed;
	double(*cp)[2][2] = w->cubic, (*cv)[2][2] = w->cubic + ns;
	for (int b = 0; b <= turns; b++)
		for (int i = 0; i <= ns; i++)
			for (int c = 0; c < 2; c++) {
				if (i < ns)
					cp[i][b][c] = hermite_sum(wp[i], e0[0][b][c], e0[1][b][c],
								  e1[0][b][c], e1[1][b][c]);
				cv[i][b][c] = hermite_sum(wv[i], e0[1][b][c], e0[2][b][c],
							  e1[1][b][c], e1[2][b][c]);
			}
	for (int k = 0; k < dk->K; k++) {
		const double d = dk->d[k];
		/* positions at the sub-steps' starts; velocities at their
		 * middles, vel[i + 1] for sub-step i and vel[0] for the one
		 * before the first (the cubic, half a sub-step outside) */
		double(*pos)[2] = w->deck_pos + (size_t)k * ns;
		double(*vel)[2] = w->deck_vel + (size_t)k * (ns + 1);
		for (int i = 0; i <= ns; i++) {
			if (i < ns) {
				pos[i][0] = cp[i][0][0] + d * (turns ? cp[i][1][0] : 1.0);
				pos[i][1] = cp[i][0][1] + (turns ? d * cp[i][1][1] : 0.0);
			}
			vel[i][0] = cv[i][0][0] + (turns ? d * cv[i][1][0] : 0.0);
			vel[i][1] = cv[i][0][1] + (turns ? d * cv[i][1][1] : 0.0);
		}
	}
}

/* The feed's sub-steps along the tracked deck (feed_dem_step): the
 * impulses over the step as forces F, the work and the energy they moved
 * booked in y's accumulators (docs/energy.md). */
static void feed_substeps(split *w, const model *md, double H, double *y,
			  double F[SIM_MAX_COLUMNS][2])
{
	const int ns = w->substeps;
	const double h = H / ns;
	const deck *dk = &md->dk;
	double impulse[SIM_MAX_COLUMNS][2];
	feed_work work = {0.0, 0.0, 0.0};
	double kin, pot, before = w->feed_energy;
	if (!w->have_feed_energy) {
		feed_energy(md, y, &kin, &pot);
		before = kin + pot;
	}
	feed_dem_step(md, y, ns, h, (const double(*)[2])w->deck_pos,
		      (const double(*)[2])w->deck_vel, w->events,
		      w->couple && w->have_yield ? w->yield : NULL, w->modes, impulse, &work);
	for (int k = 0; k < dk->K; k++) {
		F[k][0] = impulse[k][0] / H;
		F[k][1] = impulse[k][1] / H;
	}
	/* the energy the feed's sub-steps moved (docs/energy.md) */
	feed_energy(md, y, &kin, &pot);
	w->feed_energy = kin + pot;
	w->have_feed_energy = 1;
	double *acc = y + 2 * md->npos;
	acc[ACC_FRIC] += md->col_weight * work.friction;
	acc[ACC_CONTACT] += md->col_weight * work.contact;
	acc[ACC_DECK] += md->col_weight * work.deck;
	acc[ACC_FEED] += w->feed_energy - before;
}

/* The feed's reaction on the machine for the next step (w->Qfeed, from
 * the forces F at the end's rotation R1), the corrector, and what the
 * deck yields to (w->yield). */
static void feed_reaction(split *w, const model *md, double H, double *y,
			  double F[SIM_MAX_COLUMNS][2], const model_eval *evm, const deck_rot *R1)
{
	const deck *dk = &md->dk;
	double Qold[NQ_FULL];
	memcpy(Qold, w->Qfeed, sizeof Qold);
	memset(w->Qfeed, 0, sizeof w->Qfeed);
	if (md->sc.feed_coupling)
		deck_forces(dk, R1, (const double(*)[2])F, md->col_weight, w->Qfeed);
	if (w->correct)
		correct(w, md, H, y, Qold, evm, R1);
	if (w->couple) {
		for (int k = 0; k < dk->K; k++)
			for (int c = 0; c < 2; c++)
				w->yield->F[k][c] = md->sc.feed_coupling ? F[k][c] : 0.0;
		w->have_yield = 1;
	}
}

static int split_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	split *w = p;
	const model *md = sys->md;
	double H = ode_fixed_step(*t, w->dt, t_max);
	if (md->nf > 0 && !w->have_q) {
		/* first step: the feed's reaction from the smooth law now */
		memset(w->Qfeed, 0, sizeof w->Qfeed);
		dynamics_feed_reaction(md, sys->ctl, *t, y, w->tmp, w->Qfeed);
		w->have_q = 1;
	}
	/* 1. machine RK4 with the feed force held */
	model_eval ev0, evm, ev1;
	machine_rk4(w, sys, *t, H, y, &ev0, w->correct ? &evm : NULL, w->events ? &ev1 : NULL);
	double t1 = (H == t_max - *t) ? t_max : *t + H;
	if (md->nf == 0) {
		*t = t1;
		return SIM_OK;
	}
	/* 2. the feed along the interpolated deck motion (the machine's end
	 * acceleration completes the deck velocity's interpolant), staggered
	 * as leapfrog: a sub-step's impulses come from the compressions at
	 * its start, and the velocities it solves for are those of its middle
	 * (against the deck's velocity there), with which the positions
	 * advance. Free flight is then exact, and a layer riding on the deck
	 * follows the deck's displacement to O(h^3) per sub-step instead of
	 * drifting by h^2 a / 2 (which moved lift-off by O(h)). */
	if (w->events) {
		/* the end's accelerations from RK4's last stage (at t1, on the
		 * state y + H k3): they enter the deck velocity's cubic only,
		 * whose error is O(H^4) either way; the end's positions and
		 * velocities are the step's own */
		model_full_coords(md, sys->ctl, t1, y, ev1.q, ev1.qd);
	} else {
		dyn_machine_rhs(sys, t1, y, w->Qfeed, w->k4, &ev1);
	}
	deck_rot R1;
	double F[SIM_MAX_COLUMNS][2];
	deck_track(w, md, H, &ev0, &ev1, &R1);
	feed_substeps(w, md, H, y, F);
	feed_reaction(w, md, H, y, F, &evm, &R1);
	*t = t1;
	return SIM_OK;
}

static void split_reset(void *p)
{
	split *w = p;
	w->have_feed_energy = 0;
}

/* Carried between steps: the held reaction, the contacts' modes and, with
 * the deck yielding, its compliance and the held reaction of the K
 * integrated columns. */
static size_t yield_size(const split *w)
{
	size_t K = (size_t)w->K;
	return w->couple ? sizeof w->have_yield + sizeof w->yield->nb + K * sizeof w->yield->T[0] +
				   K * sizeof w->yield->Rd[0] + K * sizeof w->yield->F[0]
			 : 0;
}

static size_t split_state_size(const void *p)
{
	const split *w = p;
	return sizeof w->have_q + sizeof w->Qfeed + 2 * (size_t)w->nmodes + yield_size(w);
}

/* One field of the carried state, n bytes, into the buffer (save) or out
 * of it; *b moves past it. */
static void carry(char **b, void *field, size_t n, int save)
{
	if (save)
		memcpy(*b, field, n);
	else
		memcpy(field, *b, n);
	*b += n;
}

/* The carried state in split_state_size's order, saved into buf or loaded
 * from it (saving only reads w). */
static void carry_state(split *w, char *buf, int save)
{
	char *b = buf;
	carry(&b, &w->have_q, sizeof w->have_q, save);
	carry(&b, w->Qfeed, sizeof w->Qfeed, save);
	carry(&b, w->modes, 2 * (size_t)w->nmodes, save);
	if (!w->couple)
		return;
	carry(&b, &w->have_yield, sizeof w->have_yield, save);
	carry(&b, &w->yield->nb, sizeof w->yield->nb, save);
	carry(&b, w->yield->T, (size_t)w->K * sizeof w->yield->T[0], save);
	carry(&b, w->yield->Rd, (size_t)w->K * sizeof w->yield->Rd[0], save);
	carry(&b, w->yield->F, (size_t)w->K * sizeof w->yield->F[0], save);
}

static void split_save(const void *p, void *buf)
{
	carry_state((split *)p, buf, 1);
}

static void split_load(void *p, const void *buf)
{
	carry_state(p, (char *)buf, 0);
	split_reset(p);
}

const ode_method ode_split = {
	.info = {.name = "dem",
		 .order = 1,
		 .adaptive = 0,
		 .real_limit = RK4_REAL_LIMIT,
		 .radius_limit = RK4_RADIUS_LIMIT,
		 .doc = "machine RK4 macro step dt, feed sub-stepped with implicit Coulomb friction",
		 .substeps = 1,
		 .shadow = 1,
		 .dt_feed = 0, /* from the scene's time scales */
		 .dt_free = 0,
		 .cost = 1},
	.dense = 0,
	.alloc = split_alloc,
	.step = split_step,
	.interpolate = NULL,
	.reset = split_reset,
	.free = split_free,
	.state_size = split_state_size,
	.save = split_save,
	.load = split_load,
};
