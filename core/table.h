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

/* The text of "%.*g" (precision p) for the significant digits dig[0..p)
 * of a value d.ddd x 10^x, sign neg, into out (at least 32 bytes): the
 * trailing zeros dropped, scientific where x < -4 or x >= p, as printf
 * writes it. */
static inline int sim_fmt_g_digits(char *out, int neg, const char *dig, int p, int x)
{
	int nd = p, n = 0;
	while (nd > 1 && dig[nd - 1] == '0')
		nd--;
	if (neg)
		out[n++] = '-';
	if (x < -4 || x >= p) {
		out[n++] = dig[0];
		if (nd > 1) {
			out[n++] = '.';
			for (int i = 1; i < nd; i++)
				out[n++] = dig[i];
		}
		n += sprintf(out + n, "e%c%02d", x < 0 ? '-' : '+', x < 0 ? -x : x);
	} else if (x >= 0) {
		for (int i = 0; i <= x; i++)
			out[n++] = i < nd ? dig[i] : '0';
		if (nd > x + 1) {
			out[n++] = '.';
			for (int i = x + 1; i < nd; i++)
				out[n++] = dig[i];
		}
		out[n] = '\0';
	} else {
		out[n++] = '0';
		out[n++] = '.';
		for (int i = 0; i < -x - 1; i++)
			out[n++] = '0';
		for (int i = 0; i < nd; i++)
			out[n++] = dig[i];
		out[n] = '\0';
	}
	return n;
}

/* Whether a decimal dist units from v's 17 significant digits d.ddd x
 * 10^x (a unit: their last digit) reads back as v: 1 surely, -1 surely
 * not, 0 when too close to tell. The 17 digits are within half a unit of
 * v, so the decimal is within dist +- 0.5 units of v; it reads back as v
 * when that is inside v's rounding interval, half v's spacing each side
 * (below a power of two the spacing under it is half that). The spacing
 * in units is computed in logarithms, with a margin far above their
 * error. */
static inline int sim_fmt_inside(double v, int x, double dist)
{
	int e;
	double f = frexp(fabs(v), &e); /* |v| = f 2^e, f in [0.5, 1) */
	int ulp2 = e - 53 < -1074 ? -1074 : e - 53;
	/* half the spacing, in units of 10^(x - 16) */
	double half = exp2((double)(ulp2 - 1) - (double)(x - 16) * 3.321928094887362);
	double below = f == 0.5 ? 0.5 * half : half;
	if (dist + 0.5 < below * (1 - 1e-6))
		return 1;
	if (dist - 0.5 > half * (1 + 1e-6))
		return -1;
	return 0;
}

/* The longest text sim_fmt_double writes for a finite v, 24 bytes:
 * -d.dddddddddddddddde-ddd (17 digits, a three-digit exponent). What
 * writes many values bounds its output with it (convsim run --out). */
#define SIM_FMT_DOUBLE_MAX 24

/* Write v into buf (len bytes) as the shortest text that reads back as v
 * ("-0" and "0" kept apart); non-finite values as `nonfinite` ("null" in
 * JSON, "" in CSV). Returns the length written, as snprintf.
 *
 * The text is the first of "%.15g", "%.16g" and "%.17g" that strtod reads
 * back as v. One printf gives v's 17 significant digits (correctly
 * rounded); the 15- and 16-digit candidates are those digits rounded
 * again, which is v rounded to 15 or 16 digits unless the digits cut off
 * are exactly 5 followed by zeros (then v's own tail decides: printf is
 * asked). A candidate clearly inside or outside v's rounding interval
 * needs no strtod (sim_fmt_inside); so each value costs one printf and
 * at most two strtod, where asking printf for each candidate cost up to
 * three of each;
 * tests/unit/test_table.c checks the text byte for byte against the three
 * printf calls. */
static inline int sim_fmt_double(char *buf, size_t len, double v, const char *nonfinite)
{
	if (!isfinite(v))
		return snprintf(buf, len, "%s", nonfinite);
	if (v == 0.0)
		return snprintf(buf, len, signbit(v) ? "-0" : "0");
	char e17[40], dig[18], cand[40];
	snprintf(e17, sizeof e17, "%.16e", v); /* [-]d.dddddddddddddddde[+-]xx */
	int neg = e17[0] == '-';
	const char *m = e17 + neg;
	dig[0] = m[0];
	memcpy(dig + 1, m + 2, 16);
	int x = atoi(m + 19);
	for (int p = 15; p <= 16; p++) {
		const char *tail = dig + p;
		int tie = tail[0] == '5', up = tail[0] >= '5';
		for (int i = 1; tie && i < 17 - p; i++)
			tie = tail[i] == '0';
		if (tie) {
			/* v's digits beyond the 17th decide: printf's own rounding */
			int n = snprintf(buf, len, "%.*g", p, v);
			if (strtod(buf, NULL) == v)
				return n;
			continue;
		}
		/* how far the candidate is from the 17 digits, in units of
		 * their last: where that and the 17 digits' own half unit put it
		 * clearly inside or outside v's rounding interval, no strtod */
		double cut = 0, whole = 1;
		for (int i = 0; i < 17 - p; i++) {
			cut = cut * 10 + (tail[i] - '0');
			whole *= 10;
		}
		double dist = up ? whole - cut : cut;
		int inside = sim_fmt_inside(v, x, dist);
		if (inside < 0)
			continue;
		char r[17];
		int rx = x;
		memcpy(r, dig, (size_t)p);
		for (int i = p - 1; up && i >= 0; i--) {
			if (r[i] == '9') {
				r[i] = '0';
			} else {
				r[i]++;
				up = 0;
			}
		}
		if (up) { /* 9.99...9 rounded up: 1.00...0 x 10^(x + 1) */
			r[0] = '1';
			rx++;
		}
		sim_fmt_g_digits(cand, neg, r, p, rx);
		if (inside > 0 || strtod(cand, NULL) == v)
			return snprintf(buf, len, "%s", cand);
	}
	sim_fmt_g_digits(cand, neg, dig, 17, x);
	return snprintf(buf, len, "%s", cand);
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
