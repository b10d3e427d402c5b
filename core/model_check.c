/* SPDX-License-Identifier: GPL-3.0-or-later
 *
 * model_check.c - how far the column model is from a DEM bed for a scene:
 * the model error of every v (docs/dem.md "Model error").
 *
 * The DEM map's points with the column model's v at each (computed once by
 * tests/bench/model_check.py and committed as
 * tests/bench/results/model_check.csv) are compiled in: the build turns the
 * CSV into model_map.inc, rows of map_point. Consecutive rows with the same
 * preset, settings, material and layers are one entry: a column model (a
 * calibrated one, or the preset as it is) and the bed it was checked
 * against. A scene is checked when its settings are an entry's (every
 * machine and feed setting but the controls beta and rotation) and its
 * (beta, sense), or their mirror image on a symmetric machine, lies within
 * the angles the entry measured in that sense. Where entries of several
 * materials check it (the preset as it is, against each material's bed),
 * its error is the largest of theirs, and the note names each. No file is
 * read at run time.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "decimal.h"
#include "sim.h"
#include "sim_mirror.h"
#include "units.h"

typedef struct map_point {
	const char *preset;   /* the calibrated column model's preset */
	const char *settings; /* its changes, "name=value;..." in user units */
	const char *material; /* the DEM bed's material */
	const char *model;    /* the column model as a user knows it: "PRESET",
				 "PRESET against MATERIAL", "PRESET at e = E m
				 against MATERIAL" (a drive of the map's),
				 "PRESET calibrated to MATERIAL" */
	int layers;
	double beta_deg;
	int rotation;         /* SIM_CW or SIM_CCW */
	double v_dem, v_dem_sd; /* m/s: the seeds' mean and spread */
	int seeds;
	double v_column;      /* m/s: the column model's v at the point */
} map_point;

static const map_point map[] = {
#include "model_map.inc"
	{NULL, NULL, NULL, NULL, 0, 0, 0, 0, 0, 0, 0} /* the end (the table may be empty) */
};

/* Settings that are controls, not part of a scene's check: the angle and
 * the sense are interpolated over, the ramps only decide how a control is
 * reached (copy_controls sets the same fields). */
static int is_control(const char *name)
{
	static const char *const controls[] = {"beta", "rotation", "beta_rate", "beta_accel",
					       "drive_accel"};
	for (size_t i = 0; i < sizeof controls / sizeof *controls; i++)
		if (strcmp(name, controls[i]) == 0)
			return 1;
	return 0;
}

/* dst's controls (is_control's settings, the same list) set to src's, or to
 * 0 where src is NULL: what first_differences and the memo compare without. */
static void copy_controls(sim_params *dst, const sim_params *src)
{
	static const sim_params zero;
	if (!src)
		src = &zero;
	dst->beta = src->beta;
	dst->rotation = src->rotation;
	dst->beta_rate = src->beta_rate;
	dst->beta_accel = src->beta_accel;
	dst->drive_accel = src->drive_accel;
}

/* The settings of entry point e: its preset with its changes applied.
 * 0 on success. */
static int entry_settings(const map_point *e, sim_params *p, sim_scene *sc)
{
	sim_method m;
	if (sim_preset(e->preset, p, sc, &m) != SIM_OK)
		return -1;
	const char *at = e->settings;
	while (at && *at) {
		char item[80];
		size_t n = strcspn(at, ";");
		if (n >= sizeof item)
			return -1;
		memcpy(item, at, n);
		item[n] = '\0';
		at += n + (at[n] == ';');
		char *eq = strchr(item, '=');
		if (!eq)
			return -1;
		*eq = '\0';
		double v;
		int rc = sim_decimal(eq + 1, &v) ? sim_set_user(p, sc, &m, item, v, NULL, 0)
						  : sim_set_user_str(p, sc, &m, item, eq + 1, NULL, 0);
		if (rc != SIM_OK)
			return -1;
	}
	sc->layers = e->layers;
	return 0;
}

static int same(double a, double b)
{
	return a == b || fabs(a - b) <= 1e-9 * fmax(fabs(a), fabs(b));
}

/* A setting of the feed (its contact) rather than of the machine. */
static int is_feed_setting(const char *name)
{
	static const char *const feed[] = {"m_n", "k_c", "p", "R", "mu", "h_d", "column_span",
					   "friction"};
	for (size_t i = 0; i < sizeof feed / sizeof *feed; i++)
		if (strcmp(name, feed[i]) == 0)
			return 1;
	return 0;
}

/* The first parameter (not a control) of the machine and the first of the
 * feed (is_feed_setting's) in which p differs from q, each NULL where none
 * does; one pass over the settings. */
static void first_differences(const sim_params *p, const sim_scene *s, const sim_params *q,
			      const sim_scene *t, const char **machine, const char **feed)
{
	*machine = *feed = NULL;
	/* the common answer first: the same bytes once the controls are
	 * copied (padding that differs only sends it the long way) */
	sim_params same_controls = *q;
	copy_controls(&same_controls, p);
	if (!memcmp(&same_controls, p, sizeof *p) && s->friction == t->friction)
		return;
	size_t n;
	const sim_setting *tab = sim_settings(&n);
	for (size_t i = 0; i < n && !(*machine && *feed); i++) {
		if (strcmp(tab[i].group, "params") != 0 || is_control(tab[i].name))
			continue;
		const char **first = is_feed_setting(tab[i].name) ? feed : machine;
		if (*first)
			continue;
		double a, b;
		sim_get_setting(p, s, NULL, &tab[i], &a);
		sim_get_setting(q, t, NULL, &tab[i], &b);
		if (!same(a, b))
			*first = tab[i].name;
	}
	if (!*feed && s->friction != t->friction)
		*feed = "friction";
}

/* The angle range [lo, hi] (deg) entry [first, end) measured in a sense. */
static int entry_range(size_t first, size_t end, int rotation, double *lo, double *hi)
{
	*lo = INFINITY;
	*hi = -INFINITY;
	for (size_t i = first; i < end; i++)
		if (map[i].rotation == rotation) {
			*lo = fmin(*lo, map[i].beta_deg);
			*hi = fmax(*hi, map[i].beta_deg);
		}
	return *lo <= *hi;
}

/* Interpolate the entry [first, end) at (beta_deg, rotation): 1 inside
 * its measured angles, with *err and *unc filled. */
static int interpolate(size_t first, size_t end, double beta_deg, int rotation, double *err,
		       double *unc)
{
	const map_point *lo = NULL, *hi = NULL;
	for (size_t i = first; i < end; i++) {
		const map_point *q = &map[i];
		if (q->rotation != rotation)
			continue;
		if (q->beta_deg <= beta_deg + 1e-9 && (!lo || q->beta_deg > lo->beta_deg))
			lo = q;
		if (q->beta_deg >= beta_deg - 1e-9 && (!hi || q->beta_deg < hi->beta_deg))
			hi = q;
	}
	if (!lo || !hi)
		return 0;
	double w = hi->beta_deg > lo->beta_deg
			   ? (beta_deg - lo->beta_deg) / (hi->beta_deg - lo->beta_deg)
			   : 0.0;
	w = fmin(1.0, fmax(0.0, w));
	double d_lo = fabs(lo->v_column - lo->v_dem), d_hi = fabs(hi->v_column - hi->v_dem);
	double sd_lo = isfinite(lo->v_dem_sd) ? lo->v_dem_sd : 0.0;
	double sd_hi = isfinite(hi->v_dem_sd) ? hi->v_dem_sd : 0.0;
	double d = (1 - w) * d_lo + w * d_hi, sd = (1 - w) * sd_lo + w * sd_hi;
	*err = d + sd;
	/* between two points the curve is not measured: half the change of
	 * the error across them, growing from 0 at a point to its full share
	 * midway */
	*unc = sd + 2.0 * fmin(w, 1.0 - w) * 0.5 * fabs(d_hi - d_lo);
	return 1;
}

static const char *sense_name(int rotation)
{
	return rotation == SIM_CW ? "cw" : "ccw";
}

/* How well the scene matches entry [first, end): 0 settings and layers
 * match, 1 layers differ, 2 a machine setting differs, 3 a feed setting
 * differs, 4 both. *diff receives the first differing setting (the
 * machine's first). */
static int entry_match(size_t first, const sim_params *p, const sim_scene *sc,
		       const char **diff)
{
	sim_params q;
	sim_scene t;
	*diff = NULL;
	if (entry_settings(&map[first], &q, &t) != 0)
		return 5;
	const char *machine, *feed;
	first_differences(p, sc, &q, &t, &machine, &feed);
	*diff = machine ? machine : feed;
	if (machine)
		return feed ? 4 : 2;
	if (feed)
		return 3;
	return sc->layers == map[first].layers ? 0 : 1;
}

/* An entry's match depends on the scene's settings, not on its controls:
 * each thread keeps the last scene's matches (a closed loop checks the
 * same scene at a new beta every period, each command's event), by the
 * entry's first row; a scene of other settings starts over. */
#define MAP_ROWS (sizeof map / sizeof *map)
static _Thread_local struct {
	int valid;
	sim_params p; /* the controls zeroed */
	sim_scene sc;
	unsigned char known[MAP_ROWS];
	int rank[MAP_ROWS];
	const char *diff[MAP_ROWS];
} memo;

/* The memo for the scene p, sc (its matches kept if they are its). */
static void memo_for(const sim_params *p, const sim_scene *sc)
{
	sim_params k = *p;
	copy_controls(&k, NULL);
	if (memo.valid && !memcmp(&k, &memo.p, sizeof k) && !memcmp(sc, &memo.sc, sizeof *sc))
		return;
	memo.valid = 1;
	memo.p = k;
	memo.sc = *sc;
	memset(memo.known, 0, sizeof memo.known);
}

/* entry_match of the entry at row first, through the memo. */
static int memo_match(size_t first, const sim_params *p, const sim_scene *sc, const char **diff)
{
	if (!memo.known[first]) {
		memo.rank[first] = entry_match(first, p, sc, &memo.diff[first]);
		memo.known[first] = 1;
	}
	*diff = memo.diff[first];
	return memo.rank[first];
}

/* The end of the entry that begins at row first. */
static size_t entry_end(size_t first)
{
	size_t end = first + 1;
	while (map[end].preset && map[end].layers == map[first].layers &&
	       strcmp(map[end].preset, map[first].preset) == 0 &&
	       strcmp(map[end].settings, map[first].settings) == 0 &&
	       strcmp(map[end].material, map[first].material) == 0)
		end++;
	return end;
}

/* The map's entry nearest the scene, when none checks it. */
typedef struct {
	size_t first, end; /* first == SIZE_MAX: no entry */
	int rank;          /* entry_match's */
	const char *diff;  /* the first differing setting */
} nearest_entry;

/* The entries that check a scene: one, or one a material for the preset
 * as it is (the map has a few materials). */
#define HITS_MAX 8
typedef struct {
	size_t first;
	double err, unc;
} hit;

/* *out for the entries hits[0..n) that check the scene: the largest error
 * of theirs, and a note that names it first, then each other's: "DEM
 * check: within ±E m/s here (NAME, L layers; against MATERIAL ±E)". */
static void checked_by(const hit *hits, int n, sim_model_error *out)
{
	int top = 0;
	for (int i = 1; i < n; i++)
		if (hits[i].err > hits[top].err)
			top = i;
	const map_point *e = &map[hits[top].first];
	out->checked = 1;
	/* to 0.01 um/s, the map's finest figure (its calibrated v): the sums and
	 * the weights between two points would print as 0.0307068000000003 */
	out->error = round(hits[top].err * 1e8) / 1e8;
	out->error_uncertainty = round(hits[top].unc * 1e8) / 1e8;
	int at = snprintf(out->note, sizeof out->note, "DEM check: within ±%.3f m/s here (%s, %d layers",
			  out->error, e->model, e->layers);
	for (int i = 0; i < n; i++)
		if (i != top && at >= 0 && (size_t)at < sizeof out->note)
			at += snprintf(out->note + at, sizeof out->note - at, "; against %s ±%.3f",
				       map[hits[i].first].material, hits[i].err);
	if (at >= 0 && (size_t)at < sizeof out->note)
		snprintf(out->note + at, sizeof out->note - at, ")");
}

/* Walk the map's entries: 1 with *out filled where entries matching the
 * scene cover its angle (beta in degrees, or its mirror); else 0 and *best
 * the nearest entry: fewest differences, then the nearest depth. */
static int scan_entries(const sim_params *p, const sim_scene *sc, double beta, int can_mirror,
			sim_model_error *out, nearest_entry *best)
{
	memo_for(p, sc);
	hit hits[HITS_MAX];
	int nhits = 0;
	size_t best_first = SIZE_MAX, best_end = 0;
	int best_rank = 6;
	const char *best_diff = NULL;
	for (size_t first = 0, end; map[first].preset; first = end) {
		end = entry_end(first);
		const char *diff;
		int rank = memo_match(first, p, sc, &diff);
		if (rank == 0) {
			double err, unc;
			int inside = interpolate(first, end, beta, p->rotation, &err, &unc) ||
				     (can_mirror &&
				      interpolate(first, end, 180.0 - beta, -p->rotation, &err, &unc));
			if (inside && nhits < HITS_MAX)
				hits[nhits++] = (hit){first, err, unc};
		}
		if (rank < best_rank ||
		    (rank == best_rank && rank >= 1 && rank <= 4 &&
		     abs(map[first].layers - sc->layers) < abs(map[best_first].layers - sc->layers))) {
			best_first = first;
			best_end = end;
			best_rank = rank;
			best_diff = diff;
		}
	}
	if (nhits) {
		checked_by(hits, nhits, out);
		return 1;
	}
	best->first = best_first;
	best->end = best_end;
	best->rank = best_rank;
	best->diff = best_diff;
	return 0;
}

/* The preset the scene is as it stands, when its nearest entry differs in
 * a setting (rank >= 2); NULL if none. */
static const char *scene_preset(const sim_params *p, const sim_scene *sc, int rank)
{
	const char *named = NULL;
	for (size_t i = 0; rank >= 2 && sim_preset_names[i] && !named; i++) {
		sim_params q;
		sim_scene t;
		sim_method m;
		const char *machine, *feed;
		if (sim_preset(sim_preset_names[i], &q, &t, &m) != SIM_OK)
			continue;
		first_differences(p, sc, &q, &t, &machine, &feed);
		if (!machine && !feed)
			named = sim_preset_names[i];
	}
	return named;
}

/* The note of a scene not checked, naming its nearest entry b. */
static void note_unchecked(const sim_params *p, const sim_scene *sc, double beta,
			   const nearest_entry *b, sim_model_error *out)
{
	size_t best = b->first, best_end = b->end;
	int best_rank = b->rank;
	const char *best_diff = b->diff;
	const map_point *e = &map[best];
	char where[120];
	snprintf(where, sizeof where, "%d layers, %s", e->layers, e->model);
	/* a scene that is another preset as it stands: say so plainly */
	const char *named = scene_preset(p, sc, best_rank);
	if (named) {
		snprintf(out->note, sizeof out->note,
			 "%s's column model is not checked against DEM (checked: %s)", named,
			 where);
	} else if (best_rank == 0) {
		double lo, hi;
		if (entry_range(best, best_end, p->rotation, &lo, &hi))
			snprintf(out->note, sizeof out->note,
				 "not checked against DEM at beta %.0f deg %s: checked %.0f-%.0f deg "
				 "%s (%s)",
				 beta, sense_name(p->rotation), lo, hi, sense_name(p->rotation),
				 where);
		else
			snprintf(out->note, sizeof out->note,
				 "not checked against DEM turning %s (%s)", sense_name(p->rotation),
				 where);
	} else if (best_rank == 1) {
		snprintf(out->note, sizeof out->note,
			 "not checked against DEM for %d-layer beds: nearest checked bed is %s",
			 sc->layers, where);
	} else if (best_rank == 2 || best_rank == 4) {
		double v = NAN;
		sim_get_user(p, sc, NULL, best_diff, &v);
		const sim_setting *t = sim_setting_find(best_diff);
		snprintf(out->note, sizeof out->note,
			 "not checked against DEM at %s = %g%s%s: the DEM map's machine is %s's (%s)",
			 best_diff, v, t && *t->unit ? " " : "", t ? t->unit : "", e->preset, where);
	} else {
		snprintf(out->note, sizeof out->note,
			 "not checked against DEM with this contact (%s differs): nearest "
			 "checked is %s",
			 best_diff, where);
	}
}

int sim_model_check(const sim_params *p, const sim_scene *sc, sim_model_error *out)
{
	out->checked = 0;
	out->error = NAN;
	out->error_uncertainty = NAN;
	out->note[0] = '\0';
	if (!sc->feed) {
		snprintf(out->note, sizeof out->note, "no feed: nothing to check against DEM");
		return -1;
	}
	if (sc->feed_model != SIM_FEED_COLUMN) {
		snprintf(out->note, sizeof out->note,
			 "the feed is a LIGGGHTS bed: the DEM itself, no column model to check");
		return -1;
	}
	double beta = p->beta / RAD_PER_DEG;
	sim_scene mirrored = *sc;
	mirrored.mirror = 1;
	int can_mirror = sim_mirror_applies(p, &mirrored);
	nearest_entry best;
	if (scan_entries(p, sc, beta, can_mirror, out, &best))
		return 1;
	if (best.first == SIZE_MAX) {
		snprintf(out->note, sizeof out->note, "not checked against DEM: no DEM map entry");
		return 0;
	}
	note_unchecked(p, sc, beta, &best, out);
	return 0;
}
