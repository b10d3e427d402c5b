/*
 * workprec.c - work-precision benchmark of the integrators (`make bench`).
 *
 *   workprec scene NAME [quick]   run one scene's reference and ladders,
 *                                 one TSV row per run on stdout
 *   workprec report DIR CMD       read the scenes' TSV files in DIR, write DIR/workprec.md and
 *                                 DIR/workprec.svg (CMD: the command line
 *                                 that made them, printed at the top)
 *
 * Scenes: "nofeed" (the machine without feed, Kloss motor start), "full"
 * (czubak2016: 5 x 8 feed, motor start, beta 38 deg, cw), "reduced" (the
 * same with trough_rotation=false: alpha dropped, one column counting 5
 * times), "reductions" (each model reduction against the full model at
 * equal integrator settings).
 *
 * For every run: CPU seconds per simulated second (CLOCK_PROCESS_CPUTIME_ID,
 * one thread), the RMS distance of the trough's (x, y) from the reference
 * over the first 20 excitation periods (0.8 s of samples every 2 ms, which
 * every fixed step of the ladders divides, so sampling never cuts a step),
 * the transport velocity over [2 s, horizon] and its relative error, and
 * the energy-balance residual at the end.
 *
 * References. Trajectory: the finest run of two different methods; the
 * RMS distance between them is the reference's uncertainty and is printed.
 * Transport velocity: dem at its finest step, confirmed by Richardson
 * extrapolation of the three finest rk4 runs (observed order from the three,
 * limit from the two finest); both values and their difference are printed.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim.h"

#define SAMPLE_DT 2e-3
enum { NSAMP = 400 }; /* 0.8 s = 20 periods of omega_ss = 157.08 rad/s */

/* ---- one run --------------------------------------------------------- */

typedef struct run_spec {
	const char *method;
	double dt;       /* fixed or macro step; dopri5: first step */
	int substeps;    /* dem */
	double rtol;     /* dopri5 (atol = 1e-3 rtol) */
	double horizon;  /* s */
} run_spec;

typedef struct run_out {
	int err;
	char msg[200];
	double cpu, t;   /* CPU s, simulated s */
	double v, e_res, e_in;
	unsigned long long steps;
	int nsamp;
	double x[NSAMP], y[NSAMP];
} run_out;

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static void apply(sim_params *p, sim_scene *sc, sim_method *m, const char *const *sets)
{
	char msg[200];
	for (int i = 0; sets && sets[i]; i += 2)
		if (sim_set_str(p, sc, m, sets[i], sets[i + 1], msg, sizeof msg) != SIM_OK) {
			fprintf(stderr, "workprec: %s=%s: %s\n", sets[i], sets[i + 1], msg);
			exit(2);
		}
}

/* Runs the preset with the scene's settings `sets` (NULL-terminated
 * name/value pairs) and the method of rs. */
static void run(const char *const *sets, const run_spec *rs, run_out *o)
{
	sim_params p;
	sim_scene sc;
	sim_method m;
	sim_preset_czubak2016(&p, &sc, &m);
	apply(&p, &sc, &m, sets);
	snprintf(m.name, sizeof m.name, "%s", rs->method);
	m.dt = rs->dt;
	m.substeps = rs->substeps > 0 ? rs->substeps : 1;
	if (rs->rtol > 0) {
		m.rtol = rs->rtol;
		m.atol = 1e-3 * rs->rtol;
	}
	memset(o, 0, sizeof *o);
	o->v = NAN;
	int err;
	sim *s = sim_new(&p, &sc, &m, &err, o->msg, sizeof o->msg);
	if (!s) {
		o->err = err;
		return;
	}
	double c0 = cpu_now();
	sim_status st;
	for (int i = 0; i < NSAMP && (i + 1) * SAMPLE_DT <= rs->horizon + 1e-12; i++) {
		o->err = sim_advance(s, (i + 1) * SAMPLE_DT);
		if (o->err)
			break;
		sim_get_status(s, &st);
		o->x[i] = st.q[0];
		o->y[i] = st.q[1];
		o->nsamp = i + 1;
	}
	if (!o->err)
		o->err = sim_advance(s, rs->horizon);
	o->cpu = cpu_now() - c0;
	if (o->err)
		snprintf(o->msg, sizeof o->msg, "%s", sim_last_error(s));
	sim_get_status(s, &st);
	o->t = st.t;
	o->v = st.transport_velocity;
	o->e_res = st.e_residual;
	o->e_in = st.e_input;
	o->steps = (unsigned long long)st.steps;
	sim_free(s);
}

/* RMS distance of two trough trajectories over their common samples. */
static double traj_rms(const run_out *a, const run_out *b)
{
	int n = a->nsamp < b->nsamp ? a->nsamp : b->nsamp;
	double s = 0.0;
	for (int i = 0; i < n; i++) {
		double dx = a->x[i] - b->x[i], dy = a->y[i] - b->y[i];
		s += dx * dx + dy * dy;
	}
	return n > 0 ? sqrt(s / n) : NAN;
}

static double traj_amplitude(const run_out *a)
{
	double s = 0.0;
	for (int i = 0; i < a->nsamp; i++)
		s += a->x[i] * a->x[i] + a->y[i] * a->y[i];
	return a->nsamp > 0 ? sqrt(s / a->nsamp) : NAN;
}

static void setting_label(const run_spec *rs, char *buf, size_t n)
{
	if (strcmp(rs->method, "dopri5") == 0)
		snprintf(buf, n, "rtol=%g", rs->rtol);
	else if (strcmp(rs->method, "dem") == 0)
		snprintf(buf, n, "dt=%g,substeps=%d", rs->dt, rs->substeps);
	else
		snprintf(buf, n, "dt=%g", rs->dt);
}

/* TSV row: kind scene variant method setting horizon cpu_per_s rtf
 * traj_rms traj_rel v v_rel e_res e_res_rel steps err */
static void row(const char *kind, const char *scene, const char *variant, const run_spec *rs,
		const run_out *o, const run_out *tref, double vref)
{
	char lab[64];
	setting_label(rs, lab, sizeof lab);
	double cps = o->t > 0 ? o->cpu / o->t : NAN;
	double tr = tref && o->nsamp > 0 ? traj_rms(o, tref) : NAN;
	double amp = tref ? traj_amplitude(tref) : NAN;
	double vrel = isfinite(vref) && isfinite(o->v) ? fabs(o->v - vref) / fabs(vref) : NAN;
	printf("%s\t%s\t%s\t%s\t%s\t%g\t%.6g\t%.6g\t%.6g\t%.6g\t%.9g\t%.6g\t%.6g\t%.6g\t%llu\t%s\n",
	       kind, scene, variant, rs->method, lab, rs->horizon, cps, cps > 0 ? 1.0 / cps : NAN,
	       tr, tr / amp, o->v, vrel, o->e_res, o->e_in > 0 ? fabs(o->e_res) / o->e_in : NAN,
	       o->steps, o->err ? o->msg : "ok");
	fflush(stdout);
}

/* ---- scenes ---------------------------------------------------------- */

static const char *const S_NOFEED[] = {"feed", "false", NULL};
static const char *const S_FULL[] = {NULL};
static const char *const S_REDUCED[] = {"trough_rotation", "false", NULL};

static int quick;

static run_out *new_out(void)
{
	run_out *o = malloc(sizeof *o);
	if (!o) {
		fprintf(stderr, "workprec: out of memory\n");
		exit(1);
	}
	return o;
}

/* A ladder of runs against the given references. */
static void ladder(const char *scene, const char *const *sets, const run_spec *specs, int n,
		   const run_out *tref, double vref)
{
	run_out *o = new_out();
	for (int i = 0; i < n; i++) {
		run(sets, &specs[i], o);
		row("run", scene, "-", &specs[i], o, tref, vref);
	}
	free(o);
}

static void scene_nofeed(void)
{
	double H = quick ? 1.0 : 2.0;
	/* references: dopri5 at rtol 1e-12 and rk4 at 2.5e-6 s */
	run_spec ra = {"dopri5", 1e-4, 1, 1e-12, H}, rb = {"rk4", 2.5e-6, 1, 0, H};
	run_out *a = new_out(), *b = new_out();
	run(S_NOFEED, &ra, a);
	run(S_NOFEED, &rb, b);
	row("ref", "nofeed", "trajectory", &ra, a, a, NAN);
	row("refcheck", "nofeed", "trajectory", &rb, b, a, NAN);
	run_spec L[] = {
		{"rk4", 2e-3, 1, 0, H},      {"rk4", 1e-3, 1, 0, H},     {"rk4", 5e-4, 1, 0, H},
		{"rk4", 2.5e-4, 1, 0, H},    {"rk4", 1e-4, 1, 0, H},     {"rk4", 5e-5, 1, 0, H},
		{"rk4", 2.5e-5, 1, 0, H},    {"euler", 2e-4, 1, 0, H},   {"euler", 1e-4, 1, 0, H},
		{"euler", 5e-5, 1, 0, H},    {"euler", 2.5e-5, 1, 0, H}, {"euler", 1e-5, 1, 0, H},
		{"euler", 5e-6, 1, 0, H},    {"euler", 2.5e-6, 1, 0, H}, {"dem", 2e-3, 1, 0, H},
		{"dem", 1e-3, 1, 0, H},      {"dem", 5e-4, 1, 0, H},     {"dem", 2.5e-4, 1, 0, H},
		{"dem", 1e-4, 1, 0, H},      {"dopri5", 1e-4, 1, 1e-3, H}, {"dopri5", 1e-4, 1, 1e-4, H},
		{"dopri5", 1e-4, 1, 1e-5, H}, {"dopri5", 1e-4, 1, 1e-6, H}, {"dopri5", 1e-4, 1, 1e-7, H},
		{"dopri5", 1e-4, 1, 1e-8, H}, {"dopri5", 1e-4, 1, 1e-10, H},
	};
	int n = (int)(sizeof L / sizeof L[0]);
	ladder("nofeed", S_NOFEED, L, n, a, NAN);
	free(a);
	free(b);
}

/* Full and reduced scenes: the same ladders. */
static void scene_feed(const char *scene, const char *const *sets)
{
	double H = quick ? 3.0 : 6.0;
	/* dopri5 takes millions of floor steps (1e-7 s) per simulated second
	 * in the feed's sliding modes: capped to the trajectory window */
	double Hdp = quick ? 0.1 : 0.8;
	/* trajectory and velocity reference A: dem at h = 1e-6 s */
	run_spec ra = {"dem", 1e-5, 10, 0, H};
	run_out *a = new_out();
	run(sets, &ra, a);
	/* rk4 ladder; its three finest runs give the Richardson check */
	run_spec rl[] = {{"rk4", 2e-5, 1, 0, H},   {"rk4", 1e-5, 1, 0, H},
			 {"rk4", 5e-6, 1, 0, H},   {"rk4", 2.5e-6, 1, 0, H},
			 {"rk4", 1.25e-6, 1, 0, H}, {"rk4", 6.25e-7, 1, 0, H},
			 {"rk4", 3.125e-7, 1, 0, H}};
	int nr = (int)(sizeof rl / sizeof rl[0]);
	if (quick)
		nr = 4;
	run_out *r = calloc((size_t)nr, sizeof *r);
	if (!r)
		exit(1);
	for (int i = 0; i < nr; i++)
		run(sets, &rl[i], &r[i]);
	double v1 = r[nr - 3].v, v2 = r[nr - 2].v, v3 = r[nr - 1].v;
	double ratio = (v1 - v2) / (v2 - v3);
	double order = log(ratio) / log(2.0);
	double vrich = v3 - (v2 - v3) / (ratio - 1.0);
	double vref = a->v;
	/* the same extrapolation sample by sample for the trajectory, with
	 * the order observed on the trajectories' RMS differences */
	run_out *rt = new_out();
	*rt = r[nr - 1];
	double tp = log(traj_rms(&r[nr - 3], &r[nr - 2]) / traj_rms(&r[nr - 2], &r[nr - 1])) /
		    log(2.0);
	double fac = 1.0 / (pow(2.0, tp) - 1.0);
	for (int i = 0; i < rt->nsamp; i++) {
		rt->x[i] += (r[nr - 1].x[i] - r[nr - 2].x[i]) * fac;
		rt->y[i] += (r[nr - 1].y[i] - r[nr - 2].y[i]) * fac;
	}
	row("ref", scene, "dem_finest", &ra, a, a, vref);
	printf("richardson\t%s\trk4\t%.9g\t%.4g\t%.9g\t%.6g\t%.6g\t%.4g\n", scene, v3, order,
	       vrich, fabs(vrich - vref) / vref, traj_rms(rt, a) / traj_amplitude(a), tp);
	free(rt);
	for (int i = 0; i < nr; i++)
		row("run", scene, "-", &rl[i], &r[i], a, vref);
	free(r);
	run_spec L[] = {
		{"euler", 2e-5, 1, 0, H},        {"euler", 1e-5, 1, 0, H},
		{"euler", 5e-6, 1, 0, H},        {"euler", 2.5e-6, 1, 0, H},
		{"euler", 1.25e-6, 1, 0, H},     {"dem", 2e-3, 1, 0, H},
		{"dem", 1e-3, 1, 0, H},          {"dem", 5e-4, 1, 0, H},
		{"dem", 2.5e-4, 1, 0, H},        {"dem", 1e-4, 1, 0, H},
		{"dem", 5e-5, 1, 0, H},          {"dem", 2e-5, 1, 0, H},
		{"dem", 2e-3, 2, 0, H},          {"dem", 2e-3, 4, 0, H},
		{"dem", 1e-3, 2, 0, H},          {"dem", 1e-3, 4, 0, H},
		{"dem", 5e-4, 4, 0, H},          {"dem", 1e-4, 4, 0, H},
		{"dem", 5e-4, 5, 0, H},          {"dem", 1e-3, 10, 0, H}, /* the default */
		{"dopri5", 1e-4, 1, 1e-3, Hdp},  {"dopri5", 1e-4, 1, 1e-4, Hdp},
		{"dopri5", 1e-4, 1, 1e-5, Hdp},
	};
	int n = (int)(sizeof L / sizeof L[0]);
	if (quick)
		n -= 1;
	ladder(scene, sets, L, n, a, vref);
	free(a);
}

/* Each reduction against the full model at equal integrator settings. */
static void scene_reductions(void)
{
	double H = quick ? 3.0 : 6.0;
	static const char *const v_full[] = {NULL};
	static const char *const v_sym[] = {"trough_rotation", "false", NULL};
	static const char *const v_ideal[] = {"drive", "ideal", NULL};
	static const char *const v_l4[] = {"layers", "4", NULL};
	static const char *const v_l4m[] = {"layers", "4", "m_n", "1", NULL};
	static const char *const v_oneway[] = {"feed_coupling", "false", NULL};
	static const char *const v_sym_ideal[] = {"trough_rotation", "false", "drive", "ideal",
						  NULL};
	static const char *const v_sym_l4[] = {"trough_rotation", "false", "layers", "4", NULL};
	static const char *const v_sym_ideal_l4[] = {"trough_rotation", "false", "drive", "ideal",
						     "layers", "4", NULL};
	struct {
		const char *name;
		const char *const *sets;
		int traj; /* trajectory comparable with the full model's */
	} V[] = {
		{"full", v_full, 1},
		{"symmetric", v_sym, 1},
		{"ideal_drive", v_ideal, 0},
		{"layers_4", v_l4, 1},
		{"layers_4_same_mass", v_l4m, 1},
		{"one_way", v_oneway, 1},
		{"symmetric+ideal", v_sym_ideal, 0},
		{"symmetric+layers_4", v_sym_l4, 1},
		{"symmetric+ideal+layers_4", v_sym_ideal_l4, 0},
	};
	int nv = (int)(sizeof V / sizeof V[0]);
	run_spec settings[] = {{"dem", 1e-4, 1, 0, H}, {"dem", 1e-3, 1, 0, H}};
	run_out *full = new_out(), *o = new_out();
	for (int si = 0; si < 2; si++) {
		for (int i = 0; i < nv; i++) {
			run_out *dst = i == 0 ? full : o;
			run(V[i].sets, &settings[si], dst);
			/* repeat the cheap runs for a stable CPU time */
			double cpu = dst->cpu;
			for (int rep = 0; rep < 2; rep++) {
				run_out *tmp = new_out();
				run(V[i].sets, &settings[si], tmp);
				cpu = fmin(cpu, tmp->cpu);
				free(tmp);
			}
			dst->cpu = cpu;
			row("reduction", "reductions", V[i].name, &settings[si], dst,
			    V[i].traj ? full : NULL, full->v);
		}
	}
	free(full);
	free(o);
}

/* ---- report ---------------------------------------------------------- */

typedef struct rec {
	char kind[16], scene[16], variant[32], method[12], setting[40], err[200];
	double horizon, cps, rtf, tr, trel, v, vrel, eres, erel;
	unsigned long long steps;
} rec;

static int nrec;
static rec recs[512];
/* richardson rows: [0] scene, [1] method, [2] v finest, [3] order, [4] v limit,
 * [5] v difference, [6] trajectory difference, [7] trajectory order */
static char rich[4][8][64];
static int nrich;

static void read_tsv(const char *path)
{
	FILE *f = fopen(path, "r");
	if (!f)
		return;
	char line[1024];
	while (fgets(line, sizeof line, f)) {
		line[strcspn(line, "\n")] = 0;
		char *fld[20];
		int nf = 0;
		for (char *p = line; nf < 20;) {
			fld[nf++] = p;
			char *tab = strchr(p, '\t');
			if (!tab)
				break;
			*tab = 0;
			p = tab + 1;
		}
		if (strcmp(fld[0], "richardson") == 0 && nf >= 9 && nrich < 4) {
			for (int i = 0; i < 8; i++)
				snprintf(rich[nrich][i], sizeof rich[0][0], "%s", fld[i + 1]);
			nrich++;
			continue;
		}
		if (nf < 16 || nrec >= 512)
			continue;
		rec *r = &recs[nrec++];
		snprintf(r->kind, sizeof r->kind, "%s", fld[0]);
		snprintf(r->scene, sizeof r->scene, "%s", fld[1]);
		snprintf(r->variant, sizeof r->variant, "%s", fld[2]);
		snprintf(r->method, sizeof r->method, "%s", fld[3]);
		snprintf(r->setting, sizeof r->setting, "%s", fld[4]);
		r->horizon = strtod(fld[5], NULL);
		r->cps = strtod(fld[6], NULL);
		r->rtf = strtod(fld[7], NULL);
		r->tr = strtod(fld[8], NULL);
		r->trel = strtod(fld[9], NULL);
		r->v = strtod(fld[10], NULL);
		r->vrel = strtod(fld[11], NULL);
		r->eres = strtod(fld[12], NULL);
		r->erel = strtod(fld[13], NULL);
		r->steps = strtoull(fld[14], NULL, 10);
		snprintf(r->err, sizeof r->err, "%s", fld[15]);
	}
	fclose(f);
}

static const char *fmt_g(double v, char *buf, size_t n, const char *f)
{
	if (isnan(v))
		snprintf(buf, n, "n/a");
	else
		snprintf(buf, n, f, v);
	return buf;
}

static const char *scene_title(const char *s)
{
	if (strcmp(s, "nofeed") == 0)
		return "(1) machine without feed, motor start";
	if (strcmp(s, "full") == 0)
		return "(2) full czubak2016 scene (5 x 8 feed, motor start)";
	if (strcmp(s, "reduced") == 0)
		return "(3) reduced scene (trough_rotation=false: alpha dropped, 1 column x 5)";
	return s;
}

static const rec *find_ref(const char *scene, const char *kind)
{
	for (int i = 0; i < nrec; i++)
		if (strcmp(recs[i].scene, scene) == 0 && strcmp(recs[i].kind, kind) == 0)
			return &recs[i];
	return NULL;
}

/* The fastest run of a scene within tolerance (relative v error for the
 * feed scenes, relative trajectory error for the machine alone). */
static const rec *fastest_within(const char *scene, double tol)
{
	const rec *best = NULL;
	int feed = strcmp(scene, "nofeed") != 0;
	for (int i = 0; i < nrec; i++) {
		const rec *r = &recs[i];
		if (strcmp(r->kind, "run") || strcmp(r->scene, scene) || strcmp(r->err, "ok"))
			continue;
		double e = feed ? r->vrel : r->trel;
		if (!(e <= tol))
			continue;
		if (!best || r->cps < best->cps)
			best = r;
	}
	return best;
}

static void write_md(const char *dir, const char *cmd)
{
	char path[512], b[9][32];
	snprintf(path, sizeof path, "%s/workprec.md", dir);
	FILE *f = fopen(path, "w");
	if (!f) {
		perror(path);
		exit(1);
	}
	fprintf(f, "# Work-precision benchmark\n\nMade by `%s`\n\n", cmd);
	fprintf(f,
		"One process per scene, one thread each (at most two in parallel). CPU s/sim s: "
		"CPU seconds per simulated second over the whole run (real-time factor = its "
		"inverse). Trajectory: RMS distance of the trough's (x, y) from the reference over "
		"the first 20 excitation periods (0.8 s, samples every 2 ms), in m and relative to "
		"the reference's RMS displacement. v: transport velocity over [2 s, horizon]; v "
		"error relative to the reference. Energy: the balance residual (stored change + "
		"dissipated - input) at the end, in J and relative to the input work. dopri5 on "
		"the feed scenes runs 0.8 s only (trajectory and cost; no v): in the feed's "
		"sliding modes it accepts millions of floor steps (1e-7 s) per simulated second, "
		"so rtol is capped at 1e-5.\n\n");
	const char *scenes[] = {"nofeed", "full", "reduced"};
	for (int si = 0; si < 3; si++) {
		const char *sc = scenes[si];
		int feed = si > 0;
		const rec *ref = find_ref(sc, "ref");
		if (!ref)
			continue;
		fprintf(f, "## %s\n\n", scene_title(sc));
		if (!feed) {
			const rec *chk = find_ref(sc, "refcheck");
			fprintf(f,
				"Reference: %s %s. Confirmed by %s %s: trajectories agree to "
				"%s m RMS (%s relative).\n\n",
				ref->method, ref->setting, chk ? chk->method : "?",
				chk ? chk->setting : "?", fmt_g(chk ? chk->tr : NAN, b[0], 32, "%.2e"),
				fmt_g(chk ? chk->trel : NAN, b[1], 32, "%.2e"));
		} else {
			for (int k = 0; k < nrich; k++) {
				if (strcmp(rich[k][0], sc))
					continue;
				fprintf(f,
					"Reference: %s %s (feed sub-step 1e-6 s), v = %.6f m/s. "
					"Confirmed by rk4 (a different method: smooth RK4 on the "
					"switching law): finest run v = %s m/s, observed order %s, "
					"Richardson limit %s m/s; the two references differ by "
					"%.2e relative in v. Trajectory: the rk4 runs' Richardson "
					"extrapolation (observed order %s) lies %.2e (relative RMS) "
					"from the reference. Errors below these are not resolved "
					"(shaded in the plot).\n\n",
					ref->method, ref->setting, ref->v, rich[k][2], rich[k][3],
					rich[k][4], strtod(rich[k][5], NULL), rich[k][7],
					strtod(rich[k][6], NULL));
			}
		}
		fprintf(f,
			"| method | setting | horizon s | CPU s/sim s | real-time x | traj RMS m | "
			"traj rel | v m/s | v rel err | energy res J | res/input | steps |\n"
			"|---|---|---|---|---|---|---|---|---|---|---|---|\n");
		for (int i = 0; i < nrec; i++) {
			const rec *r = &recs[i];
			if (strcmp(r->scene, sc) || strcmp(r->kind, "run"))
				continue;
			fprintf(f, "| %s | %s | %g | %s | %s | %s | %s | %s | %s | %s | %s | %llu |%s%s\n",
				r->method, r->setting, r->horizon, fmt_g(r->cps, b[0], 32, "%.3g"),
				fmt_g(r->rtf, b[1], 32, "%.3g"), fmt_g(r->tr, b[2], 32, "%.2e"),
				fmt_g(r->trel, b[3], 32, "%.2e"), fmt_g(r->v, b[4], 32, "%.5f"),
				fmt_g(r->vrel, b[5], 32, "%.2e"), fmt_g(r->eres, b[6], 32, "%.3g"),
				fmt_g(r->erel, b[7], 32, "%.2e"), r->steps,
				strcmp(r->err, "ok") ? " " : "", strcmp(r->err, "ok") ? r->err : "");
		}
		const rec *best = fastest_within(sc, feed ? 0.01 : 0.01);
		if (best)
			fprintf(f,
				"\n**Fastest within 1 %% of the reference %s:** %s %s, %.3g CPU s "
				"per simulated s (%.0fx real time), %s error %.2e.\n\n",
				feed ? "transport velocity" : "trajectory", best->method,
				best->setting, best->cps, best->rtf, feed ? "v" : "trajectory",
				feed ? best->vrel : best->trel);
	}
	/* reductions */
	int any = 0;
	for (int i = 0; i < nrec; i++)
		any |= strcmp(recs[i].kind, "reduction") == 0;
	if (any) {
		fprintf(f,
			"## Model reductions against the full model\n\n"
			"Same integrator and settings for both (dem as given), horizon as given; "
			"CPU time the best of three runs. Trajectory compared over the first 20 "
			"periods where the start-up is the same (not with the ideal drive, which "
			"ramps the speed instead of starting the motor).\n\n"
			"| reduction | integrator | CPU s/sim s | speed-up | real-time x | traj RMS m "
			"| traj rel | v m/s | v diff rel |\n|---|---|---|---|---|---|---|---|---|\n");
		double full_cps = NAN;
		for (int i = 0; i < nrec; i++) {
			const rec *r = &recs[i];
			if (strcmp(r->kind, "reduction"))
				continue;
			if (strcmp(r->variant, "full") == 0)
				full_cps = r->cps;
			fprintf(f, "| %s | %s %s | %s | %s | %s | %s | %s | %s | %s |\n", r->variant,
				r->method, r->setting, fmt_g(r->cps, b[0], 32, "%.3g"),
				fmt_g(full_cps / r->cps, b[1], 32, "%.2f"),
				fmt_g(r->rtf, b[2], 32, "%.0f"), fmt_g(r->tr, b[3], 32, "%.2e"),
				fmt_g(r->trel, b[4], 32, "%.2e"), fmt_g(r->v, b[5], 32, "%.5f"),
				fmt_g(r->vrel, b[6], 32, "%.2e"));
		}
		fprintf(f, "\n");
	}
	fprintf(f, "Plot: `workprec.svg` (error on log x, CPU s per simulated s on log y).\n");
	fclose(f);
}

/* ---- SVG ------------------------------------------------------------- */

static const char *method_names[] = {"rk4", "euler", "dem", "dopri5"};
static const char *method_colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd"};

static void marker(FILE *f, int m, double x, double y)
{
	const char *c = method_colors[m];
	switch (m) {
	case 0:
		fprintf(f, "<circle cx='%.1f' cy='%.1f' r='4' fill='%s'/>\n", x, y, c);
		break;
	case 1:
		fprintf(f, "<rect x='%.1f' y='%.1f' width='8' height='8' fill='%s'/>\n", x - 4,
			y - 4, c);
		break;
	case 2:
		fprintf(f, "<path d='M%.1f %.1f l5 8 h-10 z' fill='%s'/>\n", x, y - 5, c);
		break;
	default:
		fprintf(f, "<path d='M%.1f %.1f l5 5 l-5 5 l-5 -5 z' fill='%s'/>\n", x, y - 5, c);
	}
}

enum { E_TRAJ, E_V, E_ENERGY };

static double err_of(const rec *r, int kind)
{
	return kind == E_TRAJ ? r->trel : kind == E_V ? r->vrel : r->erel;
}

/* One log-log panel at (ox, oy), size w x h. floor_err: errors below it
 * are drawn at it, hollow (not resolved by the reference). */
static void panel(FILE *f, double ox, double oy, double w, double h, const char *scene,
		  int kind, const char *title, double floor_err, double line_at)
{
	double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
	for (int i = 0; i < nrec; i++) {
		const rec *r = &recs[i];
		if (strcmp(r->kind, "run") || strcmp(r->scene, scene))
			continue;
		double e = err_of(r, kind);
		if (!isfinite(e) || !isfinite(r->cps) || r->cps <= 0)
			continue;
		e = fmax(e, floor_err);
		xmin = fmin(xmin, e);
		xmax = fmax(xmax, e);
		ymin = fmin(ymin, r->cps);
		ymax = fmax(ymax, r->cps);
	}
	if (!isfinite(xmin))
		return;
	if (line_at > 0) {
		xmin = fmin(xmin, line_at);
		xmax = fmax(xmax, line_at);
	}
	double lx0 = floor(log10(xmin)), lx1 = ceil(log10(xmax));
	double ly0 = floor(log10(ymin)), ly1 = ceil(log10(ymax));
	if (lx1 <= lx0)
		lx1 = lx0 + 1;
	if (ly1 <= ly0)
		ly1 = ly0 + 1;
	double px0 = ox + 60, px1 = ox + w - 10, py0 = oy + h - 40, py1 = oy + 25;
#define PX(e) (px0 + (log10(e) - lx0) / (lx1 - lx0) * (px1 - px0))
#define PY(c) (py0 + (log10(c) - ly0) / (ly1 - ly0) * (py1 - py0))
	fprintf(f, "<text x='%.1f' y='%.1f' font-size='13' font-weight='bold'>%s</text>\n",
		ox + 60, oy + 15, title);
	fprintf(f, "<rect x='%.1f' y='%.1f' width='%.1f' height='%.1f' fill='none' "
		   "stroke='#444'/>\n",
		px0, py1, px1 - px0, py0 - py1);
	for (double d = lx0; d <= lx1 + 1e-9; d++) {
		double x = px0 + (d - lx0) / (lx1 - lx0) * (px1 - px0);
		fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#ddd'/>\n", x,
			py0, x, py1);
		fprintf(f, "<text x='%.1f' y='%.1f' font-size='10' text-anchor='middle'>1e%d</text>\n",
			x, py0 + 14, (int)d);
	}
	for (double d = ly0; d <= ly1 + 1e-9; d++) {
		double y = py0 + (d - ly0) / (ly1 - ly0) * (py1 - py0);
		fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#ddd'/>\n", px0,
			y, px1, y);
		fprintf(f, "<text x='%.1f' y='%.1f' font-size='10' text-anchor='end'>1e%d</text>\n",
			px0 - 4, y + 3, (int)d);
	}
	const char *xl = kind == E_TRAJ ? "trajectory RMS error (relative)"
			 : kind == E_V	? "transport velocity error (relative)"
					: "|energy residual| / input";
	fprintf(f, "<text x='%.1f' y='%.1f' font-size='11' text-anchor='middle'>%s</text>\n",
		0.5 * (px0 + px1), py0 + 30, xl);
	fprintf(f,
		"<text x='%.1f' y='%.1f' font-size='11' text-anchor='middle' "
		"transform='rotate(-90 %.1f %.1f)'>CPU s per simulated s</text>\n",
		ox + 15, 0.5 * (py0 + py1), ox + 15, 0.5 * (py0 + py1));
	if (line_at > 0) {
		double x = PX(line_at);
		fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#f80' "
			   "stroke-dasharray='5,3'/>\n",
			x, py0, x, py1);
	}
	if (floor_err > 0 && floor_err > pow(10, lx0)) {
		double x = PX(floor_err);
		fprintf(f, "<rect x='%.1f' y='%.1f' width='%.1f' height='%.1f' fill='#000' "
			   "fill-opacity='0.06'/>\n",
			px0, py1, x - px0, py0 - py1);
	}
	for (int m = 0; m < 4; m++) {
		int first = 1;
		fprintf(f, "<polyline fill='none' stroke='%s' stroke-width='1' points='",
			method_colors[m]);
		for (int i = 0; i < nrec; i++) {
			const rec *r = &recs[i];
			if (strcmp(r->kind, "run") || strcmp(r->scene, scene) ||
			    strcmp(r->method, method_names[m]))
				continue;
			/* dem: the substeps=1 ladder only in the line */
			if (m == 2 && !strstr(r->setting, "substeps=1"))
				continue;
			double e = err_of(r, kind);
			if (!isfinite(e) || !(r->cps > 0))
				continue;
			fprintf(f, "%s%.1f,%.1f", first ? "" : " ", PX(fmax(e, floor_err)),
				PY(r->cps));
			first = 0;
		}
		fprintf(f, "'/>\n");
		for (int i = 0; i < nrec; i++) {
			const rec *r = &recs[i];
			if (strcmp(r->kind, "run") || strcmp(r->scene, scene) ||
			    strcmp(r->method, method_names[m]))
				continue;
			double e = err_of(r, kind);
			if (!isfinite(e) || !(r->cps > 0))
				continue;
			marker(f, m, PX(fmax(e, floor_err)), PY(r->cps));
		}
	}
#undef PX
#undef PY
}

static void write_svg(const char *dir)
{
	char path[512];
	snprintf(path, sizeof path, "%s/workprec.svg", dir);
	FILE *f = fopen(path, "w");
	if (!f) {
		perror(path);
		exit(1);
	}
	const double W = 420, H = 320;
	fprintf(f,
		"<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' "
		"font-family='sans-serif'>\n<rect width='100%%' height='100%%' fill='white'/>\n",
		3 * W, 2 * H + 40);
	/* reference uncertainty floors */
	double vfloor[2] = {0, 0}, tfloor[3] = {0, 0, 0};
	const char *sc[3] = {"nofeed", "full", "reduced"};
	const rec *chk = find_ref("nofeed", "refcheck");
	if (chk)
		tfloor[0] = chk->trel;
	for (int k = 0; k < nrich; k++) {
		int s = strcmp(rich[k][0], "full") == 0 ? 1 : 2;
		vfloor[s - 1] = strtod(rich[k][5], NULL);
		tfloor[s] = strtod(rich[k][6], NULL);
	}
	panel(f, 0, 0, W, H, sc[0], E_TRAJ, "(1) machine, no feed: trajectory", tfloor[0], 0);
	panel(f, W, 0, W, H, sc[1], E_TRAJ, "(2) full scene: trajectory", tfloor[1], 0);
	panel(f, 2 * W, 0, W, H, sc[2], E_TRAJ, "(3) reduced scene: trajectory", tfloor[2], 0);
	panel(f, 0, H, W, H, sc[1], E_ENERGY, "(2) full scene: energy residual", 0, 0);
	panel(f, W, H, W, H, sc[1], E_V, "(2) full scene: transport velocity", vfloor[0], 0.01);
	panel(f, 2 * W, H, W, H, sc[2], E_V, "(3) reduced scene: transport velocity", vfloor[1],
	      0.01);
	double ly = 2 * H + 20;
	for (int m = 0; m < 4; m++) {
		marker(f, m, 80 + 150 * m, ly);
		fprintf(f, "<text x='%d' y='%.1f' font-size='12'>%s</text>\n", 92 + 150 * m, ly + 4,
			method_names[m]);
	}
	fprintf(f,
		"<text x='700' y='%.1f' font-size='11'>shaded: below the reference's "
		"uncertainty (drawn at it); dashed: 1 %% in v; line: dem substeps=1</text>\n",
		ly + 4);
	fprintf(f, "</svg>\n");
	fclose(f);
}

int main(int argc, char **argv)
{
	if (argc >= 3 && strcmp(argv[1], "scene") == 0) {
		quick = argc >= 4 && strcmp(argv[3], "quick") == 0;
		if (strcmp(argv[2], "nofeed") == 0)
			scene_nofeed();
		else if (strcmp(argv[2], "full") == 0)
			scene_feed("full", S_FULL);
		else if (strcmp(argv[2], "reduced") == 0)
			scene_feed("reduced", S_REDUCED);
		else if (strcmp(argv[2], "reductions") == 0)
			scene_reductions();
		else
			return 2;
		return 0;
	}
	if (argc >= 4 && strcmp(argv[1], "report") == 0) {
		const char *names[] = {"nofeed", "full", "reduced", "reductions"};
		for (int i = 0; i < 4; i++) {
			char path[512];
			snprintf(path, sizeof path, "%s/%s.tsv", argv[2], names[i]);
			read_tsv(path);
		}
		write_md(argv[2], argv[3]);
		write_svg(argv[2]);
		return 0;
	}
	fprintf(stderr, "usage: workprec scene nofeed|full|reduced|reductions [quick]\n"
			"       workprec report DIR COMMAND\n");
	return 2;
}
