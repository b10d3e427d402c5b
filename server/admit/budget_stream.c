/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget_stream.c - what a stream client costs the daemon's cores, and
 * its charge with its session's in the cores for paced sessions
 * (budget.c): a stream of a running paced session is refused 503 (budget
 * "cpu") where the session and its streams would go past
 * --max-paced-cores, as a creation is.
 */
#include "budget.h"

/* What a stream client costs the daemon (docs/budgets.md, "Streams"):
 * tests/bench/stream_cost.mjs, 60 default sessions at pace 1 with an NDJSON
 * stream each, the daemon's CPU with and without them (29 November): a
 * stream thread's wake-up (its worker's wake-up for it, the futex, the
 * loopback send) 53-77 us, whichever its records are; a number formatted
 * (shortest round-trip double, one printf since core/table.h's fast path)
 * 0.81-0.90 us in four runs (1.5 us before it), taken as 1 us; the rest of
 * a record below the measure's noise. A stream is woken once a record, but at most once per
 * paced batch (worker.c PACE_MIN, 20 ms: 50 a wall second at any pace), so
 * a stream of every sample of a default session is woken 50 times a
 * second at pace 1 and 25 times at pace 0.1. The larger wake-up figure is
 * taken: it is the ?rate=10 stream's. */
#define STREAM_WAKE_CPU_S 75e-6
#define STREAM_NUMBER_CPU_S 1.0e-6
#define STREAM_WAKES_MAX 50.0 /* a wall s: worker.c's PACE_MIN, 20 ms */
/* Seconds a 503 of the paced budget asks to wait (as budget.c's). */
#define STREAM_RETRY_S 5

srv_stream_charge srv_budget_stream_charge(double sample_rate, double rate,
					   unsigned fields, int columns, int layers)
{
	double records = rate > 0 && rate < sample_rate ? rate : sample_rate;
	int numbers = api_record_numbers(fields, columns, layers);
	return (srv_stream_charge){records, records * numbers * STREAM_NUMBER_CPU_S, NULL};
}

double srv_budget_streams_cpu(const srv_stream_charge *list, double pace)
{
	double cpu = 0, most = pace > 0 ? STREAM_WAKES_MAX / pace : 0;
	for (; list; list = list->next)
		cpu += (list->records < most ? list->records : most) * STREAM_WAKE_CPU_S +
		       list->numbers_cpu;
	return cpu;
}

api_err srv_budget_take_stream(double *held, double before, double after,
			       double pace, api_problem *pb)
{
	double taken, limit = srv_budget_paced_limit(), stream = after - before;
	if (srv_budget_raise_paced(held, after * pace, &taken))
		return API_OK;
	api_fail(pb, API_UNAVAILABLE, NULL,
		 "this stream needs %.3g core%s (%.3g ms of CPU per simulated s at "
		 "pace %g) and running paced sessions and their streams hold %.3g "
		 "of the %g core%s for paced sessions (--max-paced-cores); nothing "
		 "was opened, retry when some have ended or paused, or ask fewer "
		 "records (rate, fields)",
		 stream * pace, api_plural_g(stream * pace, 3, "", "s"), 1e3 * stream, pace, taken,
		 limit, api_plural_g(limit, 6, "", "s"));
	return api_budget(pb, "cpu", limit, STREAM_RETRY_S);
}
