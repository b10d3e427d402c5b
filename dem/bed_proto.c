/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bed_proto.c - the bed server's lines (bed_proto.h): written with %a,
 * read back with strtod, which takes the hexadecimal form exactly.
 */
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>

#include "bed_proto.h"

/* Read n numbers from text into the pointers that follow: every one
 * finite, nothing after them but white space. 0 or -1. */
static int proto_numbers(const char *text, int n, ...)
{
	va_list ap;
	va_start(ap, n);
	const char *p = text;
	int ok = 1;
	for (int i = 0; i < n && ok; i++) {
		char *end;
		errno = 0;
		double v = strtod(p, &end);
		ok = end != p && errno == 0 && isfinite(v);
		*va_arg(ap, double *) = v;
		p = end;
	}
	va_end(ap);
	while (ok && (*p == ' ' || *p == '\n' || *p == '\r'))
		p++;
	return ok && *p == '\0' ? 0 : -1;
}

/* snprintf's length, or -1 when cut. */
static int proto_fits(int n, size_t len)
{
	return n < 0 || (size_t)n >= len ? -1 : n;
}

int dem_proto_bed_line(char *buf, size_t len, const dem_bed_spec *s)
{
	return proto_fits(snprintf(buf, len, "bed %d %a %a %a %a %a %a %a %a %a %d %u %a %a %d\n",
				   s->grains, s->d_min, s->d_max, s->density, s->cell_x, s->cell_y,
				   s->k_over_m, s->restitution, s->mu, s->mu_roll,
				   s->freeze_rotation, s->seed, s->g, s->settle,
				   s->tangential_viscous),
			  len);
}

int dem_proto_bed_parse(const char *args, dem_bed_spec *s)
{
	double grains, freeze, seed, viscous;
	/* what the line does not carry (a named material's contacts, the
	 * frame check's wiggle) is off: a bed process's spec is never what
	 * its stack held before */
	*s = (dem_bed_spec){0};
	if (proto_numbers(args, 15, &grains, &s->d_min, &s->d_max, &s->density, &s->cell_x,
			  &s->cell_y, &s->k_over_m, &s->restitution, &s->mu, &s->mu_roll, &freeze,
			  &seed, &s->g, &s->settle, &viscous) ||
	    grains < 1 || grains > 1e7 || seed < 0 || seed > 4294967295.0)
		return -1;
	s->grains = (int)grains;
	s->freeze_rotation = freeze != 0;
	s->tangential_viscous = viscous != 0;
	s->seed = (unsigned)seed;
	return 0;
}

int dem_proto_advance_line(char *buf, size_t len, double ax, double ay, double interval)
{
	return proto_fits(snprintf(buf, len, "advance %a %a %a\n", ax, ay, interval), len);
}

int dem_proto_advance_parse(const char *args, double *ax, double *ay, double *interval)
{
	return proto_numbers(args, 3, ax, ay, interval);
}

int dem_proto_state_line(char *buf, size_t len, const dem_bed_state *st, double cpu,
			 int grains)
{
	return proto_fits(snprintf(buf, len, "state %a %a %a %a %a %a %a %a %a %d\n", st->t,
				   st->mass, st->x_mean, st->z_mean, st->p_x, st->p_z,
				   st->kinetic, st->kinetic_rot, cpu, grains),
			  len);
}

int dem_proto_state_parse(const char *args, dem_bed_state *st, double *cpu, int *grains)
{
	double g;
	if (proto_numbers(args, 10, &st->t, &st->mass, &st->x_mean, &st->z_mean, &st->p_x,
			  &st->p_z, &st->kinetic, &st->kinetic_rot, cpu, &g) ||
	    g < 1 || g > 1e7)
		return -1;
	*grains = (int)g;
	return 0;
}
