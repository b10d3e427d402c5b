/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bed_spec.c - the bed this project uses unless told otherwise (dem.h):
 * its grains and contact numbers from the column model's parameters.
 * Plain arithmetic, no LIGGGHTS: the daemon builds a bed's request with it
 * for its bed process (Makefile's libdemlink.a).
 */
#include <math.h>
#include <string.h>

#include "dem.h"

int dem_bed_grains(double cell_x, double cell_y, double d_mean, double depth)
{
	long n = lround(0.6 * cell_x * cell_y * depth * d_mean / (M_PI / 6 * d_mean * d_mean * d_mean));
	return n < 1 ? 1 : n > 1000000 ? 1000000 : (int)n;
}

double dem_bed_spec_mass_mean(const dem_bed_spec *s)
{
	double d_mean = 0.5 * (s->d_min + s->d_max);
	/* the mean of d^3 over the uniform distribution of d */
	double d3 = (pow(s->d_max, 4) - pow(s->d_min, 4)) / (4 * fmax(s->d_max - s->d_min, 1e-300));
	if (s->d_max - s->d_min < 1e-12 * d_mean)
		d3 = d_mean * d_mean * d_mean;
	return s->density * M_PI / 6 * d3;
}

/* The step of a hertz bed: the smaller of a tenth of the lightest
 * grain's Rayleigh time and a fortieth of its Hertz contact on the deck
 * (same modulus) at an approach of 1 m/s. */
static double spec_dt_hertz(const dem_bed_spec *s)
{
	double r = 0.5 * s->d_min, nu = s->poisson;
	double shear = s->youngs / (2 * (1 + nu));
	double t_r = M_PI * r * sqrt(s->density / shear) / (0.1631 * nu + 0.8766);
	double m = s->density * M_PI / 6 * pow(s->d_min, 3);
	double e_star = s->youngs / (2 * (1 - nu * nu));
	double t_c = 2.87 * pow(m * m / (r * e_star * e_star * 1.0), 0.2);
	return fmin(0.1 * t_r, t_c / 40);
}

double dem_bed_spec_dt(const dem_bed_spec *s)
{
	if (s->hertz)
		return spec_dt_hertz(s);
	double m_min = s->density * M_PI / 6 * pow(s->d_min, 3);
	double kn = s->k_over_m * dem_bed_spec_mass_mean(s);
	return M_PI / sqrt(kn / m_min) / 50;
}

double dem_bed_spec_cost(const dem_bed_spec *s)
{
	return DEM_CPU_PER_GRAIN_STEP * s->grains / dem_bed_spec_dt(s);
}

void dem_bed_spec_default(const sim_params *p, double depth, dem_bed_spec *b)
{
	double d_mean = 0.004;
	memset(b, 0, sizeof *b);
	b->d_min = 0.0036;
	b->d_max = 0.0044;
	b->density = 2500;
	b->cell_x = 20 * d_mean;
	b->cell_y = 4 * d_mean;
	b->grains = dem_bed_grains(b->cell_x, b->cell_y, d_mean, depth);
	b->k_over_m = p->k_c / p->m_n;
	b->restitution = p->R;
	b->mu = p->mu;
	b->g = p->g;
	b->seed = 1;
	b->settle = b->grains == 1 ? 0.05 : 0.3;
}
