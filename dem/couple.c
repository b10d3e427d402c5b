/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * couple.c - the machine and a LIGGGHTS bed, two-way coupled at the
 * machine's step (couple.h): the staggered interval, the floor's impulse
 * from the bed's momentum, the balances of momentum and energy between
 * the two sides, and the replay of a recorded deck motion.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "couple.h"

struct dem_coupled {
	sim *machine;
	dem_bed *bed;
	double dt, H, scale, g, transient, weight;
	int steps;
	int coupled;              /* feed_coupling: the load reaches the machine */
	sim_status ms;            /* the machine at the interval's start */
	dem_bed_state bs, bs0;    /* the bed at the interval's start, at t = 0 */
	double load[2];
	double imp_m[2], imp_b[2], work_m, work_b;
	double load_y_sum, load_y_n;
	double e_bed0;
	dem_slope slope;
	double cpu;
	long k;
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

dem_coupled *dem_coupled_new(const sim_params *p, const sim_scene *sc, const sim_method *m,
			     const dem_bed_spec *spec, int steps, double transient, const void *comm,
			     char *msg, size_t msglen)
{
	size_t nm;
	const sim_method_info *const *methods = sim_methods(&nm);
	for (size_t i = 0; i < nm; i++)
		if (!strcmp(methods[i]->name, m->name) && methods[i]->adaptive) {
			snprintf(msg, msglen, "feed_model liggghts: the method must take a fixed step "
					      "(euler, rk4 or dem), not %s", m->name);
			return NULL;
		}
	if (sc->feed_model != SIM_FEED_EXTERNAL || !sc->feed || steps < 1 || steps > 100000 ||
	    !(transient >= 0)) {
		snprintf(msg, msglen, "feed_model liggghts: needs feed = true, feed_model = liggghts, "
				      "coupling steps in [1, 100000] and transient >= 0");
		return NULL;
	}
	dem_coupled *c = calloc(1, sizeof *c);
	int err = SIM_OK;
	if (!c) {
		snprintf(msg, msglen, "feed_model liggghts: out of memory");
		return NULL;
	}
	if (!(c->machine = sim_new(p, sc, m, &err, msg, msglen)))
		goto fail;
	if (!(c->bed = dem_bed_new(spec, comm, msg, msglen)))
		goto fail;
	sim_get_status(c->machine, &c->ms);
	dem_bed_get(c->bed, &c->bs);
	c->bs0 = c->bs;
	c->dt = c->ms.dt;
	c->steps = steps;
	c->H = steps * c->ms.dt;
	c->g = p->g;
	c->transient = transient;
	c->coupled = sc->feed_coupling;
	c->weight = (double)sc->columns * (double)sc->layers * p->m_n * p->g;
	c->scale = c->weight / (p->g * c->bs.mass);
	c->load[1] = c->coupled ? -c->weight : 0.0;
	c->e_bed0 = couple_bed_energy(c, &c->bs, &c->ms);
	return c;
fail:
	dem_coupled_free(c);
	return NULL;
}

void dem_coupled_free(dem_coupled *c)
{
	if (!c)
		return;
	sim_free(c->machine);
	dem_bed_free(c->bed);
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
	double cpu0 = dem_cpu_now();
	if (dem_bed_advance(c->bed, ax, ay, H, msg, msglen))
		return -1;
	dem_bed_get(c->bed, &b1);
	c->cpu += dem_cpu_now() - cpu0;
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
	if (c->k == 0 && c->transient <= 0)
		dem_slope_add(&c->slope, 0.0, c->bs.x_mean);
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
	st->dem_cpu_seconds = c->cpu;
	st->intervals = c->k;
}

const sim *dem_coupled_machine(const dem_coupled *c)
{
	return c->machine;
}

int dem_replay(dem_bed *b, const double *a, long n, double interval, double transient,
	       double *v, char *msg, size_t msglen)
{
	dem_slope s = {0};
	dem_bed_state st;
	if (transient <= 0) {
		dem_bed_get(b, &st);
		dem_slope_add(&s, 0.0, st.x_mean);
	}
	for (long k = 0; k < n; k++) {
		if (dem_bed_advance(b, a[2 * k], a[2 * k + 1], interval, msg, msglen))
			return -1;
		double t1 = (double)(k + 1) * interval;
		if (t1 >= transient - 1e-12 * interval) {
			dem_bed_get(b, &st);
			dem_slope_add(&s, t1, st.x_mean);
		}
	}
	*v = dem_slope_value(&s);
	return 0;
}
