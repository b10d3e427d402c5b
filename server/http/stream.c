/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * stream.c - GET /api/v1/sessions/{id}/stream: Server-Sent Events or
 * NDJSON.
 *
 * Each client has a cursor into its session's record ring. The
 * connection's own thread (libmicrohttpd runs one per connection) waits
 * for new records and copies them out one at a time through session.c's
 * snapshot readers (srv_session_read, srv_session_wait; it never takes the
 * session lock itself) and formats them outside the lock, so a client
 * only ever slows itself: the worker overwrites the ring regardless, and
 * a client that fell behind the oldest record gets a "dropped" notice with
 * the number of records it missed, then continues from the oldest one.
 * Resume with Last-Event-ID (or ?since=ID) from the ring; heartbeats keep
 * idle connections alive; the stream ends with an "end" record when the
 * session finishes, fails or is deleted, at ?limit=N records, or when the
 * daemon shuts down.
 */
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "api_routes.h"
#include "budget.h"
#include "metrics.h"
#include "session.h"
#include "stream.h"
#include "util.h"

static const srv_config *cfg;

void srv_streams_init(const srv_config *config)
{
	cfg = config;
}

typedef struct stream {
	srv_session *s;
	int ndjson;
	unsigned fields;
	double rate;       /* samples per simulated second, 0: all */
	double next_t;
	uint64_t cursor;   /* next record index to send */
	uint64_t limit, sent;
	api_sample rec;
	size_t rec_max;
	char *out;
	size_t out_len, out_pos, out_cap;
	double last_write;
	double heartbeat;  /* s */
	int ended;
	size_t mem_reserved; /* bytes of the memory budget */
	srv_stream_charge charge; /* in the cores for paced sessions
				     (budget.h) */
} stream;

static void end_stream(stream *k, const char *reason)
{
	k->out_len += api_format_end(k->out + k->out_len,
				     k->out_cap - k->out_len, reason,
				     k->ndjson);
	k->ended = 1;
}

/* The earliest sample time k takes next (s): ?rate thins samples out
 * (-INFINITY: every sample). The ring's reader passes over the others
 * without copying them, and the worker wakes k only when one exists. */
static double from_t(const stream *k)
{
	return k->rate > 0 ? k->next_t - 1e-9 : -INFINITY;
}

/* Format the record just copied into k->rec unless ?rate thins it out. */
static void put_record(stream *k)
{
	if (k->rec.kind == API_REC_SAMPLE && k->rate > 0) {
		double t = k->rec.st.t;
		if (t < k->next_t - 1e-9)
			return;
		k->next_t = (floor(t * k->rate + 1e-6) + 1) / k->rate;
	}
	k->out_len += api_format_record(k->out + k->out_len,
					k->out_cap - k->out_len, &k->rec,
					k->fields, k->ndjson);
	k->sent++;
	atomic_fetch_add(&srv_stats.stream_records, 1);
	if (k->limit && k->sent >= k->limit)
		end_stream(k, "limit");
}

/* Wait for and format the next batch of records into k->out. */
static void fill(stream *k)
{
	while (!k->ended) {
		srv_ring_read rd;
		srv_session_read(k->s, k->cursor, from_t(k), &k->rec, &rd);
		if (srv_stopping()) {
			end_stream(k, "shutdown");
			break;
		}
		if (rd.removed) {
			end_stream(k, "deleted");
			break;
		}
		if (k->cursor < rd.oldest) {
			uint64_t missed = rd.oldest - k->cursor;
			atomic_fetch_add(&srv_stats.dropped_samples, missed);
			k->out_len += api_format_dropped(
				k->out + k->out_len, k->out_cap - k->out_len,
				missed, rd.oldest, k->ndjson);
			k->cursor = rd.oldest;
		}
		if (rd.next < rd.head) { /* srv_session_read copied it */
			k->cursor = rd.next + 1;
			put_record(k);
			if (k->out_len + k->rec_max > k->out_cap)
				break;
			continue;
		}
		k->cursor = rd.head; /* the samples passed over are done */
		if (k->out_len)
			break;
		if (rd.state == SRV_FINISHED || rd.state == SRV_FAILED) {
			end_stream(k, rd.state == SRV_FINISHED ? "finished"
							       : "failed");
			break;
		}
		double idle = srv_now() - k->last_write;
		if (idle >= k->heartbeat) {
			k->out_len += api_format_heartbeat(
				k->out + k->out_len, k->out_cap - k->out_len,
				rd.t, k->ndjson);
			break;
		}
		double wait = k->heartbeat - idle;
		srv_session_wait(k->s, &rd, from_t(k), wait < 0.5 ? wait : 0.5);
	}
	k->last_write = srv_now();
}

static ssize_t reader(void *cls, uint64_t pos, char *buf, size_t max)
{
	(void)pos;
	stream *k = cls;
	if (k->out_pos == k->out_len) {
		k->out_pos = k->out_len = 0;
		if (k->ended)
			return MHD_CONTENT_READER_END_OF_STREAM;
		fill(k);
		if (k->out_len == 0)
			return MHD_CONTENT_READER_END_OF_STREAM;
	}
	size_t n = k->out_len - k->out_pos;
	if (n > max)
		n = max;
	memcpy(buf, k->out + k->out_pos, n);
	k->out_pos += n;
	return (ssize_t)n;
}

static void stream_free(void *cls)
{
	stream *k = cls;
	srv_session_stream_close(k->s, &k->charge);
	atomic_fetch_sub(&srv_stats.stream_clients, 1);
	srv_session_put(k->s);
	srv_budget_give(k->mem_reserved);
	srv_sample_free(&k->rec);
	free(k->out);
	free(k);
}

/* Parse the stream options; 0 and *pb on a bad one. */
static int parse_options(srv_req *r, stream *k, int64_t *resume,
			 api_problem *pb)
{
	api_stream_query q;
	if (api_parse_stream_query(srv_query(r, "format"),
				   srv_header(r, MHD_HTTP_HEADER_ACCEPT),
				   srv_query(r, "fields"), srv_query(r, "rate"),
				   srv_query(r, "limit"),
				   srv_header(r, "Last-Event-ID"),
				   srv_query(r, "since"), &q, pb) != API_OK)
		return 0;
	k->ndjson = q.ndjson;
	k->fields = q.fields;
	k->rate = q.rate;
	k->limit = q.limit;
	*resume = q.resume;
	return 1;
}

/* Admit a stream of session r->arg[0]: 1 with the session held in k->s, a
 * stream client counted, its memory taken, its CPU charged with its
 * session's in the cores for paced sessions and the feed's size in
 * *columns, *layers; else 0, k freed and the answer in *res (404, 429
 * --max-streams, 503 memory, 503 cpu). */
static int admit(srv_req *r, stream *k, int *columns, int *layers, enum MHD_Result *res)
{
	api_problem pb;
	k->s = srv_session_get(r->arg[0]);
	if (!k->s) {
		free(k);
		*res = srv_fail(r, API_NOTFOUND, NULL,
				"no session with id \"%.40s\"", r->arg[0]);
		return 0;
	}
	if (srv_session_replaying(k->s, &pb) != API_OK) {
		srv_session_put(k->s);
		free(k);
		*res = srv_reply_problem(r, &pb, NULL);
		return 0;
	}
	if (atomic_fetch_add(&srv_stats.stream_clients, 1) >=
	    cfg->max_streams) {
		atomic_fetch_sub(&srv_stats.stream_clients, 1);
		srv_session_put(k->s);
		free(k);
		api_fail(&pb, API_LIMIT, NULL,
			 "%d stream client%s %s connected, the limit (--max-streams)",
			 cfg->max_streams, api_plural(cfg->max_streams, "", "s"),
			 api_plural(cfg->max_streams, "is", "are"));
		api_budget(&pb, "streams", cfg->max_streams, 1);
		*res = srv_reply_problem(r, &pb, NULL);
		return 0;
	}
	srv_session_feed_size(k->s, columns, layers);
	size_t need = srv_budget_stream_need(*columns, *layers);
	if (srv_budget_take(need, "this stream", 0, &pb) != API_OK)
		goto counted;
	k->charge = srv_budget_stream_charge(srv_session_spec(k->s)->sample_rate, k->rate,
					     k->fields, *columns, *layers);
	if (srv_session_stream_open(k->s, &k->charge, &pb) != API_OK)
		goto reserved;
	k->mem_reserved = need;
	atomic_fetch_add(&srv_stats.streams_opened, 1);
	return 1;
	/* refused by a budget (503 memory, 503 cpu): what was taken given back */
reserved:
	srv_budget_give(need);
counted:
	atomic_fetch_sub(&srv_stats.stream_clients, 1);
	srv_session_put(k->s);
	free(k);
	*res = srv_reply_problem(r, &pb, NULL);
	return 0;
}

/* The cursor where the stream starts: after record resume, or the newest. */
static void start_cursor(stream *k, int64_t resume)
{
	srv_ring_read rv = srv_session_ring(k->s);
	if (resume >= 0)
		k->cursor = (uint64_t)resume + 1 < rv.head
				    ? (uint64_t)resume + 1
				    : rv.head;
	else
		k->cursor = rv.head > rv.oldest ? rv.head - 1 : rv.head;
}

/* The first record into k->out: where the stream starts, and the scene's
 * model error as its controls stand now (each control event carries it
 * anew); 0 out of memory. */
static int put_hello(stream *k)
{
	api_view *view = calloc(1, sizeof *view);
	if (!view)
		return 0;
	srv_session_view(k->s, view);
	sim_model_error me;
	int mc = api_model_check(srv_session_spec(k->s), view->has_status ? &view->st : NULL, &me);
	free(view);
	k->out_len = api_format_hello(k->out, k->out_cap, srv_session_id(k->s), k->cursor,
				      mc == 0 ? me.note : NULL, &me, k->ndjson);
	return 1;
}

/* Answer 200 with the stream k as the body, read by reader. */
static enum MHD_Result respond(srv_req *r, stream *k)
{
	struct MHD_Response *resp = MHD_create_response_from_callback(
		MHD_SIZE_UNKNOWN, 32 * 1024, reader, k, stream_free);
	if (!resp) {
		stream_free(k);
		return MHD_NO;
	}
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE,
				k->ndjson ? "application/x-ndjson"
					  : "text/event-stream");
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL,
				"no-store");
	MHD_add_response_header(resp, "X-Accel-Buffering", "no");
	return srv_queue(r, 200, resp);
}

enum MHD_Result srv_h_stream(srv_req *r)
{
	api_problem pb;
	int64_t resume;
	stream *k = calloc(1, sizeof *k);
	if (!k)
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	if (!parse_options(r, k, &resume, &pb)) {
		free(k);
		return srv_reply_problem(r, &pb, NULL);
	}
	k->heartbeat = cfg->heartbeat;
	enum MHD_Result res;
	int columns, layers;
	if (!admit(r, k, &columns, &layers, &res))
		return res;
	k->rec_max = api_record_max(columns, layers);
	k->out_cap = 4 * k->rec_max + 65536;
	k->out = malloc(k->out_cap);
	if (!k->out || srv_sample_alloc(&k->rec, columns, layers)) {
		stream_free(k);
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	}
	start_cursor(k, resume);
	if (!put_hello(k)) {
		stream_free(k);
		return srv_fail(r, API_UNAVAILABLE, NULL, "out of memory");
	}
	k->last_write = srv_now();
	return respond(r, k);
}
