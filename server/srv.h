/*
 * srv.h - the daemon's internal interface, shared by the files of server/.
 *
 * server/ owns sockets (libmicrohttpd, thread per connection), threads
 * (one worker per session, a small pool for sweeps), sessions and files.
 * It never parses or prints JSON itself: api/ does that. This header
 * declares the configuration, logging, the request/reply helpers, the
 * route handlers and the session machinery the handlers share.
 */
#ifndef CONVSIM_SRV_H
#define CONVSIM_SRV_H

#include <microhttpd.h>
#include <pthread.h>
#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "api.h"
#include "sim.h"

/* ---- configuration and logging ---------------------------------------- */

typedef struct srv_config {
	const char *listen;    /* address to bind, "127.0.0.1" */
	int port;              /* 0: ephemeral */
	int max_sessions;
	int max_streams;       /* open stream clients, all sessions */
	size_t max_body;       /* bytes */
	const char *data_dir;  /* NULL: results are not saved */
	const char *web_root;  /* static files served at / */
	int log_level;         /* SRV_LOG_* */
	int ring;              /* stream records kept per session */
	int history;           /* trajectory rows kept per session */
	int pool_threads;      /* sweep workers */
	double heartbeat;      /* s between stream heartbeats */
	int max_experiments, max_sweeps;
} srv_config;

enum { SRV_LOG_ERROR, SRV_LOG_WARN, SRV_LOG_INFO, SRV_LOG_DEBUG };

extern srv_config srv_cfg;         /* read-only once the daemon runs */
extern atomic_int srv_stopping;    /* set on SIGTERM/SIGINT */

void srv_log(int level, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
/* Wall-clock seconds: monotonic (for pacing) and unix time. */
double srv_now(void);
double srv_unix_time(void);
/* A fresh random id of 16 hex digits into id (>= 17 bytes). */
void srv_new_id(char *id);
/* Absolute deadline for pthread_cond_timedwait, seconds from now. */
struct timespec srv_deadline(double seconds);

/* ---- requests and replies ------------------------------------------------- */

typedef struct srv_req {
	struct MHD_Connection *conn;
	const char *method;
	const char *url;
	char arg[2][64];       /* path parameters ("*" segments) */
	const char *body;      /* NUL-terminated, body_len bytes */
	size_t body_len;
	int has_content_type;
	int json_body;         /* Content-Type is application/json */
} srv_req;

typedef enum MHD_Result (*srv_handler)(srv_req *r);

/* Queue a reply. text is malloc'd and taken (freed here); NULL text gives
 * a 503 problem. extra_name/extra_value add one header (may be NULL). */
enum MHD_Result srv_reply(srv_req *r, int status, const char *ctype,
			  char *text, const char *extra_name,
			  const char *extra_value);
enum MHD_Result srv_reply_json(srv_req *r, int status, char *text);
/* Queue a static, borrowed buffer (not freed). */
enum MHD_Result srv_reply_static(srv_req *r, int status, const char *ctype,
				 const void *data, size_t len);
/* RFC 9457 problem reply for *pb (405 adds Allow from allow if given). */
enum MHD_Result srv_reply_problem(srv_req *r, const api_problem *pb,
				  const char *allow);
enum MHD_Result srv_fail(srv_req *r, api_err code, const char *field,
			 const char *fmt, ...)
	__attribute__((format(printf, 4, 5)));
/* Queue a response and count its status for /metrics. */
enum MHD_Result srv_queue(srv_req *r, int status, struct MHD_Response *resp);
/* Query argument or NULL; header value or NULL. */
const char *srv_query(srv_req *r, const char *key);
const char *srv_header(srv_req *r, const char *name);
/* 1 if the request carries a JSON body (or none, when empty_ok); else
 * queues 415 and returns 0 (the handler then returns *result). */
int srv_need_json(srv_req *r, int empty_ok, enum MHD_Result *result);
/* Table format from ?format=json|csv or Accept: text/csv: 0 json, 1 csv,
 * -1 with *pb (400) when ?format= names something else. */
int srv_table_format(srv_req *r, api_problem *pb);

/* ---- metrics ------------------------------------------------------------- */

typedef struct srv_metrics {
	atomic_ullong sessions_created, sessions_deleted;
	atomic_ullong steps;             /* all sessions */
	atomic_int stream_clients;
	atomic_ullong streams_opened, dropped_samples, stream_records;
	atomic_ullong sweep_points, experiments;
	atomic_ullong requests[6];       /* by status class 1xx..5xx (index 1..5) */
} srv_metrics;
extern srv_metrics srv_stats;
void srv_metrics_count(int status);
char *srv_metrics_text(void);

/* ---- sessions ------------------------------------------------------------- */

typedef struct srv_session srv_session;
typedef struct srv_experiment srv_experiment;

enum { SRV_RUNNING, SRV_PAUSED, SRV_FINISHED, SRV_FAILED };

void srv_sessions_init(void);
/* Stop every worker, end every stream, free all sessions. */
void srv_sessions_shutdown(void);
/* Create a session from spec (copied) and start its worker, with exp
 * (may be NULL; borrowed, must outlive the attachment) attached before
 * the first step. Returns a new reference or NULL with *pb set. */
srv_session *srv_session_create(const api_spec *spec, srv_experiment *exp,
				api_problem *pb);
/* Look up by id; returns a new reference or NULL. */
srv_session *srv_session_get(const char *id);
/* Drop a reference; the last one frees the session. NULL is accepted. */
void srv_session_put(srv_session *s);
/* Remove from the registry, stop the worker, end the streams. */
void srv_session_delete(srv_session *s);
const char *srv_session_id(const srv_session *s);
/* Fill a view (spec borrowed from s: keep the reference while using it). */
void srv_session_view(srv_session *s, api_view *v);
size_t srv_session_count(void);
/* Every live session as new references in *out (malloc'd array; the
 * caller puts each and frees it). Returns the count. */
size_t srv_sessions_all(srv_session ***out);
/* Let the session run at least up to t_end (s): raise until, resume a
 * finished session. Worker only, session lock held. */
void srv_session_extend(srv_session *s, double t_end);
/* Sum of achieved steps/s of running sessions. */
double srv_sessions_steps_per_s(void);
/* Apply a control through the worker; waits up to timeout_s for the
 * acknowledgement. Returns API_OK (acked, *t_eff set), API_CONFLICT (the
 * session cannot take it, *pb set) or API_UNAVAILABLE (not acknowledged;
 * nothing changed). */
api_err srv_session_control(srv_session *s, const api_control *c,
			    double timeout_s, double *t_eff, api_problem *pb);
/* Attach an experiment to a running session's worker. API_CONFLICT if it
 * already runs one or has failed. */
api_err srv_session_attach(srv_session *s, srv_experiment *e,
			   api_problem *pb);

/* Stream access (stream.c): the ring under the session lock. */
typedef struct srv_ring_view {
	uint64_t head;        /* next index to be written */
	uint64_t oldest;      /* oldest index still held */
} srv_ring_view;
pthread_mutex_t *srv_session_lock(srv_session *s);
pthread_cond_t *srv_session_data_cond(srv_session *s);
/* Under the lock: ring bounds; copy record idx into dst (arrays sized by
 * srv_session_sample_alloc); the run state; the observed time. */
srv_ring_view srv_session_ring(srv_session *s);
void srv_session_copy(srv_session *s, uint64_t idx, api_sample *dst);
int srv_session_state(srv_session *s, int *removed);
double srv_session_time(srv_session *s);
void srv_session_stream_count(srv_session *s, int delta);
/* Allocate / free the arrays of a record for this session's feed size. */
int srv_sample_alloc(api_sample *rec, int columns, int layers);
void srv_sample_free(api_sample *rec);
void srv_session_feed_size(const srv_session *s, int *columns, int *layers);
/* Trajectory rows in [from, to] (s): malloc'd copy into *rows (caller
 * frees), count returned, stride in *stride. */
size_t srv_session_history(srv_session *s, double from, double to,
			   double **rows, double *stride);

/* ---- experiments (experiment.c) ------------------------------------------- */

void srv_experiments_init(void);
void srv_experiments_shutdown(void);
/* Worker hooks, called with the session lock held, in the worker. */
/* Begin an attached experiment at simulated time t (first segment). */
void srv_exp_begin(srv_experiment *e, sim *sm, const sim_status *st,
		   srv_session *s);
/* The next segment boundary (s) or INFINITY. */
double srv_exp_boundary(const srv_experiment *e);
/* After each advance: record, close segments, start the next. Returns 1
 * when the experiment is over (the session detaches it). */
int srv_exp_step(srv_experiment *e, sim *sm, const sim_status *st,
		 srv_session *s);
/* The session ended before the experiment (deleted, failed, shutdown). */
void srv_exp_abort(srv_experiment *e, const char *why);
const char *srv_exp_id(const srv_experiment *e);
/* The session's worker pushes a control event record (lock held). */
void srv_session_push_event(srv_session *s, const char *type,
			    const char *json);

/* ---- worker pool (pool.c) ------------------------------------------------- */

int srv_pool_start(int threads);
/* Queue fn(arg); returns 0, or -1 when stopping. */
int srv_pool_submit(void (*fn)(void *), void *arg);
/* Stop taking jobs, run what is queued (jobs see srv_stopping), join. */
void srv_pool_stop(void);
int srv_pool_queued(void);

/* ---- sweeps (sweep.c) ---------------------------------------------------- */

void srv_sweeps_init(void);
void srv_sweeps_shutdown(void);

/* ---- catalogue (catalog.c) ----------------------------------------------- */

/* Note the start time (health's uptime); free the cached OpenAPI text. */
void srv_catalog_init(void);
void srv_catalog_shutdown(void);

/* ---- handlers ------------------------------------------------------------ */

enum MHD_Result srv_h_sessions_create(srv_req *r);
enum MHD_Result srv_h_sessions_list(srv_req *r);
enum MHD_Result srv_h_session_get(srv_req *r);
enum MHD_Result srv_h_session_patch(srv_req *r);
enum MHD_Result srv_h_session_delete(srv_req *r);
enum MHD_Result srv_h_trajectory(srv_req *r);
enum MHD_Result srv_h_stream(srv_req *r);
enum MHD_Result srv_h_experiments_create(srv_req *r);
enum MHD_Result srv_h_experiments_list(srv_req *r);
enum MHD_Result srv_h_experiment_get(srv_req *r);
enum MHD_Result srv_h_sweeps_create(srv_req *r);
enum MHD_Result srv_h_sweeps_list(srv_req *r);
enum MHD_Result srv_h_sweep_get(srv_req *r);
enum MHD_Result srv_h_sweep_delete(srv_req *r);
enum MHD_Result srv_h_presets(srv_req *r);
enum MHD_Result srv_h_health(srv_req *r);
enum MHD_Result srv_h_metrics(srv_req *r);
enum MHD_Result srv_h_openapi(srv_req *r);
enum MHD_Result srv_h_static(srv_req *r);

/* The access handler and completion callback given to MHD (routes.c). */
enum MHD_Result srv_dispatch(void *cls, struct MHD_Connection *conn,
			     const char *url, const char *method,
			     const char *version, const char *upload_data,
			     size_t *upload_data_size, void **con_cls);
void srv_request_done(void *cls, struct MHD_Connection *conn,
		      void **con_cls, enum MHD_RequestTerminationCode toe);

#endif
