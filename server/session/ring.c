/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * ring.c - what a session's worker writes for its readers: records into the
 * bounded ring (samples and events, indexed by a sequence number that never
 * repeats; the oldest is overwritten) and rows into the trajectory history
 * (every stride, exactly on its grid; the stride doubles when it fills).
 * Below them the readers (streams, the trajectory route): one consistent
 * copy under the session lock, which never leaves this file, session.c and
 * worker.c. Above them the ring's memory: slots (a status each), their
 * feed arrays and, apart, the events' text.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/mman.h>

#include "session_int.h"
#include "util.h"

/* ---- the ring's memory --------------------------------------------------- */

int srv_ring_alloc(srv_session *s, int ring, int history)
{
	size_t per = (size_t)s->columns +
		     2 * (size_t)s->columns * (size_t)s->layers;
	s->ring.cap = ring > 16 ? (size_t)ring : 16;
	/* the record ring, slots then their arrays, in one mapping whose
	 * pages are all made now: the memory budget reserved them anyway,
	 * and a worker that fills a fresh ring would otherwise take a page
	 * fault every few samples over its first 16 s. Huge pages where the
	 * kernel has them: a sample's record lands on a fresh 4-KiB page every
	 * few samples, and with hundreds of sessions each such write missed
	 * the TLB (a fifth of the daemon's CPU in a profile:
	 * docs/performance.md). Making them is most of a session's creation
	 * (the kernel zeroes them), so a slot holds the status alone; the
	 * events' text, 528 bytes a slot and written a few times a session,
	 * is in a mapping of its own whose pages are made as events land */
	size_t bytes = s->ring.cap * (sizeof *s->ring.slots + per * sizeof(double));
	void *map = mmap(NULL, bytes, PROT_READ | PROT_WRITE,
			 MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	if (map != MAP_FAILED) {
#ifdef MADV_HUGEPAGE
		(void)madvise(map, bytes, MADV_HUGEPAGE);
#endif
#ifdef MADV_POPULATE_WRITE
		if (madvise(map, bytes, MADV_POPULATE_WRITE) != 0)
#endif
			memset(map, 0, bytes);
		s->ring.bytes = bytes;
		s->ring.slots = map;
		s->ring.store = (double *)(void *)(s->ring.slots + s->ring.cap);
	}
	size_t ev_bytes = s->ring.cap * sizeof *s->ring.events;
	map = mmap(NULL, ev_bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
	if (map != MAP_FAILED) {
		s->ring.ev_bytes = ev_bytes;
		s->ring.events = map;
	}
	s->ring.wake_t = INFINITY;
	s->ring.plan_t = INFINITY;
	s->ring.hist_cap = history > 16 ? (size_t)history : 16;
	s->ring.hist = calloc(s->ring.hist_cap * API_HISTORY_WIDTH(s->columns), sizeof(double));
	if (!s->ring.bytes || !s->ring.ev_bytes || !s->ring.hist ||
	    srv_sample_alloc(&s->scratch, s->columns, s->layers))
		return -1;
	/* trajectory rows every whole number of sample intervals, at least
	 * 0.01 s apart */
	double every = ceil(0.01 * s->spec.sample_rate - 1e-9);
	s->ring.hist_stride = (every < 1 ? 1 : every) / s->spec.sample_rate;
	return 0;
}

void srv_ring_free(srv_session *s)
{
	if (s->ring.bytes)
		munmap(s->ring.slots, s->ring.bytes);
	if (s->ring.ev_bytes)
		munmap(s->ring.events, s->ring.ev_bytes);
	free(s->ring.hist);
}

/* ---- the worker's writers -------------------------------------------------- */

static srv_slot *push_slot(srv_session *s)
{
	srv_slot *slot = &s->ring.slots[s->ring.head % s->ring.cap];
	slot->index = s->ring.head++;
	return slot;
}

void srv_ring_event(srv_session *s, const char *type, const char *json)
{
	srv_slot_event *ev = &s->ring.events[s->ring.head % s->ring.cap];
	srv_slot *slot = push_slot(s);
	slot->kind = API_REC_EVENT;
	slot->st = s->st;
	snprintf(ev->type, sizeof ev->type, "%s", type);
	snprintf(ev->json, sizeof ev->json, "%s", json);
	s->ring.event_head = s->ring.head;
}

void srv_ring_event_at(srv_session *s, const char *type, const char *detail)
{
	char json[API_EVENT_MAX], t[40];
	api_fmt_time(t, sizeof t, s->st.t);
	snprintf(json, sizeof json, "{\"t\":%s%s%s}", t, detail ? "," : "",
		 detail ? detail : "");
	srv_ring_event(s, type, json);
}

/* 1 if t lies on the grid of multiples of step (to rounding). */
static int on_grid(double t, double step)
{
	double m = t / step;
	return fabs(m - floor(m + 0.5)) < 1e-6;
}

/* A trajectory row at every multiple of the stride, exactly: rows are
 * taken at sample times on that grid (the stride is a whole number of
 * sample intervals), so the rows lie `stride` apart as reported. */
static void record_history(srv_session *s)
{
	if (!s->ring.hist_cap || s->st.t < s->ring.hist_next - 1e-9 * s->ring.hist_stride ||
	    !on_grid(s->st.t, s->ring.hist_stride))
		return;
	size_t width = API_HISTORY_WIDTH(s->columns);
	if (s->ring.hist_n == s->ring.hist_cap) {
		/* full: keep the rows on the doubled grid, double the stride */
		size_t k = 0;
		for (size_t i = 0; i < s->ring.hist_n; i++)
			if (on_grid(s->ring.hist[i * width], 2 * s->ring.hist_stride))
				memmove(s->ring.hist + k++ * width, s->ring.hist + i * width,
					width * sizeof(double));
		s->ring.hist_n = k;
		s->ring.hist_stride *= 2;
		if (!on_grid(s->st.t, s->ring.hist_stride)) {
			s->ring.hist_next = (floor(s->st.t / s->ring.hist_stride + 1e-6) + 1) * s->ring.hist_stride;
			return;
		}
	}
	api_history_row(&s->st, s->scratch.column_disp, s->columns,
			s->ring.hist + s->ring.hist_n * width);
	s->ring.hist_n++;
	s->ring.hist_next = (floor(s->st.t / s->ring.hist_stride + 0.5) + 1) * s->ring.hist_stride;
}

void srv_ring_sample(srv_session *s)
{
	double *feed = srv_ring_feed(s, s->ring.head % s->ring.cap);
	srv_slot *slot = push_slot(s);
	slot->kind = API_REC_SAMPLE;
	slot->st = s->st;
	size_t n = (size_t)s->columns +
		   2 * (size_t)s->columns * (size_t)s->layers;
	if (n)
		memcpy(feed, s->scratch.column_disp, n * sizeof(double));
	record_history(s);
}

void srv_ring_gather(srv_session *s)
{
	if (!s->columns)
		return;
	sim_column_displacement(s->sim, s->scratch.column_disp);
	sim_feed_state(s->sim, s->scratch.xi, s->scratch.eta);
}

/* ---- records for readers ------------------------------------------------ */

int srv_sample_alloc(api_sample *rec, int columns, int layers)
{
	size_t n = (size_t)columns + 2 * (size_t)columns * (size_t)layers;
	memset(rec, 0, sizeof *rec);
	rec->column_disp = calloc(n ? n : 1, sizeof(double));
	if (!rec->column_disp)
		return -1;
	rec->columns = columns;
	rec->layers = layers;
	rec->xi = rec->column_disp + columns;
	rec->eta = rec->xi + (size_t)columns * (size_t)layers;
	return 0;
}

void srv_sample_free(api_sample *rec)
{
	if (!rec)
		return;
	free(rec->column_disp);
	rec->column_disp = rec->xi = rec->eta = NULL;
}

/* Record idx of the ring into dst (lock held). */
static void copy_record(srv_session *s, api_sample *dst, uint64_t idx)
{
	size_t i = idx % s->ring.cap;
	const srv_slot *src = &s->ring.slots[i];
	size_t n = (size_t)s->columns +
		   2 * (size_t)s->columns * (size_t)s->layers;
	dst->index = src->index;
	dst->kind = src->kind;
	dst->st = src->st;
	dst->columns = s->columns;
	dst->layers = s->layers;
	if (src->kind == API_REC_SAMPLE && n)
		memcpy(dst->column_disp, srv_ring_feed(s, i), n * sizeof(double));
	if (src->kind == API_REC_EVENT) {
		memcpy(dst->event_type, s->ring.events[i].type, sizeof dst->event_type);
		memcpy(dst->event, s->ring.events[i].json, sizeof dst->event);
	} else {
		dst->event_type[0] = '\0';
	}
}

/* ---- snapshot readers ----------------------------------------------------- */

/* The ring's bounds and the run state (lock held). */
static void look(srv_session *s, srv_ring_read *rd)
{
	rd->head = s->ring.head;
	rd->oldest = s->ring.head > s->ring.cap ? s->ring.head - s->ring.cap : 0;
	rd->state = s->state;
	rd->removed = s->stop;
	rd->t = s->st.t;
}

srv_ring_read srv_session_ring(srv_session *s)
{
	srv_ring_read rd;
	pthread_mutex_lock(&s->lock);
	look(s, &rd);
	pthread_mutex_unlock(&s->lock);
	return rd;
}

void srv_session_read(srv_session *s, uint64_t cursor, double from_t,
		      api_sample *dst, srv_ring_read *rd)
{
	pthread_mutex_lock(&s->lock);
	look(s, rd);
	uint64_t idx = cursor > rd->oldest ? cursor : rd->oldest;
	/* samples before from_t are passed over here, without a copy */
	while (idx < rd->head) {
		const srv_slot *r = &s->ring.slots[idx % s->ring.cap];
		if (r->kind != API_REC_SAMPLE || r->st.t >= from_t)
			break;
		idx++;
	}
	rd->next = idx;
	if (idx < rd->head)
		copy_record(s, dst, idx);
	pthread_mutex_unlock(&s->lock);
}

void srv_session_wait(srv_session *s, const srv_ring_read *rd, double from_t,
		      double seconds)
{
	pthread_mutex_lock(&s->lock);
	/* what would wake it: an event, a sample at or past from_t, a change
	 * of state, the deletion */
	int news = s->ring.event_head > rd->head ||
		   (s->ring.head > rd->head && s->st.t >= from_t) ||
		   s->state != rd->state || s->stop;
	if (!news) {
		if (from_t < s->ring.wake_t)
			s->ring.wake_t = from_t; /* the worker wakes it from then */
		if (s->ring.plan_t < INFINITY && from_t < s->ring.plan_t - 1e-6)
			pthread_cond_signal(&s->wake); /* a paced worker sleeps past it */
		struct timespec ts = srv_deadline(seconds);
		pthread_cond_timedwait(&s->data, &s->lock, &ts);
	}
	pthread_mutex_unlock(&s->lock);
}

api_err srv_session_stream_open(srv_session *s, srv_stream_charge *c, api_problem *pb)
{
	api_err e = API_OK;
	pthread_mutex_lock(&s->lock);
	srv_session_budget *b = &s->budget;
	double before = srv_paced_cost(s, s->pace);
	c->next = b->streams;
	b->streams = c;
	if (srv_paced_need(s) > 0) /* running paced: held from now */
		e = srv_budget_take_stream(&b->paced_held, before,
					   srv_paced_cost(s, s->pace), s->pace, pb);
	if (e == API_OK)
		s->streams++;
	else
		b->streams = c->next;
	pthread_mutex_unlock(&s->lock);
	return e;
}

void srv_session_stream_close(srv_session *s, srv_stream_charge *c)
{
	pthread_mutex_lock(&s->lock);
	srv_session_budget *b = &s->budget;
	double was = srv_paced_need(s);
	srv_stream_charge **at = &b->streams;
	while (*at && *at != c)
		at = &(*at)->next;
	if (*at)
		*at = c->next;
	s->streams--;
	/* given back at once (a hold raised for a queued control keeps the
	 * rest until the worker applies it: worker_budget.c) */
	if (was > 0)
		srv_budget_set_paced(&b->paced_held,
				     b->paced_held - (was - srv_paced_need(s)));
	pthread_mutex_unlock(&s->lock);
}

void srv_session_feed_size(const srv_session *s, int *columns, int *layers)
{
	*columns = s->columns;
	*layers = s->layers;
}

size_t srv_session_history(srv_session *s, double from, double to,
			   double **rows, double *stride)
{
	pthread_mutex_lock(&s->lock);
	size_t width = API_HISTORY_WIDTH(s->columns);
	size_t first = 0, last = s->ring.hist_n;
	while (first < s->ring.hist_n && s->ring.hist[first * width] < from)
		first++;
	while (last > first && s->ring.hist[(last - 1) * width] > to)
		last--;
	size_t n = last - first;
	*rows = malloc((n ? n : 1) * width * sizeof(double));
	if (*rows && n)
		memcpy(*rows, s->ring.hist + first * width, n * width * sizeof(double));
	*stride = s->ring.hist_stride;
	pthread_mutex_unlock(&s->lock);
	return *rows ? n : 0;
}
