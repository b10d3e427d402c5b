/* SPDX-License-Identifier: GPL-3.0-or-later
 *
 * feed_auto.c - `convsim run --set feed_model=auto`: the feed model is
 * picked before the run starts (sim_feed_pick, docs/feed-models.md
 * "feed_model=auto") and the pick said on stderr, with a LIGGGHTS bed's
 * expected CPU cost, and in the summary as feed_model_pick. The plain
 * convsim knows whether convsim-mpi can couple a bed but not its cost
 * (dem/ is not linked): where it picks LIGGGHTS it hands the run over
 * untold, and convsim-mpi, which knows the cost, picks again and says it.
 */
#include <math.h>
#include <stdio.h>

#include "cli.h"

int cli_feed_auto(cli_opts *o)
{
	sim_feed_liggghts lg;
	cli_liggghts_here(o, &lg);
	if (sim_feed_pick(&o->p, &o->sc, &lg, &o->pick) != 0) {
		fprintf(stderr, "convsim run: --set feed_model=auto: %s\n", o->pick.why);
		return 2;
	}
	o->sc.feed_model = o->pick.model;
	o->picked = 1;
	double cost = o->pick.expected_cpu_s_per_s;
	if (o->pick.model == SIM_FEED_EXTERNAL && !isfinite(cost))
		return 0; /* handed over: convsim-mpi says it */
	if (o->pick.model == SIM_FEED_EXTERNAL)
		fprintf(stderr,
			"convsim run: feed_model auto: %s; for the %g s asked about %.3g CPU s (and "
			"the bed's settling)\n",
			o->pick.why, o->duration, cost * o->duration);
	else
		fprintf(stderr, "convsim run: feed_model auto: %s\n", o->pick.why);
	return 0;
}

void cli_put_feed_pick(FILE *f, const cli_opts *o)
{
	if (!o->picked)
		return;
	fprintf(f, ",\n  \"feed_model_pick\": {\"model\": \"%s\", \"why\": \"%s\"",
		o->pick.model == SIM_FEED_EXTERNAL ? "liggghts" : "column", o->pick.why);
	cli_put_json_num(f, ", \"expected_cpu_s_per_s\": ", o->pick.expected_cpu_s_per_s);
	fputc('}', f);
}
