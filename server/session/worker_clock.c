/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker_clock.c - the worker's clocks (pacing and metering anchors) and
 * the wake-up of a session's readers, shared by the loop (worker.c) and
 * the budget's phases (worker_budget.c). Session lock held.
 */
#include <math.h>
#include <pthread.h>

#include "util.h"
#include "worker_int.h"

/* Restart pacing and metering from now (after a pause or a pace change). */
void srv_worker_restart_clocks(clocks *c, const srv_session *s)
{
	c->anchor_wall = c->rate_wall = srv_now();
	c->anchor_t = c->rate_t = s->st.t;
	c->rate_steps = s->st.steps;
	c->batch_start = c->batch_end = -INFINITY;
}

/* Wake the readers if a record one of them waits for was pushed since
 * the last time: an event, or a sample at or past the earliest time a
 * waiting stream wants (wake_t, which the streams lower before they wait).
 * Once per batch, not once per sample: every waiting stream is a thread
 * to wake (lock held). */
int srv_worker_publish_wakes(srv_session *s, clocks *c)
{
	int wake = 0;
	c->publish_wall = srv_now();
	if (s->ring.head == s->ring.published)
		return 0;
	if (s->ring.event_head > s->ring.published || s->st.t >= s->ring.wake_t) {
		c->want_all = s->ring.wake_t == -INFINITY;
		s->ring.wake_t = INFINITY;
		wake = 1;
	} else {
		c->want_all = 0; /* no stream waited for these */
	}
	s->ring.published = s->ring.head;
	return wake;
}

void srv_worker_publish(srv_session *s, clocks *c)
{
	if (srv_worker_publish_wakes(s, c))
		pthread_cond_broadcast(&s->data);
}

/* The same at the end of a paced batch, with the lock let go while the
 * readers are woken: a reader woken while the worker holds the lock
 * would wake only to sleep on the lock, then be woken again by its
 * release (two context switches instead of one, a tenth of the CPU of a
 * daemon of paced sessions). Whatever happened meanwhile (a command, a
 * stream that waits) is seen by the caller after it. */
void srv_worker_publish_batch(srv_session *s, clocks *c)
{
	if (!srv_worker_publish_wakes(s, c))
		return;
	pthread_mutex_unlock(&s->lock);
	pthread_cond_broadcast(&s->data);
	pthread_mutex_lock(&s->lock);
}

