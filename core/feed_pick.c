/* SPDX-License-Identifier: GPL-3.0-or-later
 *
 * feed_pick.c - feed_model auto (docs/feed-models.md "feed_model=auto"):
 * of the feed models, the cheapest whose model error is within the scene's
 * model_tol, and a sentence saying which and why. Today the choice is
 * between the column model (milliseconds a simulated second, its error
 * from the DEM map: sim_model_check) and a LIGGGHTS bed (the DEM itself,
 * CPU seconds to hours a simulated second, its cost the caller's
 * estimate). A fast third model would go between them here.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "sim.h"

/* What the column model's DEM check says here, "NOTE[, uncertain by ±U
 * m/s]", into buf. */
static void column_check(const sim_model_error *me, char *buf, size_t n)
{
	if (me->checked)
		snprintf(buf, n, "%s, uncertain by ±%.3f m/s", me->note, me->error_uncertainty);
	else
		snprintf(buf, n, "%s", me->note);
}

static int pick_none(sim_feed_choice *out, const sim_model_error *me)
{
	out->model = -1;
	out->field = "model_tol";
	out->min = me && me->checked ? me->error + me->error_uncertainty : NAN;
	return -1;
}

int sim_feed_pick(const sim_params *p, const sim_scene *sc, const sim_feed_liggghts *lg,
		  sim_feed_choice *out)
{
	out->field = NULL;
	out->min = NAN;
	out->expected_cpu_s_per_s = NAN;
	out->why[0] = '\0';
	double tol = sc->model_tol;
	if (!sc->feed) {
		out->model = SIM_FEED_COLUMN;
		snprintf(out->why, sizeof out->why, "column: no feed, nothing to model");
		return 0;
	}
	if (!(tol > 0)) {
		snprintf(out->why, sizeof out->why,
			 "feed_model auto needs model_tol > 0 m/s: the largest model error the "
			 "feed model may have");
		return pick_none(out, NULL);
	}
	sim_scene column = *sc;
	column.feed_model = SIM_FEED_COLUMN;
	sim_model_error me;
	sim_model_check(p, &column, &me);
	if (me.checked && me.error + me.error_uncertainty <= tol) {
		out->model = SIM_FEED_COLUMN;
		snprintf(out->why, sizeof out->why,
			 "column: DEM check within ±%.3f m/s here, uncertain by ±%.3f m/s, within "
			 "model_tol %g m/s",
			 me.error, me.error_uncertainty, tol);
		return 0;
	}
	char check[260];
	column_check(&me, check, sizeof check);
	int fits = lg && lg->available && !(lg->cost > lg->max_cost);
	if (fits) {
		out->model = SIM_FEED_EXTERNAL;
		out->expected_cpu_s_per_s = lg->cost;
		if (isfinite(lg->cost))
			snprintf(out->why, sizeof out->why,
				 "liggghts: the column model is not within model_tol %g m/s here "
				 "(%s); a LIGGGHTS bed is the DEM itself, expected to cost about "
				 "%.3g CPU s a simulated second",
				 tol, check, lg->cost);
		else
			snprintf(out->why, sizeof out->why,
				 "liggghts: the column model is not within model_tol %g m/s here "
				 "(%s); a LIGGGHTS bed is the DEM itself",
				 tol, check);
		return 0;
	}
	if (!lg || !lg->available)
		snprintf(out->why, sizeof out->why,
			 "no feed model within model_tol %g m/s here: the column model: %s; a "
			 "LIGGGHTS bed cannot run: %s",
			 tol, check, lg && lg->unavailable ? lg->unavailable : "not offered");
	else
		snprintf(out->why, sizeof out->why,
			 "no feed model within model_tol %g m/s here: the column model: %s; a "
			 "LIGGGHTS bed would cost about %.3g CPU s a simulated second, over %s %g",
			 tol, check, lg->cost, lg->limit ? lg->limit : "the limit", lg->max_cost);
	return pick_none(out, &me);
}
