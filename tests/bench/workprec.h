/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * workprec.h - the work-precision benchmark's parts (see workprec.c): one
 * run of the core and its TSV row (workprec_run.c), the scenes with their
 * references and ladders (workprec_scenes.c), and the report that reads
 * the rows back into Markdown tables (workprec_report.c) and an SVG plot
 * (workprec_svg.c).
 */
#ifndef CONVSIM_WORKPREC_H
#define CONVSIM_WORKPREC_H

#include <stdio.h>

#define SAMPLE_DT 2e-3
enum { NSAMP = 400 }; /* 0.8 s = 20 periods of omega_ss = 157.08 rad/s */

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

/* Runs the czubak2016 preset with the scene's settings `sets`
 * (NULL-terminated name/value pairs, user units) and the method of rs;
 * fills o (borrowed). Exits on a setting the core refuses. */
void wp_run(const char *const *sets, const run_spec *rs, run_out *o);

/* RMS distance of two trough trajectories over their common samples (m). */
double wp_traj_rms(const run_out *a, const run_out *b);

/* RMS displacement of a trough trajectory (m). */
double wp_traj_amplitude(const run_out *a);

/* Prints one TSV row of run o on stdout, its errors against the
 * trajectory reference tref (may be NULL) and the velocity vref (NAN:
 * none). Columns: kind scene variant method setting horizon cpu_per_s rtf
 * traj_rms traj_rel v v_rel e_res e_res_rel steps err. */
void wp_row(const char *kind, const char *scene, const char *variant, const run_spec *rs,
	    const run_out *o, const run_out *tref, double vref);

/* Runs the scene NAME ("nofeed", "full", "reduced", "reductions") and
 * prints its rows; quick: shorter horizons and ladders. Returns 0, or -1
 * for an unknown name. */
int wp_scene(const char *name, int quick);

/* One TSV row read back (see wp_row for the columns). */
typedef struct wp_rec {
	char kind[16], scene[16], variant[32], method[12], setting[40], err[200];
	double horizon, cps, rtf, tr, trel, v, vrel, eres, erel;
	unsigned long long steps;
} wp_rec;

/* All rows of the scenes' TSV files. */
typedef struct wp_records {
	int nrec;
	wp_rec recs[512];
	/* richardson rows: [0] scene, [1] method, [2] v finest, [3] order, [4] v limit,
	 * [5] v difference, [6] trajectory difference, [7] trajectory order */
	char rich[4][8][64];
	int nrich;
} wp_records;

/* Reads DIR/{nofeed,full,reduced,reductions}.tsv and writes
 * DIR/workprec.md (headed by CMD, the command that made them) and
 * DIR/workprec.svg. Exits on a file it cannot write. */
void wp_report(const char *dir, const char *cmd);

/* The first row of a scene of the given kind ("ref", "refcheck"), or NULL. */
const wp_rec *wp_find_ref(const wp_records *t, const char *scene, const char *kind);

/* Opens DIR/NAME for writing (the caller closes it); exits with a message
 * when it cannot. */
FILE *wp_create(const char *dir, const char *name);

/* Writes DIR/workprec.svg from the rows t (borrowed). Exits on a file it
 * cannot write. */
void wp_write_svg(const char *dir, const wp_records *t);

#endif
