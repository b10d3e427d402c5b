/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * units.h - user units at the edges. The core's interface is SI; the
 * settings table (sim_settings()) says for each setting the unit a user
 * writes and its scale, the SI value of one such unit. The CLI and the API
 * convert once, with these helpers, where a value enters or leaves.
 */
#ifndef CONVSIM_UNITS_H
#define CONVSIM_UNITS_H

#include <math.h>

#include "sim.h"

/* pi spelt as glibc's M_PI (the same double), which strict feature-test
 * settings leave undefined; the scale of "deg" and its inverse. */
#define SIM_PI 3.14159265358979323846
#define RAD_PER_DEG (SIM_PI / 180.0)
#define DEG_PER_RAD (180.0 / SIM_PI)

/* The setting named name, or NULL. Static. */
const sim_setting *sim_setting_find(const char *name);

/* A value of setting t between user units and SI (value * scale). From
 * SI, a scaled value is the number with the fewest decimals (up to 9) that
 * converts back to the same SI double, so that a value a user gave comes
 * back as given: 30 deg, not 29.999999999999996; 121.9 after a restart,
 * not 121.89999999999999. Where none converts back (a beta in mid-ramp),
 * the plain quotient. */
static inline double sim_setting_to_si(const sim_setting *t, double user)
{
	return user * t->scale;
}
static inline double sim_setting_from_si(const sim_setting *t, double si)
{
	double user = si / t->scale;
	if (t->scale == 1 || !isfinite(user) || fabs(user) >= 1e9)
		return user;
	double p = 1;
	for (int k = 0; k <= 9; k++, p *= 10) {
		double c = nearbyint(user * p) / p;
		if (c * t->scale == si)
			return c;
	}
	return user;
}

/* The unit as written after a number: "N/m", or "" for a setting without
 * one or a dimensionless one (unit "1": 0.3, not "0.3 1"). */
static inline const char *sim_unit_shown(const sim_setting *t)
{
	return t->unit && !(t->unit[0] == '1' && !t->unit[1]) ? t->unit : "";
}

/* 1 if the SI value lies in setting t's range (finite, [min, max] scaled). */
int sim_setting_check(const sim_setting *t, double si);

/* sim_set, sim_set_str and sim_get in user units (beta in deg): the value
 * is converted with the table, then handled as the SI functions do. */
int sim_set_user(sim_params *p, sim_scene *s, sim_method *m, const char *name, double value,
		 char *msg, size_t msglen);
int sim_set_user_str(sim_params *p, sim_scene *s, sim_method *m, const char *name,
		     const char *value, char *msg, size_t msglen);
int sim_get_user(const sim_params *p, const sim_scene *s, const sim_method *m, const char *name,
		 double *value);

#endif
