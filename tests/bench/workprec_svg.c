/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * workprec_svg.c - the benchmark's plot, workprec.svg: log-log panels of
 * each scene's error (trajectory, transport velocity, energy residual)
 * against CPU seconds per simulated second, a line and a marker shape a
 * method; errors below the reference's uncertainty are drawn at it, over a
 * shaded band.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "workprec.h"

/* the core's methods, then the peers (tests/bench/peer.c) */
static const char *method_names[] = {"rk4",	    "euler",	 "dem",	      "dopri5",
				     "gsl-rk8pd",   "gsl-rkf45", "gsl-msadams", "gsl-msbdf",
				     "cvode-adams", "cvode-bdf", "arkode-erk"};
static const char *method_colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#9467bd",
				      "#ff7f0e", "#8c564b", "#e377c2", "#7f7f7f",
				      "#bcbd22", "#17becf", "#000000"};
enum { NMETHODS = sizeof method_names / sizeof method_names[0] };

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
	case 3:
		fprintf(f, "<path d='M%.1f %.1f l5 5 l-5 5 l-5 -5 z' fill='%s'/>\n", x, y - 5, c);
		break;
	default: /* the peers: hollow circles and crosses */
		if (m % 2)
			fprintf(f, "<path d='M%.1f %.1f l8 8 m0 -8 l-8 8' stroke='%s' "
				   "stroke-width='2'/>\n",
				x - 4, y - 4, c);
		else
			fprintf(f, "<circle cx='%.1f' cy='%.1f' r='4' fill='none' stroke='%s' "
				   "stroke-width='2'/>\n",
				x, y, c);
	}
}

enum { E_TRAJ, E_V, E_ENERGY };

static double err_of(const wp_rec *r, int kind)
{
	return kind == E_TRAJ ? r->trel : kind == E_V ? r->vrel : r->erel;
}

/* A panel's plot area in SVG units and the log10 decades it spans. */
typedef struct frame {
	double lx0, lx1, ly0, ly1; /* decades of the error (x) and of CPU s/sim s (y) */
	double px0, px1, py0, py1; /* plot area: left, right, bottom, top */
} frame;

static double frame_x(const frame *fr, double e)
{
	return fr->px0 + (log10(e) - fr->lx0) / (fr->lx1 - fr->lx0) * (fr->px1 - fr->px0);
}

static double frame_y(const frame *fr, double c)
{
	return fr->py0 + (log10(c) - fr->ly0) / (fr->ly1 - fr->ly0) * (fr->py1 - fr->py0);
}

/* The decades that hold a scene's runs (errors below floor_err counted at
 * it; line_at, if > 0, included) and the plot area of a panel at (ox, oy),
 * size w x h. Returns 0 when the scene has no run to draw. */
static int panel_frame(const wp_records *t, const char *scene, int kind, double floor_err,
		       double line_at, double ox, double oy, double w, double h, frame *fr)
{
	double xmin = INFINITY, xmax = -INFINITY, ymin = INFINITY, ymax = -INFINITY;
	for (int i = 0; i < t->nrec; i++) {
		const wp_rec *r = &t->recs[i];
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
		return 0;
	if (line_at > 0) {
		xmin = fmin(xmin, line_at);
		xmax = fmax(xmax, line_at);
	}
	fr->lx0 = floor(log10(xmin));
	fr->lx1 = ceil(log10(xmax));
	fr->ly0 = floor(log10(ymin));
	fr->ly1 = ceil(log10(ymax));
	if (fr->lx1 <= fr->lx0)
		fr->lx1 = fr->lx0 + 1;
	if (fr->ly1 <= fr->ly0)
		fr->ly1 = fr->ly0 + 1;
	fr->px0 = ox + 60;
	fr->px1 = ox + w - 10;
	fr->py0 = oy + h - 40;
	fr->py1 = oy + 25;
	return 1;
}

/* Title, box, decade grid and axis labels; the dashed line at line_at
 * (if > 0) and the shading below floor_err (if > 0). */
static void panel_axes(FILE *f, const frame *fr, double ox, double oy, int kind,
		       const char *title, double floor_err, double line_at)
{
	double px0 = fr->px0, px1 = fr->px1, py0 = fr->py0, py1 = fr->py1;
	double lx0 = fr->lx0, lx1 = fr->lx1, ly0 = fr->ly0, ly1 = fr->ly1;
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
		double x = frame_x(fr, line_at);
		fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#f80' "
			   "stroke-dasharray='5,3'/>\n",
			x, py0, x, py1);
	}
	if (floor_err > 0 && floor_err > pow(10, lx0)) {
		double x = frame_x(fr, floor_err);
		fprintf(f, "<rect x='%.1f' y='%.1f' width='%.1f' height='%.1f' fill='#000' "
			   "fill-opacity='0.06'/>\n",
			px0, py1, x - px0, py0 - py1);
	}
}

/* Each method's runs of a scene: a line through its ladder (dem: the
 * substeps=1 ladder only) and a marker a run. */
static void panel_series(FILE *f, const wp_records *t, const frame *fr, const char *scene,
			 int kind, double floor_err)
{
	for (int m = 0; m < NMETHODS; m++) {
		int first = 1;
		fprintf(f, "<polyline fill='none' stroke='%s' stroke-width='1' points='",
			method_colors[m]);
		for (int i = 0; i < t->nrec; i++) {
			const wp_rec *r = &t->recs[i];
			if (strcmp(r->kind, "run") || strcmp(r->scene, scene) ||
			    strcmp(r->method, method_names[m]))
				continue;
			/* dem: the substeps=1 ladder only in the line (the gate:
			 * every setting) */
			if (m == 2 && strcmp(scene, "gate") && !strstr(r->setting, "substeps=1"))
				continue;
			double e = err_of(r, kind);
			if (!isfinite(e) || !(r->cps > 0))
				continue;
			fprintf(f, "%s%.1f,%.1f", first ? "" : " ", frame_x(fr, fmax(e, floor_err)),
				frame_y(fr, r->cps));
			first = 0;
		}
		fprintf(f, "'/>\n");
		for (int i = 0; i < t->nrec; i++) {
			const wp_rec *r = &t->recs[i];
			if (strcmp(r->kind, "run") || strcmp(r->scene, scene) ||
			    strcmp(r->method, method_names[m]))
				continue;
			double e = err_of(r, kind);
			if (!isfinite(e) || !(r->cps > 0))
				continue;
			marker(f, m, frame_x(fr, fmax(e, floor_err)), frame_y(fr, r->cps));
		}
	}
}

/* One log-log panel at (ox, oy), size w x h. floor_err: errors below it
 * are drawn at it, hollow (not resolved by the reference). */
static void panel(FILE *f, const wp_records *t, double ox, double oy, double w, double h,
		  const char *scene, int kind, const char *title, double floor_err, double line_at)
{
	frame fr;
	if (!panel_frame(t, scene, kind, floor_err, line_at, ox, oy, w, h, &fr))
		return;
	panel_axes(f, &fr, ox, oy, kind, title, floor_err, line_at);
	panel_series(f, t, &fr, scene, kind, floor_err);
}

void wp_write_svg(const char *dir, const wp_records *t)
{
	FILE *f = wp_create(dir, "workprec.svg");
	const double W = 420, H = 320;
	fprintf(f,
		"<svg xmlns='http://www.w3.org/2000/svg' width='%g' height='%g' "
		"font-family='sans-serif'>\n<rect width='100%%' height='100%%' fill='white'/>\n",
		3 * W, 3 * H + 60);
	/* reference uncertainty floors */
	double vfloor[2] = {0, 0}, tfloor[3] = {0, 0, 0};
	const char *sc[3] = {"nofeed", "full", "reduced"};
	const wp_rec *chk = wp_find_ref(t, "nofeed", "refcheck");
	if (chk)
		tfloor[0] = chk->trel;
	for (int k = 0; k < t->nrich; k++) {
		int s = strcmp(t->rich[k][0], "full") == 0 ? 1 : 2;
		vfloor[s - 1] = strtod(t->rich[k][5], NULL);
		tfloor[s] = strtod(t->rich[k][6], NULL);
	}
	panel(f, t, 0, 0, W, H, sc[0], E_TRAJ, "(1) machine, no feed: trajectory", tfloor[0], 0);
	panel(f, t, W, 0, W, H, sc[1], E_TRAJ, "(2) full scene: trajectory", tfloor[1], 0);
	panel(f, t, 2 * W, 0, W, H, sc[2], E_TRAJ, "(3) reduced scene: trajectory", tfloor[2], 0);
	panel(f, t, 0, H, W, H, sc[1], E_ENERGY, "(2) full scene: energy residual", 0, 0);
	panel(f, t, W, H, W, H, sc[1], E_V, "(2) full scene: transport velocity", vfloor[0], 0.01);
	panel(f, t, 2 * W, H, W, H, sc[2], E_V, "(3) reduced scene: transport velocity", vfloor[1],
	      0.01);
	panel(f, t, 0, 2 * H, 2 * W, H, "gate", E_V,
	      "(4) the 1 % gate, czubak2016 defaults: worst v error over the gate's points "
	      "(docs/accuracy.md); core dem and the GSL / SUNDIALS peers",
	      0, 0.01);
	double ly = 3 * H + 20;
	for (int m = 0; m < NMETHODS; m++) {
		double lx = 60 + 105 * m;
		marker(f, m, lx, ly);
		fprintf(f, "<text x='%.0f' y='%.1f' font-size='12'>%s</text>\n", lx + 10, ly + 4,
			method_names[m]);
	}
	fprintf(f,
		"<text x='80' y='%.1f' font-size='11'>shaded: below the reference's "
		"uncertainty (drawn at it); dashed: 1 %% in v; line: dem substeps=1 (in (4): every "
		"dem setting; the peers: their tolerance ladders)</text>\n",
		ly + 24);
	fprintf(f, "</svg>\n");
	fclose(f);
}
