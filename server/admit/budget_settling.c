/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget_settling.c - how many requests settle simulations in their own
 * thread at once (budget.h, --max-settling). A session's creation builds
 * its instance, settles its steady start and runs its probe before it is
 * answered (seconds of CPU for a large feed: a 64 x 64 scene about one),
 * an identification or a closed loop measures its scene at the request
 * (the v(beta) curve: 73 runs); libmicrohttpd gives each connection a
 * thread, at a priority above the session workers'. Nothing bounded how
 * many did so at once: ten creations of a 64 x 64 scene sent together
 * all settled at once, each ten times slower, and a paced session
 * beside them fell to a few per cent of real time
 * (tests/bench/results/settle_flood.md). Beyond the limit a request
 * waits for a slot at most SETTLING_WAIT_MS, as long as default creations
 * take when a few arrive together (each a few ms), then is refused (503):
 * held longer, it would keep its connection and thread for as long as
 * the others settle, and its answer's time would tell nothing.
 */
#include <errno.h>
#include <pthread.h>
#include <time.h>

#include "budget.h"

/* Seconds a refusal asks to wait: a default creation settles in a few ms,
 * a large scene in seconds. */
#define SETTLING_RETRY_S 1
/* How long a request waits for a slot before its 503: a burst of default
 * creations (a few ms each) queues through, a large scene's settling
 * (about a second for 64 x 64) is not waited out. */
#define SETTLING_WAIT_MS 250

static pthread_mutex_t lock = PTHREAD_MUTEX_INITIALIZER;
static pthread_cond_t freed;            /* a slot was given back */
static int limit = 1;                   /* --max-settling */
static int settling, most;              /* lock: now, the most at once */
static unsigned long long refused;      /* lock */

void srv_budget_settling_init(const srv_config *cfg)
{
	limit = cfg->max_settling > 0 ? cfg->max_settling : 1;
	pthread_condattr_t ca;
	pthread_condattr_init(&ca);
	pthread_condattr_setclock(&ca, CLOCK_MONOTONIC);
	pthread_cond_init(&freed, &ca);
	pthread_condattr_destroy(&ca);
}

api_err srv_budget_take_settling(int *held, api_problem *pb)
{
	if (*held)
		return API_OK;
	struct timespec until;
	clock_gettime(CLOCK_MONOTONIC, &until);
	until.tv_nsec += SETTLING_WAIT_MS * 1000000L;
	until.tv_sec += until.tv_nsec / 1000000000L;
	until.tv_nsec %= 1000000000L;
	pthread_mutex_lock(&lock);
	int waited = 0;
	while (settling >= limit && waited != ETIMEDOUT)
		waited = pthread_cond_timedwait(&freed, &lock, &until);
	int fits = settling < limit;
	if (fits) {
		settling++;
		if (settling > most)
			most = settling;
	} else {
		refused++;
	}
	pthread_mutex_unlock(&lock);
	if (fits) {
		*held = 1;
		return API_OK;
	}
	api_fail(pb, API_UNAVAILABLE, NULL,
		 "as many requests as may settle simulations at once are settling (%d, "
		 "--max-settling), and none ended within %d ms: a session's creation (its steady "
		 "start and its probe) and an experiment's measurements each take a core while "
		 "they settle; nothing was created, retry in a second", limit, SETTLING_WAIT_MS);
	return api_budget(pb, "settling", limit, SETTLING_RETRY_S);
}

void srv_budget_give_settling(int *held)
{
	if (!*held)
		return;
	pthread_mutex_lock(&lock);
	settling--;
	pthread_cond_signal(&freed);
	pthread_mutex_unlock(&lock);
	*held = 0;
}

void srv_budget_settling_counts(int *now, int *most_at_once, unsigned long long *refusals)
{
	pthread_mutex_lock(&lock);
	*now = settling;
	*most_at_once = most;
	*refusals = refused;
	pthread_mutex_unlock(&lock);
}
