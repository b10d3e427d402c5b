/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * convsim_dem.c - `convsim-dem`: the feed cross-checked against LIGGGHTS.
 *
 *   convsim-dem [--preset NAME] [--set NAME=VALUE ...] [--duration S]
 *               [--transient S] [--grains N | --depth D] [--seed N] ...
 *
 * Runs the machine one-way (feed_coupling = false), fits the centre deck
 * point's motion, drives a LIGGGHTS bed with it (dem.h: the deck's
 * acceleration as a body force over a fixed floor) and prints one JSON
 * object: the DEM's transport velocity beside the column model's for the
 * same scene (its layers as --set gives them). The bed's contacts take
 * the model's own numbers unless told otherwise: stiffness over mass
 * k_c/m_n (times --stiffness), restitution R, friction mu.
 */
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "dem.h"
#include "couple.h"
#include "motion.h"
#include "tether.h"
#include "sim.h"
#include "units.h"

typedef struct dem_opts {
	sim_params p;
	sim_scene sc;
	sim_method m;
	const char *preset;
	double duration, transient, depth, stiffness, d_min, d_max, cell_x, cell_y, mu_roll, settle;
	double restitution, mu; /* NaN: the model's R and mu */
	int grains, seed, freeze_rotation, tangential_viscous, intervals, harmonics, column;
	int motion_machine, coupling_steps; /* --motion machine: the one-way machine's own deck */
	double frame_amp, frame_angle;      /* --frame-check: m, deg; amplitude 0: none */
} dem_opts;

static const struct option dem_long[] = {
	{"preset", required_argument, 0, 'p'},     {"set", required_argument, 0, 's'},
	{"duration", required_argument, 0, 'd'},   {"transient", required_argument, 0, 't'},
	{"grains", required_argument, 0, 'n'},     {"depth", required_argument, 0, 'D'},
	{"seed", required_argument, 0, 'S'},       {"stiffness", required_argument, 0, 'k'},
	{"d-min", required_argument, 0, 'a'},      {"d-max", required_argument, 0, 'b'},
	{"cell", required_argument, 0, 'x'},       {"width", required_argument, 0, 'y'},
	{"restitution", required_argument, 0, 'e'}, {"mu", required_argument, 0, 'u'},
	{"mu-roll", required_argument, 0, 'r'},    {"freeze-rotation", no_argument, 0, 'f'},
	{"intervals", required_argument, 0, 'i'},  {"harmonics", required_argument, 0, 'H'},
	{"settle", required_argument, 0, 'w'},     {"no-column", no_argument, 0, 'C'},
	{"motion", required_argument, 0, 'M'},     {"coupling-steps", required_argument, 0, 'c'},
	{"frame-check", required_argument, 0, 'F'}, {"tangential", required_argument, 0, 'T'},
	{"help", no_argument, 0, 'h'},             {0, 0, 0, 0}};

static const char dem_usage[] =
	"usage: convsim-dem [OPTIONS]\n"
	"The column model's transport velocity against a LIGGGHTS bed on the same deck motion.\n"
	"  -p, --preset NAME        model preset (czubak2016)\n"
	"  -s, --set NAME=VALUE     a setting as `convsim list` shows it; repeatable\n"
	"  -d, --duration S         simulated time (2)\n"
	"  -t, --transient S        the transport velocity ignores t < S (0.5)\n"
	"  -n, --grains N           number of grains (overrides --depth)\n"
	"  -D, --depth D            bed depth in mean diameters at packing 0.6 (8)\n"
	"  -S, --seed N             packing seed (1)\n"
	"  -k, --stiffness F        contact stiffness over mass = F k_c/m_n (1)\n"
	"      --d-min M, --d-max M grain diameters, uniform (0.0036, 0.0044 m)\n"
	"      --cell X, --width Y  periodic cell in mean diameters (20 x 4)\n"
	"  -e, --restitution E      grain on the floor (the model's R)\n"
	"  -u, --mu MU              Coulomb friction (the model's mu)\n"
	"  -r, --mu-roll MU         rolling friction, 0 for none (0)\n"
	"  -f, --freeze-rotation    grains do not rotate\n"
	"      --tangential spring|viscous  friction with a tangential spring (the default) or\n"
	"                           without one, viscous up to Coulomb (LIGGGHTS's no_history)\n"
	"  -i, --intervals N        coupling intervals a period, the deck's acceleration held over\n"
	"                           each; 0 (the default): the fit's acceleration at every DEM step\n"
	"  -H, --harmonics H        harmonics of the deck motion's fit (3)\n"
	"  -w, --settle S           settling before t = 0 (0.3 s; 0.05 s for one grain)\n"
	"      --no-column          skip the column model's run\n"
	"      --motion fit|machine fit: the deck's harmonic fit, in --intervals a period (the\n"
	"                           default); machine: the one-way machine's deck itself, its\n"
	"                           mean acceleration over every --coupling-steps machine steps, as\n"
	"                           `convsim run --set feed_model=liggghts` couples it (v from t = 0\n"
	"                           or --transient, least squares)\n"
	"      --coupling-steps N   machine steps a coupling interval (1)\n"
	"      --frame-check A:DEG  one grain on a floor moving A sin(omega_ss t) along DEG, as a\n"
	"                           body force over the fixed floor and as LIGGGHTS's moving mesh\n"
	"                           (v_body, v_mesh); no machine, no column model\n";

/* A number in [lo, hi] or exit 2 with the option's name and range. */
static double dem_number(const char *opt, const char *text, double lo, double hi)
{
	char *end;
	double v = strtod(text, &end);
	if (end == text || *end || !isfinite(v) || v < lo || v > hi) {
		fprintf(stderr, "convsim-dem: --%s must be a number in [%g, %g], got '%s'\n", opt, lo, hi,
			text);
		exit(2);
	}
	return v;
}

/* 0 for `off`, 1 for `on`, or exit 2 naming the option and both words. */
static int dem_choice(const char *opt, const char *text, const char *off, const char *on)
{
	if (!strcmp(text, off) || !strcmp(text, on))
		return !strcmp(text, on);
	fprintf(stderr, "convsim-dem: --%s must be %s or %s, got '%s'\n", opt, off, on, text);
	exit(2);
}

static void dem_parse(int argc, char **argv, dem_opts *o)
{
	int c;
	o->preset = "czubak2016";
	for (int i = 1; i < argc; i++) /* the preset first: --set applies on top */
		if ((!strcmp(argv[i], "--preset") || !strcmp(argv[i], "-p")) && i + 1 < argc)
			o->preset = argv[i + 1];
	if (sim_preset(o->preset, &o->p, &o->sc, &o->m) != SIM_OK) {
		fprintf(stderr, "convsim-dem: unknown preset '%s'\n", o->preset);
		exit(2);
	}
	o->duration = 2, o->transient = 0.5, o->depth = 8, o->stiffness = 1, o->seed = 1;
	o->d_min = 0.0036, o->d_max = 0.0044, o->cell_x = 20, o->cell_y = 4, o->settle = NAN;
	o->restitution = NAN, o->mu = NAN, o->intervals = 0, o->harmonics = 3, o->column = 1;
	o->coupling_steps = 1;
	while ((c = getopt_long(argc, argv, "p:s:d:t:n:D:S:k:e:u:r:fi:H:w:h", dem_long, NULL)) != -1) {
		char msg[200], name[64];
		const char *eq;
		switch (c) {
		case 'p': break;
		case 's':
			eq = strchr(optarg, '=');
			if (!eq || eq == optarg) {
				fprintf(stderr, "convsim-dem: --set needs NAME=VALUE, got '%s'\n", optarg);
				exit(2);
			}
			snprintf(name, sizeof name, "%.*s", (int)(eq - optarg), optarg);
			if (sim_set_user_str(&o->p, &o->sc, &o->m, name, eq + 1, msg, sizeof msg)) {
				fprintf(stderr, "convsim-dem: --set %s: %s\n", optarg, msg);
				exit(2);
			}
			break;
		case 'd': o->duration = dem_number("duration", optarg, 0.01, 1000); break;
		case 't': o->transient = dem_number("transient", optarg, 0, 1000); break;
		case 'n': o->grains = (int)dem_number("grains", optarg, 1, 1e6); break;
		case 'D': o->depth = dem_number("depth", optarg, 0.1, 1000); break;
		case 'S': o->seed = (int)dem_number("seed", optarg, 0, 1e9); break;
		case 'k': o->stiffness = dem_number("stiffness", optarg, 1e-3, 1e6); break;
		case 'a': o->d_min = dem_number("d-min", optarg, 1e-6, 0.5); break;
		case 'b': o->d_max = dem_number("d-max", optarg, 1e-6, 0.5); break;
		case 'x': o->cell_x = dem_number("cell", optarg, 2, 1000); break;
		case 'y': o->cell_y = dem_number("width", optarg, 2, 1000); break;
		case 'e': o->restitution = dem_number("restitution", optarg, 1e-3, 1); break;
		case 'u': o->mu = dem_number("mu", optarg, 0, 10); break;
		case 'r': o->mu_roll = dem_number("mu-roll", optarg, 0, 10); break;
		case 'f': o->freeze_rotation = 1; break;
		case 'i': o->intervals = (int)dem_number("intervals", optarg, 0, 100000); break;
		case 'H': o->harmonics = (int)dem_number("harmonics", optarg, 1, DEM_MAX_HARMONICS); break;
		case 'w': o->settle = dem_number("settle", optarg, 0, 100); break;
		case 'C': o->column = 0; break;
		case 'M': o->motion_machine = dem_choice("motion", optarg, "fit", "machine"); break;
		case 'T': o->tangential_viscous = dem_choice("tangential", optarg, "spring", "viscous"); break;
		case 'c': o->coupling_steps = (int)dem_number("coupling-steps", optarg, 1, 1000); break;
		case 'F':
			if (sscanf(optarg, "%lf:%lf", &o->frame_amp, &o->frame_angle) != 2 ||
			    !(o->frame_amp > 0) || !(o->frame_amp <= 0.01) || !(o->frame_angle >= 0) ||
			    !(o->frame_angle <= 180)) {
				fprintf(stderr, "convsim-dem: --frame-check must be A:DEG with A in (0, 0.01] m "
						"and DEG in [0, 180], got '%s'\n", optarg);
				exit(2);
			}
			break;
		case 'h': fputs(dem_usage, stdout); exit(0);
		default: fputs(dem_usage, stderr); exit(2);
		}
	}
	if (optind < argc || o->d_min > o->d_max || o->transient >= o->duration) {
		fprintf(stderr, "convsim-dem: %s\n", optind < argc ? "no operands are taken"
				 : o->d_min > o->d_max ? "--d-min must not exceed --d-max"
						       : "--transient must be less than --duration");
		exit(2);
	}
}

/* The bed of the options: dem_bed_spec_default's, with what they change. */
static void dem_spec(const dem_opts *o, dem_bed_spec *b)
{
	double d_mean = 0.5 * (o->d_min + o->d_max);
	dem_bed_spec_default(&o->p, o->depth * 0.004 / d_mean, b);
	b->d_min = o->d_min;
	b->d_max = o->d_max;
	b->cell_x = o->cell_x * d_mean;
	b->cell_y = o->cell_y * d_mean;
	b->grains = o->grains > 0 ? o->grains : dem_bed_grains(b->cell_x, b->cell_y, d_mean, o->depth);
	b->k_over_m *= o->stiffness;
	if (!isnan(o->restitution))
		b->restitution = o->restitution;
	if (!isnan(o->mu))
		b->mu = o->mu;
	b->mu_roll = o->mu_roll;
	b->freeze_rotation = o->freeze_rotation;
	b->tangential_viscous = o->tangential_viscous;
	b->seed = (unsigned)o->seed;
	b->settle = isnan(o->settle) ? (b->grains == 1 ? 0.05 : 0.3) : o->settle;
}

/* "  \"name\": value,\n", null where the value is not finite (JSON has no NaN). */
static void put(const char *name, double v, int last)
{
	if (isfinite(v))
		printf("  \"%s\": %.17g%s\n", name, v, last ? "" : ",");
	else
		printf("  \"%s\": null%s\n", name, last ? "" : ",");
}

/* The bed under the one-way machine's own deck, as a coupled run drives
 * it (--motion machine); 0 or -1 with msg. */
static int run_machine_motion(const dem_opts *o, dem_bed *bed, dem_prescribed *r, char *msg,
			      size_t msglen)
{
	double *acc, H;
	long n;
	if (dem_motion_sample(&o->p, &o->sc, &o->m, o->coupling_steps, o->duration, &acc, &n, &H, msg,
			      msglen) != SIM_OK)
		return -1;
	dem_bed_state st;
	dem_bed_get(bed, &st);
	r->mass = st.mass;
	r->bed_height = 2 * st.z_mean;
	r->dt = dem_bed_dt(bed);
	r->periods = NAN;
	int rc = dem_replay(bed, acc, n, H, o->transient, &r->transport_velocity, msg, msglen);
	free(acc);
	return rc;
}

/* The frame check (--frame-check): v of one grain under the body force
 * of a harmonic line motion over the fixed floor, and on LIGGGHTS's floor
 * mesh moving so; prints both. 0, or 1 with the reason on stderr. */
static int frame_check(const dem_opts *o)
{
	char msg[300];
	double w = o->p.omega_ss, T = 2 * M_PI / w, a = o->frame_angle * M_PI / 180;
	double v[2];
	dem_motion line = {.omega = w, .harmonics = 1}, still = {.omega = w, .harmonics = 1};
	line.a[2] = o->frame_amp * cos(a);
	line.b[2] = o->frame_amp * sin(a);
	for (int mesh = 0; mesh < 2; mesh++) {
		dem_bed_spec spec;
		dem_spec(o, &spec);
		spec.grains = 1;
		spec.freeze_rotation = 1;
		spec.cell_x = 1.0; /* the closed cell of the mesh: room to travel */
		/* LIGGGHTS's moving mesh wall goes wrong with an overdamped contact
		 * (R < 0.135: one grain on a floor along 30 deg ran off at -0.43
		 * m/s): the check takes R >= 0.2, which it does not depend on */
		spec.restitution = fmax(spec.restitution, 0.2);
		if (mesh) {
			spec.wiggle_x = line.a[2];
			spec.wiggle_z = line.b[2];
			spec.wiggle_period = T;
		}
		dem_prescribed r;
		dem_bed *bed = dem_bed_new(&spec, NULL, msg, sizeof msg);
		if (!bed || dem_run_prescribed(bed, mesh ? &still : &line, o->duration, o->transient,
					       o->intervals, &r, msg, sizeof msg)) {
			fprintf(stderr, "convsim-dem: %s\n", msg);
			dem_bed_free(bed);
			return 1;
		}
		dem_bed_free(bed);
		v[mesh] = r.transport_velocity;
	}
	printf("{\n  \"amplitude\": %.17g,\n  \"angle\": %.17g,\n  \"omega\": %.17g,\n", o->frame_amp,
	       o->frame_angle, w);
	printf("  \"v_body\": %.17g,\n  \"v_mesh\": %.17g\n}\n", v[0], v[1]);
	return 0;
}

int main(int argc, char **argv)
{
	sim_tether_from_env(); /* the test suite's: end with the test */
	dem_opts o;
	memset(&o, 0, sizeof o);
	dem_parse(argc, argv, &o);
	if (o.frame_amp > 0)
		return frame_check(&o);
	char msg[300];
	dem_motion mo = {.omega = NAN, .residual = NAN, .amplitude = NAN};
	int err = o.motion_machine ? SIM_OK
				   : dem_motion_fit(&o.p, &o.sc, &o.m, o.transient, o.duration,
						    o.harmonics, &mo, msg, sizeof msg);
	if (err != SIM_OK) {
		fprintf(stderr, "convsim-dem: %s\n", msg);
		return 1;
	}
	sim_measurement col = {.transport_velocity = NAN, .uncertainty = NAN};
	sim_scene one_way = o.sc;
	one_way.feed_coupling = 0;
	one_way.feed_model = SIM_FEED_COLUMN;
	one_way.transient = o.transient;
	if (o.column &&
	    sim_measure(&o.p, &one_way, &o.m, o.duration, &col, msg, sizeof msg) != SIM_OK) {
		fprintf(stderr, "convsim-dem: column model: %s\n", msg);
		return 1;
	}
	dem_bed_spec spec;
	dem_spec(&o, &spec);
	dem_bed *bed = dem_bed_new(&spec, NULL, msg, sizeof msg);
	if (!bed) {
		fprintf(stderr, "convsim-dem: %s\n", msg);
		return 1;
	}
	dem_prescribed r;
	double cpu0 = dem_cpu_now();
	if (o.motion_machine ? run_machine_motion(&o, bed, &r, msg, sizeof msg)
			     : dem_run_prescribed(bed, &mo, o.duration, o.transient, o.intervals, &r,
						  msg, sizeof msg)) {
		fprintf(stderr, "convsim-dem: %s\n", msg);
		dem_bed_free(bed);
		return 1;
	}
	if (o.motion_machine)
		r.cpu_seconds = dem_cpu_now() - cpu0;
	dem_bed_free(bed);
	double zeta = dem_restitution_damping(spec.restitution);
	printf("{\n  \"beta\": %.17g,\n  \"rotation\": \"%s\",\n", o.p.beta / RAD_PER_DEG,
	       o.p.rotation == SIM_CW ? "cw" : "ccw");
	printf("  \"motion\": \"%s\",\n  \"grains\": %d,\n", o.motion_machine ? "machine" : "fit",
	       spec.grains);
	put("bed_height", r.bed_height, 0);
	put("bed_mass", r.mass, 0);
	put("k_over_m", spec.k_over_m, 0);
	put("restitution_floor", spec.restitution, 0);
	put("restitution_pair", dem_restitution(zeta / sqrt(2)), 0);
	put("mu", spec.mu, 0);
	put("mu_roll", spec.mu_roll, 0);
	printf("  \"tangential\": \"%s\",\n", spec.tangential_viscous ? "viscous" : "spring");
	put("seed", o.seed, 0);
	put("deck_omega", mo.omega, 0);
	put("deck_fit_residual", mo.residual, 0);
	put("deck_amplitude", mo.amplitude, 0);
	put("dem_dt", r.dt, 0);
	put("intervals", o.motion_machine ? NAN : o.intervals, 0);
	put("periods", r.periods, 0);
	put("v_dem", r.transport_velocity, 0);
	put("v_column", col.transport_velocity, 0);
	put("v_column_uncertainty", col.uncertainty, 0);
	put("layers", o.sc.layers, 0);
	put("dem_cpu_seconds", r.cpu_seconds, 1);
	printf("}\n");
	return 0;
}
