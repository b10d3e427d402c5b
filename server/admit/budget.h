/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * budget.h - the daemon's resource budgets, so that no one client takes the
 * machine: memory (the need of each session and stream, estimated before it
 * is created and reserved against --max-memory), the cores that running
 * paced sessions need (each its CPU s per simulated s times its pace,
 * committed against --max-paced-cores before it is created, resumed or
 * sped up), CPU turns for pace "max" sessions (at most --max-busy step at
 * once, taking turns in time slices, first come first served) and the
 * open connections of each client address (counted in libmicrohttpd's
 * connection notification), and the requests that settle simulations in
 * their own thread at once (--max-settling). The CPU turns are in
 * budget_turns.h.
 *
 * A leaf like metrics.c: it calls nothing else of server/ but util.c. Its
 * lock is a leaf of the lock order (registry.h): nothing is taken under it
 * (it only signals a waiting worker's condition).
 */
#ifndef CONVSIM_BUDGET_H
#define CONVSIM_BUDGET_H

#include <microhttpd.h>
#include <pthread.h>
#include <stdarg.h>
#include <stddef.h>

#include "api.h"
#include "config.h"

/* Keep cfg (borrowed for the daemon's life). */
void srv_budget_init(const srv_config *cfg);
/* The connections' counts per client address (budget_clients.c); called
 * by srv_budget_init. */
void srv_budget_clients_init(const srv_config *cfg);

/* ---- memory ---------------------------------------------------------------- */

/* Estimated bytes of a session with this feed (0 x 0 without feed): the
 * core instance, its worker, the record ring (--ring) and the trajectory
 * history (--history) when full. */
size_t srv_budget_session_need(int columns, int layers);
/* Estimated bytes of one stream client of such a session. */
size_t srv_budget_stream_need(int columns, int layers);
/* Reserve a session's need: API_OK (*need set), 422 when it alone exceeds
 * the whole budget (naming scene.layers or scene.columns with the largest
 * value that fits) or 503 when the budget has no room now; *pb names the
 * budget. Nothing is reserved on failure. */
api_err srv_budget_take_session(int columns, int layers, size_t *need,
				api_problem *pb);
/* Reserve bytes for what (a noun for the message): API_OK or 503 with *pb.
 * force: reserve even beyond the budget (a session restored at start-up). */
api_err srv_budget_take(size_t bytes, const char *what, int force,
			api_problem *pb);
/* Give back a reservation (0 is accepted). */
void srv_budget_give(size_t bytes);
/* Bytes reserved now, and the budget. */
size_t srv_budget_reserved(void);
size_t srv_budget_memory(void);

/* ---- cores of paced sessions ------------------------------------------------ */

/* The cost model (budget_cost.c): doubles per record of a feed (column
 * displacements, xi and eta); CPU s a worker spends on one published
 * sample of a feed of columns x layers besides the core's step, the
 * status and the feed's arrays read out (ring record, trajectory row,
 * sleeping and waking): what cpu_probe.c adds to its measure. */
size_t srv_budget_record_doubles(int columns, int layers);
double srv_budget_sample_cpu(int columns, int layers);
/* Estimated CPU s per simulated s of a session before it has run: from
 * its integrator (method, the step dt and the feed sub-steps in use, as
 * sim_get_status reports them after sim_new) and the feed elements it
 * integrates (feed: columns x layers; the symmetric reduction integrates
 * one representative column). Calibrated on this machine (docs/budgets.md "Budgets
 * and load"); a running session's worker measures its own. */
double srv_budget_cpu_estimate(const api_spec *spec, const sim_status *st,
			       int columns, int layers);
/* Estimated CPU s of the steady start's settling (0 for a start at rest):
 * scene.settle simulated s over the columns it integrates
 * (st->settle_columns, each of layers elements) with the same model, no
 * samples published; the creating request's thread runs it whole. */
double srv_budget_settle_cpu(const api_spec *spec, const sim_status *st, int layers);
/* The settling's estimate (srv_budget_settle_cpu) before the instance is
 * built, from what sim_new would integrate (sim_preview); 0 for a set it
 * refuses. */
double srv_budget_settle_preview(const api_spec *spec);
/* The same estimates before the instance is built: from what sim_new
 * would integrate (sim_preview: the set validated, nothing settled), so
 * that a creation the cores cannot take is refused for the price of its
 * parse. API_OK and *cpu_per_s, or sim_new's validation error in *pb as a
 * session's creation answers it. Then the work no worker's grant or stop
 * interrupts (API_RANGE with *pb, budget "cpu", nothing built): a sample
 * interval, which the worker advances whole, estimated beyond
 * SRV_SAMPLE_CPU_MAX (422 naming integrator.dt, about the least step that
 * fits as min), and the settling of a steady start, which runs in the
 * creating request's thread, beyond --max-cpu-seconds (srv_budget_cost_init)
 * less before, the CPU s the request's thread spent before it (an
 * experiment's measurements; 0: none) (422 naming scene.settle, the
 * longest that fits as max). */
#define SRV_SAMPLE_CPU_MAX 1.0 /* CPU s: well within a control's 5-s wait */
api_err srv_budget_cpu_preview(const api_spec *spec, double before, double *cpu_per_s,
			       api_problem *pb);
/* The refusal of a creation whose settling the core stopped at
 * --max-cpu-seconds less before (as above) (sim_new_bounded's SIM_ECPU)
 * after spent CPU s of its own, with settled of scene.settle's simulated s
 * settled: 422, budget "cpu", naming integrator.method with the methods of
 * a fixed step as choices where the method is adaptive (no estimate knows
 * its steps), else scene.settle with what settled as max. Returns
 * API_RANGE. */
api_err srv_budget_settle_stopped(const api_spec *spec, double before, double spent,
				  double settled, api_problem *pb);
/* An adaptive method's creation whose first spent CPU s settled settled of
 * scene.settle's simulated s (cpu_probe.c's peek), with left CPU s of the
 * request's --max-cpu-seconds from its start: where its whole settling
 * would take twice left or more at that rate, 1 and *pb (422, budget
 * "cpu", naming integrator.method with the methods of a fixed step as
 * choices), refused before it settles; else 0. */
int srv_budget_settle_peeked(const api_spec *spec, double left, double spent, double settled,
			     api_problem *pb);
/* 1 when spec's method is adaptive; the methods of a fixed step into
 * names ("rk4, euler, dem", for a detail) and choices (api_choices_of's
 * "rk4|euler|dem"), each of its length in bytes. */
int srv_budget_fixed_methods(const api_spec *spec, char *names, size_t names_len,
			     char *choices, size_t choices_len);
/* 1 when spec's method is adaptive (its steps are known only once it runs). */
int srv_budget_adaptive(const api_spec *spec);
/* A job's run (a sweep's point, a fit's evaluation): a steady start's
 * settling and t_end simulated s, which nothing interrupts once begun (a
 * DELETE, a SIGTERM wait for it). One estimated beyond --max-cpu-seconds
 * (srv_budget_cost_init) is refused: 422, budget "cpu", naming t_end with
 * the longest after scene.transient that fits as max, or integrator.dt
 * (about the least step that fits as min) where none does. API_OK (also
 * for a set sim_new refuses: the run fails at once) or API_RANGE with
 * *pb. */
void srv_budget_cost_init(double max_cpu_seconds);
/* --max-cpu-seconds: also what a request's own measurements may cost. */
double srv_budget_run_limit(void);
/* Estimated CPU s of one sim_measure of spec to t_end (its first run:
 * the settling, then sim_measure_span's simulated s; no samples), as the
 * request's thread of an identification or a closed loop runs it; 0 for
 * a set sim_new refuses (it fails at once). */
double srv_budget_measure_cpu(const api_spec *spec, double t_end);
api_err srv_budget_run_check(const api_spec *spec, double t_end, api_problem *pb);

/* Raise what a paced session holds (*held, cores; the caller's, guarded
 * by its lock) to need = cpu_per_s x pace. API_OK when need <= *held or
 * the running paced sessions' sum stays within --max-paced-cores; else
 * nothing changes and *pb is 503 (budget "cpu", Retry-After, field named)
 * or, when need alone is more than the whole budget, 422 naming field
 * with the largest pace that fits as max. verb: "created" or "changed",
 * for the message. */
api_err srv_budget_take_paced(double *held, double cpu_per_s, double pace,
			      const char *field, const char *verb,
			      api_problem *pb);
/* Raise *held (cores) to need if need <= *held or the running paced
 * sessions' sum stays within --max-paced-cores with it: 1; else 0 and
 * nothing changes. *taken: the cores all hold after. */
int srv_budget_raise_paced(double *held, double need, double *taken);
/* What a stream client of a session costs the daemon (budget_stream.c,
 * measured with tests/bench/stream_cost.mjs, docs/budgets.md): the records
 * it takes a simulated s (sample_rate of its session, thinned to rate when
 * 0 < rate) and the CPU s a simulated s of formatting their numbers
 * (api_record_numbers of its fields); next links a session's streams. */
typedef struct srv_stream_charge {
	double records;
	double numbers_cpu;
	struct srv_stream_charge *next;
} srv_stream_charge;
srv_stream_charge srv_budget_stream_charge(double sample_rate, double rate,
					   unsigned fields, int columns, int layers);
/* CPU s per simulated s that the streams linked from list cost at pace
 * (> 0): their numbers, and a wake-up a record but at most one per paced
 * batch (50 a wall s) each, so at most 50 / pace a simulated s each. */
double srv_budget_streams_cpu(const srv_stream_charge *list, double pace);
/* Raise what a running paced session holds (*held) to after x pace for a
 * stream it opens, before and after its cost (CPU s per simulated s, its
 * own and its streams') without and with the stream: API_OK, else nothing
 * changes and *pb is 503 (budget "cpu", Retry-After) naming what the
 * stream needs and what is taken. */
api_err srv_budget_take_stream(double *held, double before, double after,
			       double pace, api_problem *pb);
/* Set what a session holds to need (cores, >= 0), even beyond the budget:
 * its worker's own measure, a pause, the end. */
void srv_budget_set_paced(double *held, double need);
/* CPU s per simulated s a paced session costs at a pace (> 0): its own
 * and its streams' (their share falls as the pace rises: budget_stream.c),
 * so that its need, pace x cost, grows with the pace. */
typedef double (*srv_pace_cost)(const void *session, double pace);
/* The greatest pace at which session needs at most `cores`: bisection on
 * its growing need (0 where `cores` is none). */
double srv_budget_greatest_pace(srv_pace_cost cost, const void *session, double cores);
/* The pace, at most pace, at which a running paced session of that cost
 * fits beside the other paced sessions' holds within --max-paced-cores
 * (three significant digits, rounded down; at least API_PACE_MIN even
 * where that does not fit); *held is set to its need at that pace. */
double srv_budget_fit_pace(double *held, srv_pace_cost cost, const void *session, double pace);
/* Cores held by running paced sessions now, and the budget. */
double srv_budget_paced(void);
double srv_budget_paced_limit(void);

/* ---- requests settling ------------------------------------------------------- */

/* A request that builds and settles simulations in its own thread (a
 * session's creation: its instance, the steady start's settling, the
 * probe; an identification's or a closed loop's measurements at the
 * request) holds one of --max-settling slots meanwhile (budget_settling.c;
 * cfg borrowed). take: API_OK with *held 1; else at once, nothing taken,
 * *pb is 503 (budget "settling", its limit, Retry-After 1). give: gives
 * the slot back where *held (then 0); any number of times. Its lock is a
 * leaf of the lock order (registry.h). */
void srv_budget_settling_init(const srv_config *cfg);
api_err srv_budget_take_settling(int *held, api_problem *pb);
void srv_budget_give_settling(int *held);
/* Requests settling now, the most at once so far, those refused so far. */
void srv_budget_settling_counts(int *now, int *most, unsigned long long *refused);

/* ---- queued sweep points ------------------------------------------------------ */

/* Reserve n sweep points (queued or running, all sweeps): API_OK, 422 when
 * n alone exceeds --max-queued-points (naming field), or 429 with a
 * Retry-After from the measured time per point; *pb names the budget.
 * force: reserve beyond the budget (a sweep restored at start-up). */
api_err srv_budget_take_points(size_t n, const char *field, int force,
			       api_problem *pb);
/* One point is done (or skipped) after seconds of wall time (0: skipped). */
void srv_budget_point_done(double seconds);
/* Give back n points that were never queued. */
void srv_budget_give_points(size_t n);
/* Points queued or running now. */
size_t srv_budget_points(void);

/* ---- connections per client ------------------------------------------------- */

/* libmicrohttpd's connection notification: counts the connections of each
 * client address (MHD_OPTION_NOTIFY_CONNECTION, cls unused). */
void srv_budget_connection(void *cls, struct MHD_Connection *conn,
			   void **socket_context,
			   enum MHD_ConnectionNotificationCode code);
/* Connections open from sa's address now (0 when none, or no IP). */
int srv_budget_open_from(const struct sockaddr *sa);
/* Count a connection closed at accept (acceptor.h: no room). */
void srv_budget_count_dropped(void);
/* conn's entry in the table of open connections and their deadlines
 * (conns.h), borrowed until libmicrohttpd closes it; NULL if it has none. */
struct srv_conn *srv_budget_live(struct MHD_Connection *conn);
/* 1 if conn was opened beyond its client's --max-client-connections
 * while every other connection of that client was being answered (none
 * could be closed to make room: conns.h), with *pb naming the budget: it
 * gets a 429 and is closed. */
int srv_budget_client_over(struct MHD_Connection *conn, api_problem *pb);
/* Connections answered 429 by the per-client budget so far, and those
 * closed without an answer (beyond the 429s' grace: conns.h; or
 * libmicrohttpd's own limits at accept). */
unsigned long long srv_budget_client_refused(void);
unsigned long long srv_budget_connections_dropped(void);
/* libmicrohttpd's error log (MHD_OPTION_EXTERNAL_LOGGER): its refusals at
 * the connection limits are counted and logged at debug level (thousands
 * of idle sockets must not flood the log), the rest as warnings. */
void srv_budget_mhd_log(void *cls, const char *fmt, va_list ap);

#endif
