/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * disturb.c - disturbances of a running instance: the column feed's
 * element mass m_n (its load) and friction coefficient mu changed between
 * steps, with the state carried over by the rule of docs/MODEL.md
 * "Disturbances" and the energy books kept closed across the change.
 *
 * m_n and mu sit in the model's parameters, which are otherwise const
 * during a run: these two are read by the feed at every evaluation and
 * by nothing the instance derived once (the step, the sub-steps and the
 * layout stay those of the start), so changing them between steps is
 * safe. The one derived choice that depends on m_n, the split method's
 * corrected coupling of a light feed (feed mass at most
 * MODEL_CORRECTOR_MAX_RATIO of the machine's), is kept on its side by
 * sim_feed_mass_range (instance.c, where the method is resolved as
 * sim_alloc resolves it).
 */
#include <math.h>
#include <string.h>

#include "feed.h"
#include "sim_int.h"
#include "units.h"

/* Scale the contacts of state vector y at time t by factor (the deck
 * points where y puts them). */
static void scale_contacts(const sim *s, double *y, double t, double factor)
{
	double q[NQ_FULL], qd[NQ_FULL];
	deck_motion dm;
	model_full_coords(&s->md, &s->ctl, t, y, q, qd);
	deck_motion_eval(&s->md.dk, q, qd, &dm);
	feed_scale_contacts(&s->md, y, &dm, factor);
}

/* The stored energy of state y at the integrator's time: kinetic plus
 * potential into *kp, the contacts' elastic energy returned. */
static double stored(const sim *s, const double *y, double *kp)
{
	double kin, pot, q[NQ_FULL], qd[NQ_FULL];
	*kp = dynamics_energy_stored(&s->md, &s->ctl, s->t_int, y, &kin, &pot);
	model_full_coords(&s->md, &s->ctl, s->t_int, y, q, qd);
	return dynamics_contact_energy(&s->md, y, q, qd);
}

int sim_set_feed(sim *s, double m_n, double mu)
{
	model *md = &s->md;
	if (md->nf == 0 || s->failed)
		return SIM_EPARAM;
	m_n = isnan(m_n) ? md->p.m_n : m_n;
	mu = isnan(mu) ? md->p.mu : mu;
	double lo, hi;
	sim_feed_mass_range(&md->p, &md->sc, &s->cfg, &lo, &hi);
	if (!sim_setting_check(sim_setting_find("m_n"), m_n) ||
	    !sim_setting_check(sim_setting_find("mu"), mu) || m_n < lo || m_n > hi ||
	    !(m_n < sim_m_n_most(&md->p, &md->sc)))
		return SIM_EPARAM;
	double kp0, el0 = stored(s, s->y, &kp0);
	if (m_n != md->p.m_n) {
		/* the observed state and the last step's start too, so that
		 * what is shown before the next step is of the same feed */
		double factor = pow(m_n / md->p.m_n, 1.0 / md->p.p);
		scale_contacts(s, s->y, s->t_int, factor);
		scale_contacts(s, s->y_obs, s->t_obs, factor);
		scale_contacts(s, s->y_prev, s->t_prev, factor);
	}
	md->p.m_n = m_n;
	md->p.mu = mu;
	/* the stored energy's jump is the disturbance's work: booked as
	 * input (e_disturb), the elastic part where the contacts' work keeps
	 * it, the rest where dem keeps the feed's energy change */
	double kp1, el1 = stored(s, s->y, &kp1);
	double *vec[3] = {s->y, s->y_obs, s->y_prev};
	for (int v = 0; v < 3; v++) {
		double *acc = vec[v] + 2 * md->npos;
		acc[ACC_CONTACT] += el1 - el0;
		if (s->ode->info.substeps)
			acc[ACC_FEED] += kp1 - kp0;
	}
	s->e_disturb += (kp1 - kp0) + (el1 - el0);
	/* the integrator's cached values held the old feed; the transport
	 * estimate and the step error's shadow start over on the new one */
	s->ode->reset(s->ws);
	sim_restart_transport(s);
	return SIM_OK;
}
