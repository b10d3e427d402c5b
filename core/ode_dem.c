/*
 * ode_dem.c - split (multirate) method for the non-smooth feed, in the
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
 * Without feed it is exactly RK4 on the machine.
 */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "feed.h"
#include "ode.h"

typedef struct dem {
	int n, substeps, have_q;
	int nmodes; /* feed elements with a normal and a tangential mode each */
	int correct; /* corrector on: feed light enough (added mass) */
	double dt;
	double Qfeed[NQ_FULL];
	double *k1, *k2, *k3, *k4, *tmp, *save;
	signed char *modes;
	double (*deck_pos)[2], (*deck_vel)[2]; /* a column's deck track, per sub-step */
} dem;

static void dem_free(void *p)
{
	dem *w = p;
	if (!w)
		return;
	free(w->k1);
	free(w->modes);
	free(w->deck_pos);
	free(w);
}

static void *dem_alloc(const model *md, const sim_method *cfg)
{
	dem *w = calloc(1, sizeof *w);
	if (!w)
		return NULL;
	w->n = md->n;
	w->dt = cfg->dt;
	w->substeps = cfg->substeps > 0 ? cfg->substeps : 1;
	w->correct = w->substeps > 1 && md->sc.feed_coupling &&
		     model_feed_mass_ratio(&md->p, &md->sc) <= MODEL_CORRECTOR_MAX_RATIO;
	size_t nf = (size_t)(md->nf > 0 ? md->nf : 1);
	w->nmodes = (int)nf;
	w->k1 = calloc(6 * (size_t)md->n, sizeof(double));
	w->modes = calloc(2 * nf, 1);
	w->deck_pos = calloc(2 * (size_t)w->substeps, sizeof *w->deck_pos);
	if (!w->k1 || !w->modes || !w->deck_pos) {
		dem_free(w);
		return NULL;
	}
	w->k2 = w->k1 + md->n;
	w->k3 = w->k2 + md->n;
	w->k4 = w->k3 + md->n;
	w->tmp = w->k4 + md->n;
	w->save = w->tmp + md->n;
	w->deck_vel = w->deck_pos + w->substeps;
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

/* One classical RK4 step of the machine's entries of y over H, with the
 * feed's reaction held at w->Qfeed; ev0 receives the start evaluation. */
static void machine_rk4(dem *w, dyn *sys, double t, double H, double *y, model_eval *ev0)
{
	const model *md = sys->md;
	memcpy(w->tmp, y, sizeof(double) * (size_t)w->n);
	dyn_machine_rhs(sys, t, y, w->Qfeed, w->k1, ev0);
	machine_axpy(md, w->tmp, y, 0.5 * H, w->k1);
	dyn_machine_rhs(sys, t + 0.5 * H, w->tmp, w->Qfeed, w->k2, NULL);
	machine_axpy(md, w->tmp, y, 0.5 * H, w->k2);
	dyn_machine_rhs(sys, t + 0.5 * H, w->tmp, w->Qfeed, w->k3, NULL);
	machine_axpy(md, w->tmp, y, H, w->k3);
	dyn_machine_rhs(sys, t + H, w->tmp, w->Qfeed, w->k4, NULL);
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
 * 1e-3 s); the energy accumulators keep the predictor's values. One mass
 * matrix solve instead of four right-hand sides. */
static void correct(dem *w, dyn *sys, double t, double H, double *y, const double Qold[NQ_FULL])
{
	const model *md = sys->md;
	double dQ[NQ_FULL], a[NQ_FULL];
	for (int i = 0; i < NQ_FULL; i++)
		dQ[i] = w->Qfeed[i] - Qold[i];
	for (int r = 0; r < md->nq; r++) {
		int v = md->npos + r;
		w->tmp[r] = 0.5 * (y[r] + w->save[r]);
		w->tmp[v] = 0.5 * (y[v] + w->save[v]);
	}
	model_force_response(md, sys->ctl, t + 0.5 * H, w->tmp, dQ, a);
	for (int r = 0; r < md->nq; r++) {
		y[r] += 0.5 * H * H * a[r];
		y[md->npos + r] += H * a[r];
	}
}

static int dem_step(void *p, dyn *sys, double *t, double *y, double t_max)
{
	dem *w = p;
	const model *md = sys->md;
	const int n = w->n;
	double H = ode_fixed_step(*t, w->dt, t_max);
	if (md->nf > 0 && !w->have_q) {
		/* first step: the feed's reaction from the smooth law now */
		memset(w->Qfeed, 0, sizeof w->Qfeed);
		dynamics_feed_reaction(md, sys->ctl, *t, y, w->tmp, w->Qfeed);
		w->have_q = 1;
	}
	const int ns = w->substeps;
	if (w->correct)
		memcpy(w->save, y, sizeof(double) * (size_t)n);
	/* 1. machine RK4 with the feed force held */
	model_eval ev0, ev1;
	machine_rk4(w, sys, *t, H, y, &ev0);
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
	dyn_machine_rhs(sys, t1, y, w->Qfeed, w->k4, &ev1);
	const double h = H / ns;
	double F[SIM_MAX_COLUMNS][2];
	double fric = 0.0, contact = 0.0;
	const deck *dk = &md->dk;
	deck_rot R0 = deck_rotation(ev0.q), R1 = deck_rotation(ev1.q);
	for (int k = 0; k < dk->K; k++) {
		double p0[2], v0[2], p1[2], v1[2], a0[2], a1[2];
		deck_point(dk, dk->d[k], &R0, ev0.q, ev0.qd, p0, v0);
		deck_point(dk, dk->d[k], &R1, ev1.q, ev1.qd, p1, v1);
		deck_accel(dk, k, &R0, ev0.qd, ev0.qdd, a0);
		deck_accel(dk, k, &R1, ev1.qd, ev1.qdd, a1);
		double impulse[2] = {0.0, 0.0};
		for (int i = 0; i < ns; i++) {
			double s0 = (double)i / ns, s1 = (double)(i + 1) / ns;
			for (int c = 0; c < 2; c++) {
				w->deck_pos[i][c] = ode_hermite(p0[c], v0[c], p1[c], v1[c], H, s0);
				w->deck_vel[i][c] =
					ode_hermite(v0[c], a0[c], v1[c], a1[c], H, 0.5 * (s0 + s1));
			}
		}
		feed_dem_column(md, y, k, ns, h, (const double(*)[2])w->deck_pos,
				(const double(*)[2])w->deck_vel, w->modes, impulse, &fric, &contact);
		F[k][0] = impulse[0] / H;
		F[k][1] = impulse[1] / H;
	}
	y[2 * md->npos + ACC_FRIC] += md->col_weight * fric;
	y[2 * md->npos + ACC_CONTACT] += md->col_weight * contact;
	double Qold[NQ_FULL];
	memcpy(Qold, w->Qfeed, sizeof Qold);
	memset(w->Qfeed, 0, sizeof w->Qfeed);
	if (md->sc.feed_coupling)
		deck_forces(dk, &R1, (const double(*)[2])F, md->col_weight, w->Qfeed);
	if (w->correct)
		correct(w, sys, *t, H, y, Qold);
	*t = t1;
	return SIM_OK;
}

static void dem_reset(void *p)
{
	(void)p;
}

/* Carried between steps: the held reaction and the contacts' modes. */
static size_t dem_state_size(const void *p)
{
	const dem *w = p;
	return sizeof w->have_q + sizeof w->Qfeed + 2 * (size_t)w->nmodes;
}

static void dem_save(const void *p, void *buf)
{
	const dem *w = p;
	char *b = buf;
	memcpy(b, &w->have_q, sizeof w->have_q);
	memcpy(b + sizeof w->have_q, w->Qfeed, sizeof w->Qfeed);
	memcpy(b + sizeof w->have_q + sizeof w->Qfeed, w->modes, 2 * (size_t)w->nmodes);
}

static void dem_load(void *p, const void *buf)
{
	dem *w = p;
	const char *b = buf;
	memcpy(&w->have_q, b, sizeof w->have_q);
	memcpy(w->Qfeed, b + sizeof w->have_q, sizeof w->Qfeed);
	memcpy(w->modes, b + sizeof w->have_q + sizeof w->Qfeed, 2 * (size_t)w->nmodes);
}

const ode_method ode_dem = {
	.info = {.name = "dem",
		 .order = 1,
		 .adaptive = 0,
		 .doc = "machine RK4 macro step dt, feed sub-stepped with implicit Coulomb friction"},
	.dense = 0,
	.alloc = dem_alloc,
	.step = dem_step,
	.interpolate = NULL,
	.reset = dem_reset,
	.free = dem_free,
	.state_size = dem_state_size,
	.save = dem_save,
	.load = dem_load,
};
