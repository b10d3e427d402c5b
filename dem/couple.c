/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * couple.c - the machine and a LIGGGHTS bed, two-way coupled at the
 * machine's step (couple.h): the staggered interval, the floor's impulse
 * from the bed's momentum, the balances of momentum and energy between
 * the two sides. The bed is a dem_feed (feed.h): this file builds
 * without LIGGGHTS, so that the daemon couples a bed in a child process
 * with the very arithmetic the CLI uses on a bed in its own.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "couple.h"

struct dem_coupled {
	sim *machine;
	int own_machine;
	dem_feed *bed;
	double dt, H, scale, g, transient, weight;
	int steps;
	int coupled;              /* feed_coupling: the load reaches the machine */
	sim_status ms;            /* the machine at the interval's start */
	dem_bed_state bs, bs0;    /* the bed at the interval's start, at attach */
	double load[2];
	double imp_m[2], imp_b[2], work_m, work_b;
	double load_y_sum, load_y_n;
	double e_bed0;
	dem_slope slope;
	double cpu0;              /* the bed's CPU at attach */
	long k;                   /* intervals since t = 0 */
};

void dem_slope_add(dem_slope *s, double t, double x)
{
	s->n += 1;
	s->st += t;
	s->sx += x;
	s->stt += t * t;
	s->stx += t * x;
}

double dem_slope_value(const dem_slope *s)
{
	double d = s->n * s->stt - s->st * s->st;
	return s->n >= 2 && d > 0 ? (s->n * s->stx - s->st * s->sx) / d : NAN;
}

/* The bed's energy in the absolute frame (J, scaled to the feed): kinetic
 * of translation (relative momentum and the deck's velocity), rotation,
 * and potential of the mean height above the moving deck. */
static double couple_bed_energy(const dem_coupled *c, const dem_bed_state *b, const sim_status *m)
{
	const double *v = m->deck_vel;
	double kin = b->kinetic + b->p_x * v[0] + b->p_z * v[1] +
		     0.5 * b->mass * (v[0] * v[0] + v[1] * v[1]) + b->kinetic_rot;
	return c->scale * (kin + b->mass * c->g * (b->z_mean + m->deck[1]));
}

int dem_coupled_check(const sim_scene *sc, const sim_method *m, int steps, double transient,
		      char *msg, size_t msglen)
{
	size_t nm;
	const sim_method_info *const *methods = sim_methods(&nm);
	for (size_t i = 0; i < nm; i++)
		if (!strcmp(methods[i]->name, m->name) && methods[i]->adaptive) {
			snprintf(msg, msglen, "feed_model liggghts: the method must take a fixed step "
					      "(euler, rk4 or dem), not %s", m->name);
			return -1;
		}
	if (sc->feed_model != SIM_FEED_EXTERNAL || !sc->feed || steps < 1 || steps > 100000 ||
	    !(transient >= 0)) {
		snprintf(msg, msglen, "feed_model liggghts: needs feed = true, feed_model = liggghts, "
				      "coupling steps in [1, 100000] and transient >= 0");
		return -1;
	}
	return 0;
}

dem_coupled *dem_coupled_attach(sim *machine, int own_machine, dem_feed *bed,
				const sim_params *p, const sim_scene *sc, int steps,
				double transient, char *msg, size_t msglen)
{
	dem_coupled *c = calloc(1, sizeof *c);
	if (!c) {
		snprintf(msg, msglen, "feed_model liggghts: out of memory");
		if (own_machine)
			sim_free(machine);
		dem_feed_free(bed);
		return NULL;
	}
	c->machine = machine;
	c->own_machine = own_machine;
	c->bed = bed;
	sim_get_status(c->machine, &c->ms);
	c->bs = c->bs0 = bed->state;
	c->cpu0 = bed->cpu;
	c->dt = c->ms.dt;
	c->steps = steps;
	c->H = steps * c->ms.dt;
	/* a restored machine resumes on an interval's end, in the core's
	 * own arithmetic for its time (k_fixed * dt) */
	c->k = (long)llround(c->ms.t / c->H);
	if (c->ms.t_int != c->ms.t || (double)(c->k * c->steps) * c->dt != c->ms.t) {
		snprintf(msg, msglen, "feed_model liggghts: the machine (t = %.17g s) does not "
				      "stand at the end of a coupling interval", c->ms.t);
		dem_coupled_free(c);
		return NULL;
	}
	c->g = p->g;
	c->transient = transient;
	c->coupled = sc->feed_coupling;
	c->weight = (double)sc->columns * (double)sc->layers * p->m_n * p->g;
	c->scale = c->weight / (p->g * c->bs.mass);
	/* the load the machine holds: the feed's weight at t = 0, the last
	 * bed's load on a restored machine (its checkpoint keeps it) */
	c->load[1] = c->coupled && c->k == 0 ? -c->weight : 0.0;
	c->e_bed0 = couple_bed_energy(c, &c->bs, &c->ms);
	if (c->ms.t >= c->transient - 1e-12 * c->H)
		dem_slope_add(&c->slope, c->ms.t, c->bs.x_mean);
	return c;
}

void dem_coupled_free(dem_coupled *c)
{
	if (!c)
		return;
	if (c->own_machine)
		sim_free(c->machine);
	dem_feed_free(c->bed);
	free(c);
}

/* One coupling interval (couple.h's stages 1-3). */
static int couple_interval(dem_coupled *c, FILE *deck_out, char *msg, size_t msglen)
{
	sim_status m1;
	dem_bed_state b1;
	/* the core's own arithmetic for its time (k_fixed * dt): the machine
	 * ends the interval exactly on a step, where the next load starts */
	const double H = c->H, t1 = (double)((c->k + 1) * c->steps) * c->dt;
	/* 1. the machine under the held load */
	if (sim_advance(c->machine, t1) != SIM_OK) {
		snprintf(msg, msglen, "machine: %s", sim_last_error(c->machine));
		return -1;
	}
	sim_get_status(c->machine, &m1);
	if (m1.t_int != m1.t) {
		snprintf(msg, msglen, "machine: its step does not end the coupling interval");
		return -1;
	}
	double dx = m1.deck[0] - c->ms.deck[0], dy = m1.deck[1] - c->ms.deck[1];
	if (c->coupled) {
		c->work_m += c->load[0] * dx + c->load[1] * dy;
		c->imp_m[0] += c->load[0] * H;
		c->imp_m[1] += c->load[1] * H;
	}
	/* 2. the bed under the deck's mean acceleration */
	double ax = (m1.deck_vel[0] - c->ms.deck_vel[0]) / H;
	double ay = (m1.deck_vel[1] - c->ms.deck_vel[1]) / H;
	if (deck_out)
		fprintf(deck_out, "%.17g %.17g\n", ax, ay);
	if (dem_feed_advance(c->bed, ax, ay, H, msg, msglen))
		return -1;
	b1 = c->bed->state;
	/* 3. the floor's impulse on the grains, scaled: the next load */
	double Jx = c->scale * (b1.p_x - c->bs.p_x + b1.mass * ax * H);
	double Jy = c->scale * (b1.p_z - c->bs.p_z + b1.mass * (ay + c->g) * H);
	c->imp_b[0] += Jx;
	c->imp_b[1] += Jy;
	c->work_b += (Jx * dx + Jy * dy) / H;
	c->load[0] = -Jx / H;
	c->load[1] = -Jy / H;
	if (c->coupled && sim_set_deck_load(c->machine, c->load[0], c->load[1], 0.0) != SIM_OK) {
		snprintf(msg, msglen, "machine: the bed's load is not finite");
		return -1;
	}
	c->k++;
	c->ms = m1;
	c->bs = b1;
	if (t1 >= c->transient - 1e-12 * H) {
		dem_slope_add(&c->slope, t1, b1.x_mean);
		c->load_y_sum += c->load[1];
		c->load_y_n += 1;
	}
	return 0;
}

int dem_coupled_advance(dem_coupled *c, double t_end, FILE *deck_out, char *msg, size_t msglen)
{
	while ((double)((c->k + 1) * c->steps) * c->dt <= t_end + 1e-9 * c->H)
		if (couple_interval(c, deck_out, msg, msglen))
			return -1;
	return 0;
}

void dem_coupled_get(const dem_coupled *c, dem_coupled_status *st)
{
	memset(st, 0, sizeof *st);
	st->t = c->ms.t;
	st->interval = c->H;
	st->scale = c->scale;
	st->transport_velocity = dem_slope_value(&c->slope);
	st->load[0] = c->load[0];
	st->load[1] = c->load[1];
	st->load_mean_y = c->load_y_n > 0 ? c->load_y_sum / c->load_y_n : NAN;
	st->weight = c->weight;
	memcpy(st->impulse_machine, c->imp_m, sizeof c->imp_m);
	memcpy(st->impulse_bed, c->imp_b, sizeof c->imp_b);
	st->work_machine = c->work_m;
	st->work_bed = c->work_b;
	st->bed_energy = couple_bed_energy(c, &c->bs, &c->ms) - c->e_bed0;
	st->machine_residual = c->ms.e_residual;
	st->dem_cpu_seconds = c->bed->cpu - c->cpu0;
	st->displacement = c->bs.x_mean - c->bs0.x_mean;
	st->bed_velocity = c->bs.mass > 0 ? c->bs.p_x / c->bs.mass : NAN;
	st->grains = c->bed->grains;
	st->intervals = c->k;
}

const sim *dem_coupled_machine(const dem_coupled *c)
{
	return c->machine;
}

const dem_feed *dem_coupled_bed(const dem_coupled *c)
{
	return c->bed;
}

void dem_coupled_restart_transport(dem_coupled *c)
{
	memset(&c->slope, 0, sizeof c->slope);
	c->load_y_sum = c->load_y_n = 0;
	if (c->transient < c->ms.t)
		c->transient = c->ms.t;
	if (c->ms.t >= c->transient - 1e-12 * c->H)
		dem_slope_add(&c->slope, c->ms.t, c->bs.x_mean);
}

double dem_coupled_interval_end(const dem_coupled *c, double t)
{
	long k = (long)ceil(t / c->H - 1e-9);
	return (double)(k * c->steps) * c->dt;
}

int dem_feed_advance(dem_feed *f, double ax, double ay, double interval, char *msg,
		     size_t msglen)
{
	return f->ops->advance(f, ax, ay, interval, msg, msglen);
}

void dem_feed_free(dem_feed *f)
{
	if (f)
		f->ops->free(f);
}
