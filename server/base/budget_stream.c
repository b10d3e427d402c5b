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
 * (shortest round-trip double) 1.5 us; the rest of a record below the
 * measure's noise. A stream of every sample is woken once per paced batch
 * (worker.c PACE_MIN, 20 ms: 50 a second at pace 1), a thinned one once a
 * record. The larger wake-up figure is taken: it is the ?rate=10 stream's. */
#define STREAM_WAKE_CPU_S 75e-6
#define STREAM_NUMBER_CPU_S 1.5e-6
#define STREAM_WAKES_MAX 50.0
/* Seconds a 503 of the paced budget asks to wait (as budget.c's). */
#define STREAM_RETRY_S 5

double srv_budget_stream_cpu(double sample_rate, double rate, unsigned fields,
			     int columns, int layers)
{
	double records = rate > 0 && rate < sample_rate ? rate : sample_rate;
	double wakes = records < STREAM_WAKES_MAX ? records : STREAM_WAKES_MAX;
	int numbers = api_record_numbers(fields, columns, layers);
	return wakes * STREAM_WAKE_CPU_S + records * numbers * STREAM_NUMBER_CPU_S;
}

api_err srv_budget_take_stream(double *held, double session_cpu, double stream_cpu,
			       double pace, api_problem *pb)
{
	double taken, limit = srv_budget_paced_limit();
	if (srv_budget_raise_paced(held, (session_cpu + stream_cpu) * pace, &taken))
		return API_OK;
	api_fail(pb, API_UNAVAILABLE, NULL,
		 "this stream needs %.3g cores (%.3g ms of CPU per simulated s at "
		 "pace %g) and running paced sessions and their streams hold %.3g "
		 "of the %g cores for paced sessions (--max-paced-cores); nothing "
		 "was opened, retry when some have ended or paused, or ask fewer "
		 "records (rate, fields)",
		 stream_cpu * pace, 1e3 * stream_cpu, pace, taken, limit);
	return api_budget(pb, "cpu", limit, STREAM_RETRY_S);
}
