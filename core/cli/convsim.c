/*
 * convsim.c - command-line runner of the simulation core.
 *
 *   convsim run   --preset czubak2016 [--set NAME=VALUE ...] --duration S
 *                 [--out FILE] [--format csv|json] [--sample-rate HZ]
 *   convsim sweep --preset czubak2016 --beta FROM:TO:STEP --rotation cw,ccw
 *                 [--set NAME=VALUE ...] [--duration S] [--threads N]
 *                 [--format csv|json]
 *   convsim list  (settings with units and ranges, integrators)
 *
 * `run` prints a JSON summary on stdout; `sweep` prints v(beta) per
 * rotation direction and reports progress on stderr. Uses the core only.
 */
#include <math.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "sim.h"
#include "units.h"

static double now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_MONOTONIC, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static double cpu_now(void)
{
	struct timespec ts;
	clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
	return (double)ts.tv_sec + 1e-9 * (double)ts.tv_nsec;
}

static int usage(void)
{
	fprintf(stderr,
		"usage: convsim run --preset NAME [--set NAME=VALUE ...] --duration S\n"
		"                   [--out FILE] [--format csv|json] [--sample-rate HZ]\n"
		"       convsim sweep --preset NAME --beta FROM:TO:STEP [--rotation cw,ccw]\n"
		"                   [--set NAME=VALUE ...] [--duration S] [--threads N]\n"
		"                   [--format csv|json]\n"
		"       convsim list\n");
	return 2;
}

typedef struct opts {
	sim_params p;
	sim_scene sc;
	sim_method m;
	const char *preset, *out, *format, *beta, *rotation;
	double duration, rate;
	int threads;
} opts;

/* Parse the options shared by run and sweep. Returns 0 or an exit code. */
static int parse(int argc, char **argv, opts *o)
{
	o->preset = "czubak2016";
	o->format = NULL;
	o->duration = -1.0;
	o->rate = 1000.0;
	o->threads = 2;
	o->rotation = "cw,ccw";
	sim_preset(o->preset, &o->p, &o->sc, &o->m);
	/* the preset first, so that --set applies on top of it */
	for (int i = 2; i < argc - 1; i++)
		if (strcmp(argv[i], "--preset") == 0)
			o->preset = argv[i + 1];
	if (sim_preset(o->preset, &o->p, &o->sc, &o->m) != SIM_OK) {
		fprintf(stderr, "convsim: unknown preset '%s' (known: czubak2016)\n", o->preset);
		return 2;
	}
	for (int i = 2; i < argc; i++) {
		const char *a = argv[i], *v = i + 1 < argc ? argv[i + 1] : NULL;
		if (!v)
			return usage();
		i++;
		char msg[200];
		if (strcmp(a, "--preset") == 0) {
			continue;
		} else if (strcmp(a, "--set") == 0) {
			const char *eq = strchr(v, '=');
			if (!eq) {
				fprintf(stderr, "convsim: --set needs NAME=VALUE, got '%s'\n", v);
				return 2;
			}
			char name[64];
			snprintf(name, sizeof name, "%.*s", (int)(eq - v), v);
			if (sim_set_user_str(&o->p, &o->sc, &o->m, name, eq + 1, msg, sizeof msg) !=
			    SIM_OK) {
				fprintf(stderr, "convsim: %s\n", msg);
				return 2;
			}
		} else if (strcmp(a, "--duration") == 0) {
			o->duration = atof(v);
		} else if (strcmp(a, "--out") == 0) {
			o->out = v;
		} else if (strcmp(a, "--format") == 0) {
			o->format = v;
		} else if (strcmp(a, "--sample-rate") == 0) {
			o->rate = atof(v);
		} else if (strcmp(a, "--beta") == 0) {
			o->beta = v;
		} else if (strcmp(a, "--rotation") == 0) {
			o->rotation = v;
		} else if (strcmp(a, "--threads") == 0) {
			o->threads = atoi(v);
		} else {
			fprintf(stderr, "convsim: unknown option '%s'\n", a);
			return usage();
		}
	}
	if (o->format && strcmp(o->format, "csv") != 0 && strcmp(o->format, "json") != 0) {
		fprintf(stderr, "convsim: --format must be csv or json\n");
		return 2;
	}
	if (!(o->rate > 0.0 && o->rate <= 1e6)) {
		fprintf(stderr, "convsim: --sample-rate must be in (0, 1e6] Hz\n");
		return 2;
	}
	return 0;
}

static void print_num(FILE *f, double v)
{
	if (isfinite(v))
		fprintf(f, "%.17g", v);
	else
		fputs("null", f);
}

static void write_row(FILE *f, const sim *s, const sim_status *st, int json, int first,
		      double *colbuf)
{
	int K = sim_columns(s);
	double vals[16] = {st->t,           st->q[0],          st->q[1],
			   st->q[2],        st->q[4],          st->q[5],
			   st->rotor_speed, st->motor_torque,  st->beta * DEG_PER_RAD,
			   st->deck[0],     st->deck[1],       st->feed_displacement,
			   st->e_input,     st->e_dissipated,  st->e_residual,
			   st->transport_velocity};
	static const char *const names[16] = {
		"t",     "x",     "y",           "alpha", "s1",          "s2",
		"rotor_speed", "motor_torque", "beta_deg", "deck_x", "deck_y",
		"feed_displacement", "e_input", "e_dissipated", "e_residual",
		"transport_velocity"};
	sim_column_displacement(s, colbuf);
	if (json) {
		fputs(first ? "[\n{" : ",\n{", f);
		for (int i = 0; i < 16; i++) {
			fprintf(f, "%s\"%s\":", i ? "," : "", names[i]);
			print_num(f, vals[i]);
		}
		fputs(",\"columns\":[", f);
		for (int k = 0; k < K; k++) {
			if (k)
				fputc(',', f);
			print_num(f, colbuf[k]);
		}
		fputs("]}", f);
		return;
	}
	if (first) {
		for (int i = 0; i < 16; i++)
			fprintf(f, "%s%s", i ? "," : "", names[i]);
		for (int k = 0; k < K; k++)
			fprintf(f, ",column_%d", k + 1);
		fputc('\n', f);
	}
	for (int i = 0; i < 16; i++) {
		if (i)
			fputc(',', f);
		if (isfinite(vals[i]))
			fprintf(f, "%.10g", vals[i]);
	}
	for (int k = 0; k < K; k++)
		fprintf(f, ",%.10g", colbuf[k]);
	fputc('\n', f);
}

/* The run's JSON summary on stdout: final status, cost (cpu, wall in s)
 * and the error, if any. */
static void print_summary(const opts *o, const sim *s, const sim_status *st, int err, double cpu,
			  double wall)
{
	printf("{\n  \"preset\": \"%s\",\n  \"duration\": %.17g,\n", o->preset, st->t);
	printf("  \"integrator\": {\"method\": \"%s\", \"dt\": %.17g, \"rtol\": %.17g, "
	       "\"atol\": %.17g, \"substeps\": %d},\n",
	       o->m.name, st->dt, o->m.rtol, o->m.atol, st->substeps);
	printf("  \"reductions\": [");
	for (int b = 0, first = 1; sim_reduction_name(b); b++)
		if (st->reductions & (1u << b)) {
			printf("%s\"%s\"", first ? "" : ", ", sim_reduction_name(b));
			first = 0;
		}
	printf("],\n  \"transport_velocity\": ");
	print_num(stdout, st->transport_velocity);
	printf(",\n  \"transport_velocity_uncertainty\": ");
	print_num(stdout, st->transport_velocity_uncertainty);
	printf(",\n  \"steady\": %s", st->steady ? "true" : "false");
	printf(",\n  \"transport_periods\": %.0f,\n  \"rotor_speed\": ", st->transport_periods);
	print_num(stdout, st->rotor_speed_mean);
	printf(",\n  \"motor_torque\": ");
	print_num(stdout, st->motor_torque_mean);
	printf(",\n  \"power\": ");
	print_num(stdout, st->power_mean);
	printf(",\n  \"beta_deg\": %.17g,\n  \"feed_displacement\": ", st->beta * DEG_PER_RAD);
	print_num(stdout, st->feed_displacement);
	printf(",\n  \"steps\": %llu,\n  \"rhs_evals\": %llu,\n  \"n_dof\": %d,\n",
	       (unsigned long long)st->steps, (unsigned long long)st->rhs_evals, st->n_dof);
	printf("  \"cpu_seconds\": %.6g,\n  \"wall_seconds\": %.6g,\n", cpu, wall);
	printf("  \"real_time_factor\": %.6g,\n", cpu > 0 ? st->t / cpu : 0.0);
	printf("  \"energy\": {\"input\": %.10g, \"kinetic\": %.10g, \"potential\": %.10g, "
	       "\"dissipated\": %.10g, \"residual\": %.6g},\n",
	       st->e_input, st->e_kinetic, st->e_potential, st->e_dissipated, st->e_residual);
	printf("  \"error\": ");
	if (err != SIM_OK)
		printf("\"%s\"\n}\n", sim_last_error(s));
	else
		printf("null\n}\n");
}

static int cmd_run(int argc, char **argv)
{
	opts o = {0};
	int rc = parse(argc, argv, &o);
	if (rc)
		return rc;
	if (!(o.duration > 0.0 && o.duration <= 1e5)) {
		fprintf(stderr, "convsim: --duration must be in (0, 1e5] s\n");
		return 2;
	}
	char msg[200];
	int err;
	double w0 = now(), c0 = cpu_now(); /* the steady start's settling included */
	sim *s = sim_new(&o.p, &o.sc, &o.m, &err, msg, sizeof msg);
	if (!s) {
		fprintf(stderr, "convsim: %s\n", msg);
		return 2;
	}
	FILE *f = NULL;
	double *colbuf = calloc(SIM_MAX_COLUMNS, sizeof(double));
	if (o.out) {
		f = fopen(o.out, "w");
		if (!f) {
			perror(o.out);
			sim_free(s);
			free(colbuf);
			return 1;
		}
	}
	int json_traj = o.format && strcmp(o.format, "json") == 0;
	sim_status st;
	long nsamples = (long)ceil(o.duration * o.rate - 1e-9);
	if (f) {
		sim_get_status(s, &st);
		write_row(f, s, &st, json_traj, 1, colbuf);
	}
	err = SIM_OK;
	for (long i = 1; i <= nsamples && err == SIM_OK; i++) {
		double t = i == nsamples ? o.duration : (double)i / o.rate;
		err = sim_advance(s, t);
		if (f && err == SIM_OK) {
			sim_get_status(s, &st);
			write_row(f, s, &st, json_traj, 0, colbuf);
		}
	}
	double wall = now() - w0, cpu = cpu_now() - c0;
	if (f) {
		if (json_traj)
			fputs("\n]\n", f);
		fclose(f);
	}
	sim_get_status(s, &st);
	print_summary(&o, s, &st, err, cpu, wall);
	sim_free(s);
	free(colbuf);
	return err == SIM_OK ? 0 : 1;
}

/* ---- sweep ---- */

/* The default measuring window of a sweep point (s after the transient):
 * with the `steady` start, 4 s keep all 74 points of czubak2016 within
 * 1 % of the converged reference (README "Accuracy"). */
#define SWEEP_WINDOW 4.0

typedef struct task {
	double beta;
	int rotation;
	sim_measurement r;
	int err;
	char msg[160];
} task;

typedef struct pool {
	const opts *o;
	task *tasks;
	int n, next, done;
	pthread_mutex_t lock;
} pool;

static void *worker(void *arg)
{
	pool *pl = arg;
	for (;;) {
		pthread_mutex_lock(&pl->lock);
		int i = pl->next < pl->n ? pl->next++ : -1;
		pthread_mutex_unlock(&pl->lock);
		if (i < 0)
			return NULL;
		task *t = &pl->tasks[i];
		sim_params p = pl->o->p;
		p.beta = t->beta * RAD_PER_DEG;
		p.rotation = t->rotation;
		t->err = sim_measure(&p, &pl->o->sc, &pl->o->m, pl->o->duration, &t->r, t->msg,
				     sizeof t->msg);
		pthread_mutex_lock(&pl->lock);
		pl->done++;
		fprintf(stderr, "\rsweep: %d/%d done", pl->done, pl->n);
		pthread_mutex_unlock(&pl->lock);
	}
}

/* The sweep's table on stdout (CSV or JSON), failures on stderr; returns
 * the number of failed points. */
static int print_sweep(const opts *o, const pool *pl)
{
	int json = o->format && strcmp(o->format, "json") == 0, failed = 0;
	if (json)
		printf("{\"duration\": %.17g, \"transient\": %.17g, \"method\": \"%s\", \"points\": [\n",
		       o->duration, o->sc.transient, o->m.name);
	else
		printf("beta_deg,rotation,transport_velocity_m_s,uncertainty_m_s,steady\n");
	for (int i = 0; i < pl->n; i++) {
		task *t = &pl->tasks[i];
		const char *rot = t->rotation == SIM_CW ? "cw" : "ccw";
		const char *steady = t->r.steady ? "true" : "false";
		if (t->err != SIM_OK) {
			failed++;
			fprintf(stderr, "convsim: beta %g %s: %s\n", t->beta, rot, t->msg);
		}
		if (json) {
			printf("  {\"beta\": %.17g, \"rotation\": \"%s\", \"transport_velocity\": ",
			       t->beta, rot);
			print_num(stdout, t->r.transport_velocity);
			printf(", \"uncertainty\": ");
			print_num(stdout, t->r.uncertainty);
			printf(", \"steady\": %s}%s\n", steady, i + 1 < pl->n ? "," : "");
		} else {
			printf("%g,%s,", t->beta, rot);
			if (isfinite(t->r.transport_velocity))
				printf("%.9g", t->r.transport_velocity);
			printf(",");
			if (isfinite(t->r.uncertainty))
				printf("%.3g", t->r.uncertainty);
			printf(",%s\n", steady);
		}
	}
	if (json)
		printf("]}\n");
	return failed;
}

static int cmd_sweep(int argc, char **argv)
{
	opts o = {0};
	int rc = parse(argc, argv, &o);
	if (rc)
		return rc;
	if (o.duration <= 0.0)
		o.duration = o.sc.transient + SWEEP_WINDOW;
	if (!(o.duration > o.sc.transient)) {
		fprintf(stderr, "convsim: --duration (%g s) must exceed the scene's transient (%g s): "
				"v is measured over [transient, duration]\n",
			o.duration, o.sc.transient);
		return 2;
	}
	double from, to, step;
	if (!o.beta || sscanf(o.beta, "%lf:%lf:%lf", &from, &to, &step) != 3 || !(step > 0) ||
	    from < 0 || to > 180 || to < from) {
		fprintf(stderr, "convsim: --beta FROM:TO:STEP with 0 <= FROM <= TO <= 180, STEP > 0\n");
		return 2;
	}
	int rots[2], nrot = 0;
	if (strstr(o.rotation, "cw") == o.rotation || strstr(o.rotation, ",cw"))
		rots[nrot++] = SIM_CW;
	if (strstr(o.rotation, "ccw"))
		rots[nrot++] = SIM_CCW;
	if (nrot == 0) {
		fprintf(stderr, "convsim: --rotation takes cw, ccw or cw,ccw\n");
		return 2;
	}
	int nb = (int)floor((to - from) / step + 1e-9) + 1;
	if (nb > 10000 || o.threads < 1 || o.threads > 64) {
		fprintf(stderr, "convsim: at most 10000 beta values and 1..64 threads\n");
		return 2;
	}
	pool pl = {.o = &o, .n = nb * nrot};
	pl.tasks = calloc((size_t)pl.n, sizeof(task));
	if (!pl.tasks)
		return 1;
	for (int r = 0; r < nrot; r++)
		for (int i = 0; i < nb; i++) {
			pl.tasks[r * nb + i].beta = from + step * i;
			pl.tasks[r * nb + i].rotation = rots[r];
		}
	pthread_mutex_init(&pl.lock, NULL);
	pthread_t th[64];
	double w0 = now();
	for (int i = 0; i < o.threads; i++)
		pthread_create(&th[i], NULL, worker, &pl);
	for (int i = 0; i < o.threads; i++)
		pthread_join(th[i], NULL);
	fprintf(stderr, "\rsweep: %d/%d done in %.1f s\n", pl.done, pl.n, now() - w0);
	int failed = print_sweep(&o, &pl);
	pthread_mutex_destroy(&pl.lock);
	free(pl.tasks);
	return failed ? 1 : 0;
}

static int cmd_list(void)
{
	size_t n;
	const sim_setting *t = sim_settings(&n);
	printf("%-16s %-11s %-9s %-24s %s\n", "name", "group", "unit", "range", "meaning");
	for (size_t i = 0; i < n; i++) {
		char range[64];
		if (t[i].kind == SIM_KIND_ENUM)
			snprintf(range, sizeof range, "%s", t[i].choices);
		else if (t[i].kind == SIM_KIND_BOOL)
			snprintf(range, sizeof range, "true|false");
		else
			snprintf(range, sizeof range, "[%g, %g]", t[i].min, t[i].max);
		printf("%-16s %-11s %-9s %-24s %s\n", t[i].name, t[i].group, t[i].unit, range,
		       t[i].doc);
	}
	const sim_method_info *const *mi = sim_methods(&n);
	printf("\nintegrators:\n");
	for (size_t i = 0; i < n; i++)
		printf("  %-8s order %d%s: %s\n", mi[i]->name, mi[i]->order,
		       mi[i]->adaptive ? ", adaptive" : "", mi[i]->doc);
	return 0;
}

int main(int argc, char **argv)
{
	if (argc < 2)
		return usage();
	if (strcmp(argv[1], "run") == 0)
		return cmd_run(argc, argv);
	if (strcmp(argv[1], "sweep") == 0)
		return cmd_sweep(argc, argv);
	if (strcmp(argv[1], "list") == 0)
		return cmd_list();
	return usage();
}
