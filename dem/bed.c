/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bed.c - a bed of spheres in LIGGGHTS on the deck (dem.h): the input
 * deck of commands that builds it, the settling, the advance over one
 * coupling interval under the deck's acceleration, and the bed's totals
 * read back through equal-style variables.
 *
 * LIGGGHTS's fix gravity takes no variables, so a held deck acceleration
 * enters as a new gravity fix at each interval ("unfix", "fix", then a run
 * with its set-up), which LIGGGHTS evaluates once per run; a formula of
 * time enters as a fix addforce of atom-style variables, evaluated at
 * every step (dem_bed_advance_drive). LIGGGHTS ends
 * the process on a command it refuses, so every value is checked here
 * before it is sent.
 */
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include <library.h>

#include "dem.h"

struct dem_bed {
	void *lmp;
	dem_bed_spec spec;
	char stl[64];   /* the moving floor's mesh file (frame check), "" for none */
	double dt;      /* s DEM step */
	double t;       /* s since the end of the settling */
	double m_mean;  /* kg of the mean grain */
	double t_zero;  /* s: LIGGGHTS's own time at the bed's t = 0 */
	int drive;      /* 1: the deck fix is the addforce of v_ax, v_ay; 0: the settling's gravity */
	double step;    /* s: the DEM step of the last run (drive 1) */
};

/* One LIGGGHTS command, printf-style. */
static void bed_cmd(dem_bed *b, const char *fmt, ...)
{
	char line[2048];
	va_list ap;
	va_start(ap, fmt);
	vsnprintf(line, sizeof line, fmt, ap);
	va_end(ap);
	lammps_command(b->lmp, line);
}

/* An equal-style variable's value (LIGGGHTS returns a malloc'd copy). */
static double bed_var(const dem_bed *b, const char *name)
{
	double *v = lammps_extract_variable(b->lmp, (char *)name, NULL);
	double out = v ? *v : NAN;
	free(v);
	return out;
}

double dem_cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

/* xorshift64*: the packing's reproducible random numbers in [0, 1). */
static double bed_random(unsigned long long *s)
{
	*s ^= *s >> 12;
	*s ^= *s << 25;
	*s ^= *s >> 27;
	return (double)((*s * 2685821657736338717ULL) >> 11) / 9007199254740992.0;
}

static int spec_check(const dem_bed_spec *s, char *msg, size_t msglen)
{
	const char *bad = NULL;
	if (s->grains < 1 || s->grains > 1000000)
		bad = "grains must be in [1, 1e6]";
	else if (!(s->d_min > 0) || !(s->d_max >= s->d_min) || !(s->d_max < 1))
		bad = "diameters must satisfy 0 < d_min <= d_max < 1 m";
	else if (!(s->density > 0) || !isfinite(s->density))
		bad = "density must be > 0";
	else if (!(s->cell_x >= 2 * s->d_max) || !(s->cell_y >= 2 * s->d_max) ||
		 !isfinite(s->cell_x) || !isfinite(s->cell_y))
		bad = "the cell must be at least 2 d_max wide in x and y";
	else if (!(s->k_over_m > 0) || !isfinite(s->k_over_m))
		bad = "k_over_m must be > 0";
	else if (!(s->restitution > 0) || !(s->restitution <= 1))
		bad = "restitution must be in (0, 1]";
	else if (!(s->mu >= 0) || !(s->mu <= 10) || !(s->mu_roll >= 0) || !(s->mu_roll <= 10))
		bad = "mu and mu_roll must be in [0, 10]";
	else if (!(s->g >= 0) || !(s->g <= 100) || !(s->settle >= 0) || !(s->settle <= 100))
		bad = "g must be in [0, 100] m/s^2 and settle in [0, 100] s";
	else if (!(s->wiggle_period >= 0) || !isfinite(s->wiggle_x) || !isfinite(s->wiggle_z) ||
		 (s->wiggle_period > 0 &&
		  (s->grains != 1 || fabs(s->wiggle_x) > 0.01 || fabs(s->wiggle_z) > 0.01)))
		bad = "the moving floor takes one grain and amplitudes of at most 0.01 m";
	else if (s->hertz &&
		 (!(s->youngs >= 5e6) || !(s->youngs <= 1e9) || !(s->poisson > 0) || !(s->poisson < 0.5) ||
		  s->wiggle_period > 0))
		bad = "hertz contacts take Young's modulus in [5e6, 1e9] Pa (LIGGGHTS's bounds), "
		      "Poisson's ratio in (0, 0.5) and no moving floor";
	else if (s->hertz && (!(s->e_pp > 0.05) || !(s->e_pp <= 1) || !(s->e_pw > 0.05) || !(s->e_pw <= 1)))
		bad = "hertz restitution must be in (0.05, 1] (LIGGGHTS's bounds)";
	else if (s->hertz && (!(s->mu_pp >= 0) || !(s->mu_pp <= 10) || !(s->mu_pw >= 0) ||
			      !(s->mu_pw <= 10) || !(s->roll_pp >= 0) || !(s->roll_pp <= 10) ||
			      !(s->roll_pw >= 0) || !(s->roll_pw <= 10)))
		bad = "hertz friction and rolling friction must be in [0, 10]";
	if (bad)
		snprintf(msg, msglen, "dem bed: %s", bad);
	return bad ? -1 : 0;
}

/* The contact law and the floor (dem.h's spec). */
static void bed_contacts(dem_bed *b)
{
	const dem_bed_spec *s = &b->spec;
	double kn = s->k_over_m * b->m_mean;
	double zeta = dem_restitution_damping(s->restitution);
	/* hooke/stiffness multiplies gamma by the contact's effective mass:
	 * 2 zeta omega for the mean grain on the floor */
	double gamman = 2 * zeta * sqrt(s->k_over_m);
	const char *roll = s->mu_roll > 0 ? " rolling_friction cdt" : "";
	/* history: a tangential spring capped by Coulomb; no_history: a
	 * viscous tangential force (gammat) capped by Coulomb, no spring */
	const char *tang = s->tangential_viscous ? "no_history" : "history";
	bed_cmd(b, "fix m1 all property/global kn peratomtypepair 1 %.17g", kn);
	bed_cmd(b, "fix m2 all property/global kt peratomtypepair 1 %.17g", kn * 2.0 / 7.0);
	bed_cmd(b, "fix m3 all property/global gamman peratomtypepair 1 %.17g", gamman);
	bed_cmd(b, "fix m4 all property/global gammat peratomtypepair 1 %.17g", gamman);
	bed_cmd(b, "fix m5 all property/global coefficientFriction peratomtypepair 1 %.17g", s->mu);
	if (s->mu_roll > 0)
		bed_cmd(b, "fix m6 all property/global coefficientRollingFriction peratomtypepair 1 %.17g",
			s->mu_roll);
	bed_cmd(b, "pair_style gran model hooke/stiffness tangential %s%s limitForce on", tang, roll);
	bed_cmd(b, "pair_coeff * *");
	if (!b->stl[0]) {
		bed_cmd(b, "fix floor all wall/gran model hooke/stiffness tangential %s%s "
			   "primitive type 1 zplane 0.0 limitForce on", tang, roll);
		return;
	}
	bed_cmd(b, "fix cad all mesh/surface file %s type 1", b->stl);
	bed_cmd(b, "fix floor all wall/gran model hooke/stiffness tangential %s%s "
		   "mesh n_meshes 1 meshes cad limitForce on", tang, roll);
}

/* A named material's contacts (dem.h, hertz): atom type 1 the grains,
 * type 2 the deck's plane, each pair's restitution, friction and rolling
 * friction in LIGGGHTS's type-pair tables (the 2-2 entry is never used);
 * the overlaps of every contact (compute pair/gran/local delta) and of
 * every grain into the plane z = 0 reduced to their maxima. */
static void bed_contacts_hertz(dem_bed *b)
{
	const dem_bed_spec *s = &b->spec;
	int roll = s->roll_pp > 0 || s->roll_pw > 0;
	const char *rf = roll ? " rolling_friction epsd2" : "";
	bed_cmd(b, "fix m1 all property/global youngsModulus peratomtype %.17g %.17g", s->youngs,
		s->youngs);
	bed_cmd(b, "fix m2 all property/global poissonsRatio peratomtype %.17g %.17g", s->poisson,
		s->poisson);
	bed_cmd(b, "fix m3 all property/global coefficientRestitution peratomtypepair 2 "
		   "%.17g %.17g %.17g %.17g", s->e_pp, s->e_pw, s->e_pw, s->e_pw);
	bed_cmd(b, "fix m4 all property/global coefficientFriction peratomtypepair 2 "
		   "%.17g %.17g %.17g %.17g", s->mu_pp, s->mu_pw, s->mu_pw, s->mu_pw);
	if (roll)
		bed_cmd(b, "fix m5 all property/global coefficientRollingFriction peratomtypepair 2 "
			   "%.17g %.17g %.17g %.17g", s->roll_pp, s->roll_pw, s->roll_pw, s->roll_pw);
	bed_cmd(b, "pair_style gran model hertz tangential history%s", rf);
	bed_cmd(b, "pair_coeff * *");
	bed_cmd(b, "fix floor all wall/gran model hertz tangential history%s primitive type 2 "
		   "zplane 0.0", rf);
}

/* The overlap computes of a hertz bed (after its grains exist). */
static void bed_overlap_computes(dem_bed *b)
{
	bed_cmd(b, "compute ovl all pair/gran/local delta");
	bed_cmd(b, "compute ovpp all reduce max c_ovl[1]");
	bed_cmd(b, "variable ovpp equal c_ovpp");
	bed_cmd(b, "compute rad all property/atom radius");
	bed_cmd(b, "variable gap atom c_rad-z");
	bed_cmd(b, "compute ovpw all reduce max v_gap");
	bed_cmd(b, "variable ovpw equal c_ovpw");
	/* compute reduce takes no update_on_run_end: the thermo output,
	 * written at every run's last step (to no screen), keeps both
	 * current for their reading between runs */
	bed_cmd(b, "thermo_style custom step v_ovpp v_ovpw");
}

void dem_bed_overlap(const dem_bed *b, double *pp, double *pw)
{
	*pp = *pw = NAN;
	if (!b->spec.hertz)
		return;
	/* no contact at all: the reduction's max is -1e20 or so; none is 0 */
	*pp = fmax(0, bed_var(b, "ovpp"));
	*pw = fmax(0, bed_var(b, "ovpw"));
}

/* The frame check's floor: a rectangle at z = 0, 2 mm inside the cell's
 * sides, as an ASCII STL file of two facets in a fresh temporary file. */
static int bed_floor_mesh(dem_bed *b)
{
	const dem_bed_spec *s = &b->spec;
	double x0 = 0.002, x1 = s->cell_x - 0.002, y0 = 0.002, y1 = s->cell_y - 0.002;
	/* LIGGGHTS reads a mesh by its name's extension */
	snprintf(b->stl, sizeof b->stl, "/tmp/convsim-dem-floor-XXXXXX.stl");
	int fd = mkstemps(b->stl, 4);
	FILE *f = fd >= 0 ? fdopen(fd, "w") : NULL;
	if (!f) {
		b->stl[0] = 0;
		return -1;
	}
	fprintf(f, "solid floor\n");
	const double tri[2][3][2] = {{{x0, y0}, {x1, y0}, {x1, y1}}, {{x0, y0}, {x1, y1}, {x0, y1}}};
	for (int t = 0; t < 2; t++) {
		fprintf(f, "facet normal 0 0 1\nouter loop\n");
		for (int v = 0; v < 3; v++)
			fprintf(f, "vertex %.17g %.17g 0\n", tri[t][v][0], tri[t][v][1]);
		fprintf(f, "endloop\nendfacet\n");
	}
	fprintf(f, "endsolid floor\n");
	return fclose(f) ? -1 : 0;
}

/* Grains on a lattice of pitch 1.05 d_max, jittered, diameters drawn
 * uniformly: both from the seed. */
static void bed_grains(dem_bed *b, double pitch, int nx, int ny)
{
	const dem_bed_spec *s = &b->spec;
	unsigned long long rng = 0x9E3779B97F4A7C15ULL ^ ((unsigned long long)s->seed * 0x100000001B3ULL);
	for (int i = 0; i < 4; i++)
		bed_random(&rng);
	for (int i = 0; i < s->grains; i++) {
		int ix = i % nx, iy = (i / nx) % ny, iz = i / (nx * ny);
		double jx = 0.02 * pitch * (bed_random(&rng) - 0.5);
		double jy = 0.02 * pitch * (bed_random(&rng) - 0.5);
		double d = s->d_min + (s->d_max - s->d_min) * bed_random(&rng);
		double x = s->wiggle_period > 0 ? 0.5 * s->cell_x : (ix + 0.5) * pitch + jx;
		double y = s->wiggle_period > 0 ? 0.5 * s->cell_y : (iy + 0.5) * pitch + jy;
		bed_cmd(b, "create_atoms 1 single %.17g %.17g %.17g units box", x, y,
			(iz + 0.5) * pitch + 0.1 * s->d_max);
		bed_cmd(b, "set atom %d diameter %.17g density %.17g", i + 1, d, s->density);
	}
}

/* LIGGGHTS opened for bed b, on communicator comm or without MPI: 0, or
 * -1 with msg (b is the caller's to free). */
static int bed_open(dem_bed *b, const void *comm, char *msg, size_t msglen)
{
	const dem_bed_spec *s = &b->spec;
	/* CONVSIM_DEM_LOG names a file for LIGGGHTS's own output (its error
	 * messages among it): the one way to see why it ended the process */
	const char *screen = getenv("CONVSIM_DEM_LOG");
	/* the mesh reader writes to the screen unasked: /dev/null, not none */
	if (!screen)
		screen = s->wiggle_period > 0 ? "/dev/null" : "none";
	char *args[] = {"liggghts", "-log", "none", "-screen", (char *)screen, NULL};
	if (comm)
		lammps_open(5, args, *(const MPI_Comm *)comm, &b->lmp);
	else
		lammps_open_no_mpi(5, args, &b->lmp);
	if (!b->lmp) {
		snprintf(msg, msglen, "dem bed: LIGGGHTS did not open");
		return -1;
	}
	return 0;
}

/* What the bed reports: its mass, centre, momentum and energies as
 * LIGGGHTS variables (bed_var). */
static void bed_observers(dem_bed *b)
{
	bed_cmd(b, "compute ke all ke update_on_run_end yes");
	bed_cmd(b, "variable m equal mass(all)");
	bed_cmd(b, "variable xm equal xcm(all,x)");
	bed_cmd(b, "variable zm equal xcm(all,z)");
	bed_cmd(b, "variable px equal mass(all)*vcm(all,x)");
	bed_cmd(b, "variable pz equal mass(all)*vcm(all,z)");
	bed_cmd(b, "variable ke equal c_ke");
	bed_cmd(b, "compute rke all erotate/sphere update_on_run_end yes");
	bed_cmd(b, "variable rke equal c_rke");
}

dem_bed *dem_bed_new(const dem_bed_spec *spec, const void *comm, char *msg, size_t msglen)
{
	if (spec_check(spec, msg, msglen))
		return NULL;
	dem_bed *b = calloc(1, sizeof *b);
	if (!b) {
		snprintf(msg, msglen, "dem bed: out of memory");
		return NULL;
	}
	b->spec = *spec;
	const dem_bed_spec *s = &b->spec;
	double pitch = 1.05 * s->d_max;
	int nx = (int)floor(s->cell_x / pitch), ny = (int)floor(s->cell_y / pitch);
	int nz = (s->grains + nx * ny - 1) / (nx * ny);
	b->m_mean = dem_bed_spec_mass_mean(s);
	b->dt = dem_bed_spec_dt(s);
	double z_top = 4 * nz * pitch + 20 * s->d_max;

	if (bed_open(b, comm, msg, msglen)) {
		free(b);
		return NULL;
	}
	bed_cmd(b, "atom_style granular");
	bed_cmd(b, "atom_modify map array");
	/* the moving floor's closed cell: LIGGGHTS's atom sorting finds a bin
	 * size of 0 there with an overdamped contact and stops; one grain
	 * needs no sorting */
	if (s->wiggle_period > 0)
		bed_cmd(b, "atom_modify sort 0 0.0");
	if (s->wiggle_period > 0 && bed_floor_mesh(b)) {
		snprintf(msg, msglen, "dem bed: the floor mesh's file could not be written");
		dem_bed_free(b);
		return NULL;
	}
	bed_cmd(b, "boundary %s", s->wiggle_period > 0 ? "f f f" : "p p f");
	/* ranks split the cell along the deck and across, never in height:
	 * the box is four times the bed's height, and a split there left the
	 * upper rank empty (two ranks cost what one did) */
	bed_cmd(b, "processors * * 1");
	bed_cmd(b, "newton off");
	bed_cmd(b, "communicate single vel yes");
	bed_cmd(b, "units si");
	/* below the floor: room for the moving floor's mesh */
	bed_cmd(b, "region cell block 0 %.17g 0 %.17g %.17g %.17g units box", s->cell_x, s->cell_y,
		s->wiggle_period > 0 ? -0.02 : 0.0, z_top);
	bed_cmd(b, "create_box %d cell", s->hertz ? 2 : 1);
	bed_cmd(b, "neighbor %.17g bin", 0.2 * s->d_max);
	bed_cmd(b, "neigh_modify delay 0");
	if (s->hertz)
		bed_contacts_hertz(b);
	else
		bed_contacts(b);
	bed_cmd(b, "timestep %.17g", b->dt);
	bed_grains(b, pitch, nx, ny);
	if (s->hertz)
		bed_overlap_computes(b);
	bed_cmd(b, "fix deck all gravity %.17g vector 0 0 -1", s->g);
	bed_cmd(b, "fix step all %s", s->freeze_rotation ? "nve" : "nve/sphere");
	bed_observers(b);
	if (s->settle > 0)
		bed_cmd(b, "run %ld", (long)ceil(s->settle / b->dt));
	else
		bed_cmd(b, "run 0");
	if (s->wiggle_period > 0) { /* the floor starts moving, the grain with it */
		double w = 2 * M_PI / s->wiggle_period;
		bed_cmd(b, "velocity all set %.17g 0 %.17g units box", w * s->wiggle_x, w * s->wiggle_z);
		bed_cmd(b, "fix move all move/mesh mesh cad wiggle amplitude %.17g 0 %.17g period %.17g",
			s->wiggle_x, s->wiggle_z, s->wiggle_period);
	}
	bed_cmd(b, "variable now equal time");
	b->t_zero = bed_var(b, "now");
	bed_cmd(b, "variable t equal time-%.17g", b->t_zero);
	b->t = 0;
	return b;
}

void dem_bed_free(dem_bed *b)
{
	if (!b)
		return;
	if (b->lmp)
		lammps_close(b->lmp);
	if (b->stl[0])
		unlink(b->stl);
	free(b);
}

double dem_bed_dt(const dem_bed *b)
{
	return b->dt;
}

/* Advance over `interval` with the deck's acceleration (ax, ay) given as
 * LIGGGHTS equal-style expressions (numbers, or formulas of v_t): a fix
 * addforce of atom-style variables, evaluated at every DEM step. Once the
 * fix stands and the step is unchanged, each run continues the one before
 * without LIGGGHTS's set-up ("pre no"): a set-up re-evaluates the forces
 * and so restarts the tangential springs' integration, which biased v by
 * -7 % when a run held 4 DEM steps (one grain, preset contacts, held
 * acceleration; docs/dem.md "One grain"). */
static void bed_run_deck(dem_bed *b, const char *ax, const char *ay, double interval)
{
	long n = (long)ceil(interval / b->dt * (1 - 1e-12));
	double step = interval / (double)n;
	int cont = b->drive && step == b->step;
	if (!cont)
		bed_cmd(b, "timestep %.17g", step);
	if (!b->drive) {
		/* per grain: its mass times g_eff = (-a_x, 0, -g - a_y); fx
		 * and fz before ax and ay in LIGGGHTS's list of variables:
		 * a redefined variable moves to the list's end, and the
		 * addforce fix holds fx's and fz's places from its set-up */
		bed_cmd(b, "variable fx atom -mass*v_ax");
		bed_cmd(b, "variable fz atom -mass*(%.17g+v_ay)", b->spec.g);
		bed_cmd(b, "unfix deck");
		bed_cmd(b, "fix deck all addforce v_fx 0.0 v_fz");
		b->drive = 1;
	}
	bed_cmd(b, "variable ax equal %s", ax);
	bed_cmd(b, "variable ay equal %s", ay);
	bed_cmd(b, cont ? "run %ld pre no post no" : "run %ld post no", n);
	b->step = step;
	b->t += interval;
}

int dem_bed_advance(dem_bed *b, double ax, double ay, double interval, char *msg, size_t msglen)
{
	if (!isfinite(ax) || !isfinite(ay) || !(interval > 0) || !isfinite(interval)) {
		snprintf(msg, msglen, "dem bed: the deck's acceleration and the interval must be finite, "
				      "the interval > 0");
		return -1;
	}
	char fx[40], fy[40];
	snprintf(fx, sizeof fx, "%.17g", ax);
	snprintf(fy, sizeof fy, "%.17g", ay);
	bed_run_deck(b, fx, fy, interval);
	return 0;
}

/* A formula for LIGGGHTS: numbers, v_t, + - * / ( ) . e and the names
 * of its math functions only, so that LIGGGHTS never sees a command it
 * refuses from here. */
static int bed_formula_ok(const char *f)
{
	size_t n = f ? strlen(f) : 0;
	if (n == 0 || n > 1500)
		return 0;
	for (const char *c = f; *c; c++)
		if (!strchr("0123456789.+-*/()_ eEvtcosinqrxp", *c))
			return 0;
	return 1;
}

int dem_bed_advance_drive(dem_bed *b, const char *ax, const char *ay, double interval, char *msg,
			  size_t msglen)
{
	if (!bed_formula_ok(ax) || !bed_formula_ok(ay) || !(interval > 0) || !isfinite(interval)) {
		snprintf(msg, msglen, "dem bed: the deck's acceleration must be a formula of v_t "
				      "(numbers, + - * / ( ), sin, cos, exp, sqrt) and the interval > 0");
		return -1;
	}
	bed_run_deck(b, ax, ay, interval);
	return 0;
}

void dem_bed_get(const dem_bed *b, dem_bed_state *st)
{
	st->t = b->t;
	st->mass = bed_var(b, "m");
	st->x_mean = bed_var(b, "xm");
	st->z_mean = bed_var(b, "zm");
	st->p_x = bed_var(b, "px");
	st->p_z = bed_var(b, "pz");
	st->kinetic = bed_var(b, "ke");
	st->kinetic_rot = bed_var(b, "rke");
}
