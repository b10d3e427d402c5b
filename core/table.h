/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * table.h - the tables a user takes away, as the CLI and the daemon write
 * them: one column list for trajectories, one header for v(beta) sweeps,
 * and one way to print a number. Header only (static inline, libc and
 * libm), so that cli/ (which sees core/ and fit/, not api/) and api/ share it
 * without a dependency between the two.
 *
 * Numbers are the shortest of %.15g, %.16g and %.17g that strtod reads
 * back bit for bit: a value printed by `convsim` and by `convsimd` is the
 * same text (1e-06, never 9.9999999999999995e-07).
 */
#ifndef CONVSIM_TABLE_H
#define CONVSIM_TABLE_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "sim.h"
#include "units.h"

/* Write v into buf (len bytes) as the shortest text that reads back as v
 * ("-0" and "0" kept apart); non-finite values as `nonfinite` ("null" in
 * JSON, "" in CSV). Returns the length written, as snprintf. */
static inline int sim_fmt_double(char *buf, size_t len, double v, const char *nonfinite)
{
	if (!isfinite(v))
		return snprintf(buf, len, "%s", nonfinite);
	if (v == 0.0)
		return snprintf(buf, len, signbit(v) ? "-0" : "0");
	int n = 0;
	for (int prec = 15; prec <= 17; prec++) {
		n = snprintf(buf, len, "%.*g", prec, v);
		if (strtod(buf, NULL) == v)
			break;
	}
	return n;
}

/* A time in s as the tables and answers print it: rounded to the
 * nanosecond, so that a time on a step or sample grid reads as k dt (0.052,
 * not 0.052000000000000005). Every grid of the engine (steps of at least
 * 1e-7 s, sample intervals of whole microseconds) is a whole number of
 * nanoseconds; adaptive dopri5 times lose what lies below one. */
static inline double sim_time_ns(double t)
{
	return isfinite(t) && fabs(t) < 1e6 ? nearbyint(t * 1e9) / 1e9 : t;
}

/* A user-unit value of a setting from SI (beta: rad to deg), by the
 * settings table's scale; the API, the CLI and the trajectories all
 * convert with it. sim_setting_from_si gives a value a user sent back as
 * sent; a value the model made (a beta in mid-ramp) it leaves as the
 * plain quotient, with noise in its last digits (31.487812499999997):
 * 15 significant digits, what a double carried through a scale and back
 * keeps. A name that is no setting, a scale of 1 or a value not finite
 * pass unchanged. */
static inline double sim_table_user(const char *setting, double si)
{
	/* the last conversion of this thread, kept: a trajectory row converts
	 * beta and its target 100 times a simulated second, and they rarely
	 * change (the lookup and the text round trip showed in the daemon's
	 * profile, docs/load.md). The same setting and the same bits give the
	 * same answer */
	static _Thread_local const sim_setting *memo_t;
	static _Thread_local double memo_si, memo_user;
	if (memo_t && setting && memcmp(&memo_si, &si, sizeof si) == 0 &&
	    strcmp(memo_t->name, setting) == 0)
		return memo_user;
	const sim_setting *t = sim_setting_find(setting);
	if (!t)
		return si;
	double user = sim_setting_from_si(t, si);
	if (t->scale == 1 || !isfinite(user))
		return user;
	char text[32];
	snprintf(text, sizeof text, "%.15g", user);
	memo_t = t;
	memo_si = si;
	memo_user = strtod(text, NULL);
	return memo_user;
}

/*
 * The trajectory's columns: X(name, unit, value from `const sim_status
 * *st`). After them come `column_1` ... `column_K` (m), the mean
 * displacement of each feed column since t = 0. The daemon's
 * GET /sessions/ID/trajectory and `convsim run --out` write exactly these.
 */
#define SIM_TRAJECTORY_COLUMNS(X)                                               \
	X(t, "s", sim_time_ns(st->t))                                           \
	X(beta, "deg", sim_table_user("beta", st->beta))                        \
	X(beta_target, "deg", sim_table_user("beta", st->beta_target))          \
	X(x, "m", st->q[0])                                                     \
	X(y, "m", st->q[1])                                                     \
	X(alpha, "rad", st->q[2])                                               \
	X(s1, "m", st->q[4])                                                    \
	X(s2, "m", st->q[5])                                                    \
	X(deck_x, "m", st->deck[0])                                             \
	X(deck_y, "m", st->deck[1])                                             \
	X(rotor_speed, "rad/s", st->rotor_speed)                                \
	X(motor_torque, "N m", st->motor_torque)                                \
	X(power, "W", st->power)                                                \
	X(feed_displacement, "m", st->feed_displacement)                        \
	X(feed_velocity, "m/s", st->feed_velocity)                              \
	X(transport_velocity, "m/s", st->transport_velocity)                    \
	X(transport_velocity_uncertainty, "m/s", st->transport_velocity_uncertainty) \
	X(e_input, "J", st->e_input)                                            \
	X(e_dissipated, "J", st->e_dissipated)                                  \
	X(e_residual, "J", st->e_residual)

#define SIM_TABLE_COUNT_(name, unit, value) +1
/* Number of named trajectory columns (before column_1 ... column_K). */
#define SIM_TRAJECTORY_NAMED (0 SIM_TRAJECTORY_COLUMNS(SIM_TABLE_COUNT_))

/* Name and unit of named column i (0 <= i < SIM_TRAJECTORY_NAMED). */
static inline const char *sim_trajectory_name(int i)
{
#define SIM_TABLE_NAME_(name, unit, value) #name,
	static const char *const names[] = {SIM_TRAJECTORY_COLUMNS(SIM_TABLE_NAME_)};
#undef SIM_TABLE_NAME_
	return names[i];
}
static inline const char *sim_trajectory_unit(int i)
{
#define SIM_TABLE_UNIT_(name, unit, value) unit,
	static const char *const units[] = {SIM_TRAJECTORY_COLUMNS(SIM_TABLE_UNIT_)};
#undef SIM_TABLE_UNIT_
	return units[i];
}

/* The named columns of one row from a status into row[0 ..
 * SIM_TRAJECTORY_NAMED - 1]. */
static inline void sim_trajectory_row(const sim_status *st, double *row)
{
#define SIM_TABLE_VALUE_(name, unit, value) value,
	const double v[] = {SIM_TRAJECTORY_COLUMNS(SIM_TABLE_VALUE_)};
#undef SIM_TABLE_VALUE_
	for (int i = 0; i < SIM_TRAJECTORY_NAMED; i++)
		row[i] = v[i];
}

/* The v(beta) sweep's CSV header: beta in deg, rotation cw|ccw, velocity
 * and uncertainty in m/s (empty when not measured), steady true|false,
 * state queued|running|done|failed|cancelled; then the steps the point
 * was measured with (dt in s, feed sub-steps), the steps' share of the
 * uncertainty (step_error, m/s) and whether the uncertainty is within
 * the accuracy target tol (tol_met true|false); then the point's model
 * error (SIM_MODEL_ERROR_COLUMNS). A study over other
 * settings has their columns in place of beta (SIM_SWEEP_POINT_COLUMNS
 * after them). */
#define SIM_SWEEP_POINT_COLUMNS \
	"rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met," \
	SIM_MODEL_ERROR_COLUMNS
/* A v's DEM check in a CSV row (sim_model_check, docs/dem.md "Model
 * error"): model_error and model_error_uncertainty in m/s, empty where not
 * checked, and model_checked true|false (the note, a sentence, is in the
 * JSON only). */
#define SIM_MODEL_ERROR_COLUMNS "model_error,model_error_uncertainty,model_checked"
#define SIM_SWEEP_CSV_HEADER "beta," SIM_SWEEP_POINT_COLUMNS

#endif
