/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * api.h - the JSON face of the conveyor simulator.
 *
 * api/ turns request bodies into core settings and controls, and core
 * state back into JSON, CSV and stream records. It is the only module that
 * sees cJSON; the server hands it byte buffers and plain structs and gets
 * back malloc'd text (caller frees) or text written into its own buffers.
 * Every double that leaves here is printed so that it round-trips (the
 * shortest of %.15g/%.16g/%.17g that parses back to the same value);
 * non-finite values are written as null. Nothing here keeps state or
 * aborts on bad input: errors are reported as api_problem values that
 * map to an HTTP status and an RFC 9457 problem+json body. The jobs'
 * part (experiments, sweeps, fits, listings) is api_jobs.h, which this
 * header includes.
 */
#ifndef CONVSIM_API_H
#define CONVSIM_API_H

#include <stddef.h>
#include <stdint.h>

#include "fit.h"
#include "sim.h"
#include "table.h"

/* ---- errors ----------------------------------------------------------- */

/* X(name, http_status, type slug, title, explanation). 400: the body is not
 * JSON, a value has the wrong JSON type or the query is wrong; 422:
 * well-formed but unacceptable (out of range, unknown name, inconsistent
 * set). The explanation is the page each problem type URI serves. */
#define API_ERRNO_MAP(X)                                                      \
	X(OK, 200, "ok", "OK", "The request succeeded.")                       \
	X(MALFORMED, 400, "malformed-json", "Malformed JSON",                 \
	  "The request body is not one JSON value: a syntax error, or text after it. Send one "   \
	  "JSON object with Content-Type: application/json.")                \
	X(TYPE, 400, "wrong-type", "Wrong type",                              \
	  "A member has the wrong JSON type (a string where a number belongs, true for pace), " \
	  "or the body is not an object. `field` names the member; GET /api/v1/presets lists " \
	  "every setting with its kind.")                                     \
	X(QUERY, 400, "bad-query", "Bad query parameter",                     \
	  "A query parameter is unknown to this route or malformed, or Last-Event-ID is not a " \
	  "record id. `field` names it; the route's parameters are in /api/v1/openapi.json.") \
	X(BADREQUEST, 400, "bad-request", "Bad request",                      \
	  "The request itself is malformed: no Host header, a Host or Content-Length header " \
	  "given twice (RFC 9112), or a header the daemon cannot read. `field` names the " \
	  "header.")                                                          \
	X(UNAUTHORIZED, 401, "unauthorized", "Unauthorized",                  \
	  "The daemon runs with --token-file: send Authorization: Bearer TOKEN (the token in " \
	  "that file). Only the dashboard's files and /api/v1/health are open without it.") \
	X(FORBIDDEN, 403, "forbidden-origin", "Origin not allowed",           \
	  "The request came from a web page of another origin. The daemon answers its own " \
	  "origin and those given with --allow-origin; nothing was changed.") \
	X(NOTFOUND, 404, "not-found", "Not found",                            \
	  "No session, experiment, sweep, path or file has this name. Sessions are gone once " \
	  "deleted; experiments and sweeps once deleted or pushed out by newer ones.")          \
	X(METHOD, 405, "method-not-allowed", "Method not allowed",            \
	  "The path exists but not with this method; the Allow header lists the methods it " \
	  "takes.")                                                           \
	X(NOTACCEPTABLE, 406, "not-acceptable", "Not acceptable",             \
	  "The Accept header names no representation the route has. Result routes answer " \
	  "application/json or text/csv (also chosen with ?format=json|csv); the others " \
	  "application/json.")                                                \
	X(TIMEOUT, 408, "request-timeout", "Request timeout",                \
	  "The body came slower than the daemon allows (--min-body-rate after the first " \
	  "--request-timeout seconds); nothing was done with the request and the "       \
	  "connection is closed. Send it again, at a steady pace.")          \
	X(CONFLICT, 409, "conflict", "Conflict",                              \
	  "The session cannot do this now: it failed (diverged), finished (raise until to " \
	  "resume), until lies in the past, or it already runs an experiment.") \
	X(MISDIRECTED, 421, "misdirected-request", "Misdirected request",    \
	  "The Host header names neither the address the daemon listens on nor a " \
	  "--server-name (a defence against DNS rebinding); nothing was changed.") \
	X(TOOLARGE, 413, "body-too-large", "Request body too large",          \
	  "The body is larger than the daemon's --max-body (`budget` body-bytes, `limit` " \
	  "its bytes); it was not read.")                                     \
	X(HEADERS, 431, "header-fields-too-large", "Request header fields too large", \
	  "The query has more parameters than any route takes (`budget` query-parameters, " \
	  "`limit` 64); it was not read.")                                    \
	X(MEDIATYPE, 415, "unsupported-media-type", "Unsupported media type", \
	  "POST, PATCH, PUT and DELETE must carry Content-Type: application/json, even with " \
	  "an empty body (a web page of another origin cannot send that type unasked).") \
	X(RANGE, 422, "out-of-range", "Value out of range",                   \
	  "A value lies outside its range or choices (or names an unknown preset). `field` " \
	  "names it and `min`/`max` or `choices` say what is allowed. Nothing was changed.") \
	X(UNKNOWN, 422, "unknown-field", "Unknown field",                     \
	  "A member or setting name is not known here; unknown members are refused, never " \
	  "ignored. `field` names it. Nothing was changed.")                 \
	X(INVALID, 422, "invalid-value", "Invalid value",                     \
	  "The values are each in range but do not fit together (the core's sim_validate), " \
	  "the simulation failed on them, or a PATCH changed nothing.")     \
	X(LIMIT, 429, "limit-reached", "Limit reached",                       \
	  "A limit of the daemon is reached (--max-sessions, --max-streams, kept experiments " \
	  "or sweeps, the connections of one client, the queued sweep points). `budget` and " \
	  "`limit` name a budget that refused it. Delete something or retry later "         \
	  "(Retry-After).")                                                   \
	X(UNAVAILABLE, 503, "unavailable", "Service unavailable",             \
	  "The daemon is shutting down, its memory budget (--max-memory) or the cores for " \
	  "paced sessions (--max-paced-cores) have no room for this now (`budget` and `limit` " \
	  "say so; `field` names what asked for the cores: pace, running), or its worker did " \
	  "not take a control within 5 s; nothing was changed. Retry later (Retry-After).")

typedef enum {
#define API_ERR_ENUM(name, status, slug, title, explanation) API_##name,
	API_ERRNO_MAP(API_ERR_ENUM)
#undef API_ERR_ENUM
	API_NERR
} api_err;

/* One problem report. field is the JSON path of the offending member
 * ("params.k_s1"), empty when none; the range or choices are filled when
 * the field is a known setting. */
typedef struct api_problem {
	api_err code;
	char field[64];
	char detail[320];
	int has_range;
	double min, max;
	char choices[96];
	char budget[24];   /* the budget or limit that refused it ("memory",
			      "body-bytes", ...), "" */
	double limit;      /* its limit, in the budget's unit */
	int retry_after;   /* s for Retry-After (429, 503); 0: 1 s */
	int has_position;  /* a malformed body: the byte where it goes wrong */
	size_t position;
	int close;         /* 1: the answer closes its connection (a client
			      over its connections' budget) */
} api_problem;

/* HTTP status of an api_err (500 for an unknown code). */
int api_status(api_err code);
/* HTTP status of a core return code (500 for an unknown code), through
 * the one table in errors.c. */
int api_sim_status(int sim_err);
/* The api_err a core return code maps to. */
api_err api_from_sim(int sim_err);
/* Fill *pb: code, field (may be NULL) and a printf-style detail. If field
 * ends in a setting name of sim_settings(), its range or choices are added.
 * Returns code, so handlers can `return api_fail(...)`. */
api_err api_fail(api_problem *pb, api_err code, const char *field,
		 const char *fmt, ...) __attribute__((format(printf, 4, 5)));
/* v rounded to digits significant digits (as %.{digits}g prints it)
 * towards the inside of a range: up for its lower end, down for its
 * upper, so that the end a refusal states is a value the range takes
 * (0.2 x 166 kg / 40 is 0.8300000000000001 in binary, stated 0.83). */
double api_round_inward(double v, int up, int digits);
/* A value of field outside [min, max] (an open end given as its limit):
 * api_fail with API_RANGE and that range, the problem's min and max
 * members; the one way a refusal states a range that is not the
 * settings table's. Returns API_RANGE. */
api_err api_fail_range(api_problem *pb, const char *field, double min, double max,
		       const char *fmt, ...) __attribute__((format(printf, 5, 6)));
/* The word for n things in a detail, one when n is 1, else many: "%d
 * stream client%s %s connected" with api_plural(n, "", "s") and
 * api_plural(n, "is", "are") reads "1 stream client is connected". */
const char *api_plural(double n, const char *one, const char *many);
/* The same for a figure the detail prints with "%.<digits>g": one when
 * it reads "1" there (0.9996 at 3 digits: "1 core"), else many. */
const char *api_plural_g(double n, int digits, const char *one, const char *many);
/* A refusal of a body nested in member ("session": a create body within
 * an experiment's): its field named by the path the client sent,
 * "member.field", unless it has none or is named so already (a field too
 * long for the room is left as it was). */
void api_field_within(api_problem *pb, const char *member);
/* Copy the id text of field (a session's or a fit's: what names it in
 * the detail) into buf of size bytes, or refuse a length outside 1 to
 * size - 1 bytes with that range (api_fail_range): an id longer than the
 * buffer is refused, not cut to another one's. */
api_err api_copy_id(api_problem *pb, const char *field, const char *what,
		    const char *text, char *buf, size_t size);
/* A value of field that is none of choices ("cw|ccw": a setting's
 * choices, or those of them the request takes): api_fail with code
 * (API_RANGE; API_TYPE for a value of another JSON type) and those
 * choices, the problem's choices member; the one way a refusal states
 * choices its field's path does not give from the settings table.
 * Returns code. */
api_err api_fail_choices(api_problem *pb, api_err code, const char *field, const char *choices,
			 const char *fmt, ...) __attribute__((format(printf, 5, 6)));
/* The choices of the enum setting name whose values are in mask (bit v for
 * the value v), joined by "|" into out (n bytes): the ones a request
 * takes where it takes fewer than the setting has. "" for a name that is
 * no enum setting. Returns out. */
const char *api_choices_of(const char *name, unsigned mask, char *out, size_t n);
/* Name the budget that refused a request (copied) and its limit, with the
 * Retry-After seconds; returns pb->code. */
api_err api_budget(api_problem *pb, const char *budget, double limit, int retry_after);
/* The RFC 9457 body for *pb (type, title, status, detail, instance and the
 * extensions field/position/min/max/choices/budget/limit). instance (borrowed) may be NULL.
 * Returns malloc'd text, NULL only when out of memory. */
char *api_problem_json(const api_problem *pb, const char *instance);

/* Shortest text of v that parses back to v; "null" if not finite. Returns
 * the length written (buf of at least 32 bytes). */
int api_fmt_double(char *buf, size_t len, double v);

/* A time in s as answers print it (core/table.h's sim_time_ns: a time on
 * a step or sample grid reads as k dt, 16.016 and not 16.016000000000002),
 * as api_fmt_double. */
int api_fmt_time(char *buf, size_t len, double t);

/* ---- values in user units ------------------------------------------------ */

/* A setting's value as a request gave it in the settings table's user unit
 * (beta in deg, beta_rate in deg/s), converted to SI once, where api/
 * parsed it: si goes to the core, user is what answers echo. */
typedef struct api_value {
	double si;
	double user;
} api_value;

/* ---- sessions ----------------------------------------------------------- */

#define API_PACE_MAX 0.0         /* pace value meaning "as fast as possible" */
#define API_PACE_MIN 0.001       /* the least real-time factor a request may set */
#define API_CPU_BUDGET_MIN 0.001 /* CPU s: the least grant a PATCH may set */
#define API_DEFAULT_MAX_UNTIL 60.0 /* s: "until" for pace "max" if none given */
#define API_DEFAULT_SAMPLE_RATE 250.0
#define API_SAMPLE_RATE_MAX 10000.0 /* 1/s: the most samples a simulated second */

/* A session as created: preset, settings, pace, optional end time. */
typedef struct api_spec {
	char preset[32];
	sim_params params;
	sim_scene scene;
	sim_method method;
	double pace;        /* real-time factor, API_PACE_MAX for "max" */
	double until;       /* s simulated end time, 0 = none */
	double sample_rate; /* samples recorded per simulated second */
} api_spec;

/* Parse a POST /sessions body (len bytes, need not be NUL-terminated; an
 * empty or blank body is refused, {} takes every default). Fills *spec from the preset and overrides, checks
 * every value with sim_set/sim_validate. Returns API_OK or the error in
 * *pb; *spec is then unspecified. */
api_err api_parse_session(const char *body, size_t len, api_spec *spec,
			  api_problem *pb);

/* A session's spec as stored (sessions/ID/spec.json): its format
 * ("format": API_SPEC_FILE_FORMAT), its creation time (unix s), whether an
 * experiment owns it, and the create body that makes it again ("session":
 * preset, pace, until, sample_rate and every setting by group), the API's
 * own JSON, so that another build reads it. malloc'd text, NULL when out
 * of memory. api_parse_spec_file reads it back through api_parse_session
 * (400/422 as a POST would be), with its format in *format (1: a file
 * without the member, as builds before format 2 wrote it); a format above
 * API_SPEC_FILE_FORMAT (a newer build's) is refused. A session that asked
 * for feed_model auto also keeps its pick ("feed_model_pick", as the
 * status shows it; pick NULL: none), read back into *pick with *picked 1
 * (0 where the file has none or one this build cannot read; a build
 * before it ignores the member). */
#define API_SPEC_FILE_FORMAT 3
char *api_spec_file(const api_spec *spec, double created, int owned,
		    const sim_feed_choice *pick);
api_err api_parse_spec_file(const char *text, size_t len, api_spec *spec,
			    double *created, int *owned, int *format, sim_feed_choice *pick,
			    int *picked, api_problem *pb);
/* Check a spec that did not come from api_parse_session (a file read
 * back): its strings are terminated, the preset known, pace, until and
 * sample_rate within the ranges the parser allows, every setting within
 * its range, and the set passes sim_validate. API_OK or the problem (nothing is changed). */
api_err api_check_spec(const api_spec *spec, api_problem *pb);
/* api_check_spec of the model alone (preset, settings, the set valid),
 * not pace, until and sample_rate: a stored sweep's or experiment's, which
 * are not sessions' settings there. */
api_err api_check_model(const api_spec *spec, api_problem *pb);

/* The controls of PATCH /sessions/{id}, one row each, in the order they
 * are parsed, echoed in the control event and listed in messages and the
 * OpenAPI document: X(ID, member, API_C_ID bit, function suffix). The
 * rest of each row is api/control.c's (parse, echo) and
 * server/session/worker_control.c's (apply), both indexed by API_CTL_ID.
 * m_n and mu are disturbances of a column feed (sim_set_feed); whatever
 * sends a control (a PATCH, the control log's replay, an experiment's
 * schedule) parses it with api_parse_control against the session's spec. */
#define API_CONTROLS(X)                                                                    \
	X(BETA, "beta", 1u << 0, beta)                                                      \
	X(BETA_RATE, "beta_rate", 1u << 1, beta_rate)                                       \
	X(ROTATION, "rotation", 1u << 2, rotation)                                          \
	X(OMEGA_SS, "omega_ss", 1u << 3, omega_ss)                                          \
	X(M_N, "m_n", 1u << 9, m_n)                                                         \
	X(MU, "mu", 1u << 10, mu)                                                           \
	X(RUNNING, "running", 1u << 4, running)                                             \
	X(MOTOR, "motor_on", 1u << 7, motor)                                                \
	X(PACE, "pace", 1u << 5, pace)                                                      \
	X(UNTIL, "until", 1u << 6, until)                                                   \
	X(CPU, "cpu_budget", 1u << 8, cpu)
#define API_C_BIT_(id, member, bit, fn) API_C_##id = bit,
enum { API_CONTROLS(API_C_BIT_) }; /* the bits of api_control.set */
#undef API_C_BIT_
#define API_CTL_ID_(id, member, bit, fn) API_CTL_##id,
typedef enum { API_CONTROLS(API_CTL_ID_) API_CTL_COUNT } api_control_id;
#undef API_CTL_ID_
typedef struct api_control {
	unsigned set;
	api_value beta;      /* rad (deg as sent) */
	api_value beta_rate; /* rad/s (deg/s as sent) */
	int rotation;     /* SIM_CW / SIM_CCW */
	double omega_ss;  /* rad/s */
	double m_n;       /* kg: the column feed's element mass (a disturbance) */
	double mu;        /* the column feed's friction coefficient (one too) */
	int running;
	int motor_on;     /* drive switched on (motor or ideal drive) */
	double pace;      /* API_PACE_MAX for "max" */
	double until;     /* s, 0 = none */
	double cpu_budget; /* CPU s granted from now (the server checks the
			      upper bound, --max-cpu-seconds) */
} api_control;

/* Parse one line of a session's control log (api_control_log_line: a
 * PATCH body with t_effective, and the experiment that sent it) back into
 * *c, *t_effective (s) and experiment (explen bytes, "" when a client
 * sent it; may be NULL), checked as api_parse_control checks a PATCH. */
api_err api_parse_control_event(const char *line, size_t len, const api_spec *spec,
				api_control *c, double *t_effective, char *experiment,
				size_t explen, api_problem *pb);
/* Parse a PATCH body against the session's spec (ranges from the settings
 * table). All or nothing: on error *c is unspecified and nothing is to be
 * applied. An empty object is a 422. */
api_err api_parse_control(const char *body, size_t len, const api_spec *spec,
			  api_control *c, api_problem *pb);
/* The control as a stream event payload, a JSON object with t_effective
 * (s); written into buf, returns the length (truncated text if too
 * small). */
int api_control_event(char *buf, size_t len, const api_control *c,
		      double t_effective);
/* The same with the scene's model error after the control (me, borrowed:
 * model_error, model_error_uncertainty, model_checked, model_check_note),
 * the stream's form of the event; the control log keeps api_control_event's. */
int api_control_event_model(char *buf, size_t len, const api_control *c,
			    double t_effective, const sim_model_error *me);
/* The model error of a session's scene now (sim_model_check): the spec's
 * settings with the status's controls (beta_target, rotation, omega_ss,
 * m_n, mu)
 * when st is not NULL. Returns sim_model_check's value. */
int api_model_check(const api_spec *spec, const sim_status *st, sim_model_error *me);
/* The control as a line of the session's control log: the stream event's
 * object, and "experiment": its id when an experiment's segment sent it
 * (experiment may be NULL), so that a restore that resumes the
 * experiment leaves its commands to it. Returns the length as above. */
int api_control_log_line(char *buf, size_t len, const api_control *c, double t_effective,
			 const char *experiment);

/* Everything GET /sessions/{id} shows, filled by the server. */
/* A LIGGGHTS session's bed (feed_model liggghts, docs/dem.md): it runs in
 * a child process of the daemon; scaled to the scene's feed. */
typedef struct api_bed {
	int grains;
	long pid;              /* the bed process, 0 once it ended */
	double interval;       /* s: the coupling interval */
	long intervals;        /* coupling intervals since t = 0 */
	double displacement;   /* m: the grains' mean x since the bed began */
	double velocity;       /* m/s: their mean velocity relative to the deck */
	double cpu_seconds;    /* the bed process's CPU time, s */
	double weight, load_mean_y;          /* N */
	double work_machine, work_bed, bed_energy; /* J since the bed began */
	int resettled;         /* restored: the machine from its checkpoint,
				  the bed settled anew from its seed */
} api_bed;

typedef struct api_view {
	char id[24];
	const api_spec *spec;  /* borrowed */
	const char *state;     /* running, paused, finished, failed */
	char error[256];
	double pace, until;    /* current values */
	double created;        /* unix time, s */
	int has_status;
	sim_status st;
	double steps_per_s, rtf; /* achieved over the last wall second */
	uint64_t samples;      /* samples recorded so far */
	int streams;           /* open stream clients */
	int columns, layers;
	char experiment[24];   /* running experiment id or "" */
	double cpu_seconds;    /* worker CPU time used, s */
	double cpu_limit;      /* CPU time at which it pauses, s */
	const char *pause_reason; /* "client", "cpu-budget" or NULL */
	int waiting_for_cpu;   /* pace "max" waiting for a CPU slot */
	int replayed;          /* re-created from its spec at the last start
				  (its checkpoint unusable), its control log
				  replayed: "restored": "replayed" */
	double replay_seconds; /* wall s the replay took; NAN while it runs */
	int has_bed;           /* feed_model liggghts: bed is its bed */
	const sim_feed_choice *pick; /* feed_model auto's pick, or NULL */
	api_bed bed;
} api_view;

/* Session as JSON; with_spec adds the full settings. malloc'd text. */
char *api_session_json(const api_view *v, int with_spec);
/* {"sessions": [...]} of n views (no spec). malloc'd text. */
char *api_session_list_json(const api_view *v, size_t n);
/* n sessions' summaries as CSV, one row each: id, state, the trajectory's
 * named columns at the session's time, then steady, transport_periods and
 * the means over whole periods. malloc'd text. */
char *api_session_csv(const api_view *v, size_t n);
/* PATCH answer: the session plus "applied" (the changes), "t_effective"
 * (s, null if the worker did not acknowledge in time). malloc'd text. */
char *api_control_result_json(const api_view *v, const api_control *c,
			      int acked, double t_effective);

/* ---- streams ------------------------------------------------------------ */

enum {
	API_F_TROUGH = 1 << 0,
	API_F_ORBIT = 1 << 1,
	API_F_ROTOR = 1 << 2,
	API_F_ELIMINATORS = 1 << 3,
	API_F_FEED = 1 << 4,
	API_F_ENERGY = 1 << 5,
	API_F_ELEMENTS = 1 << 6,
	API_F_DEFAULT = API_F_TROUGH | API_F_ORBIT | API_F_ROTOR |
			API_F_ELIMINATORS | API_F_FEED,
	API_F_ALL = API_F_DEFAULT | API_F_ENERGY | API_F_ELEMENTS,
};
/* Parse a comma list of field groups ("trough,feed" or "all"). Returns the
 * mask, or 0 and *pb (API_QUERY) on an unknown name. */
unsigned api_parse_fields(const char *list, api_problem *pb);

enum { API_REC_SAMPLE = 0, API_REC_EVENT = 1 };
#define API_EVENT_MAX 512
/* One stream record. Arrays are owned by whoever made the record (the
 * server's ring), sized for columns and columns*layers. */
typedef struct api_sample {
	uint64_t index;      /* sequence number in the session: the SSE id */
	int kind;            /* API_REC_SAMPLE or API_REC_EVENT */
	sim_status st;       /* API_REC_SAMPLE */
	int columns, layers; /* 0 when the scene has no feed */
	double *column_disp; /* columns entries */
	double *xi, *eta;    /* columns*layers entries each */
	char event_type[16]; /* API_REC_EVENT: "control", "finished", ... */
	char event[API_EVENT_MAX]; /* API_REC_EVENT: JSON object text */
} api_sample;

/* Largest text api_format_record can write for this feed size. */
size_t api_record_max(int columns, int layers);
/* Numbers api_format_record writes in a sample of these field groups
 * (API_F_*) for this feed size (0 x 0 without feed): what a stream's
 * record costs to format (the daemon's stream budget). */
int api_record_numbers(unsigned fields, int columns, int layers);
/* Write one record as SSE ("id:", "event:", "data:") or as one NDJSON
 * line with "type" and "id". buf holds api_record_max() bytes. Returns the
 * length. Doubles round-trip. */
size_t api_format_record(char *buf, size_t len, const api_sample *s,
			 unsigned fields, int ndjson);
/* The stream's first record: the session, the id the next record will
 * have, the scene's feed_warning (the model check's note where the scene's
 * column model is not checked against DEM; NULL for none, written as null)
 * and, with me (borrowed, may be NULL), its model error as the status
 * gives it, so that a client that only streams knows it. Returns the
 * length (0 if it does not fit). */
size_t api_format_hello(char *buf, size_t len, const char *session, uint64_t next_id,
			const char *feed_warning, const sim_model_error *me, int ndjson);
/* Stream notices: missed samples, heartbeat, end (reason: finished,
 * deleted, failed, shutdown, limit). Return the length. */
size_t api_format_dropped(char *buf, size_t len, uint64_t missed,
			  uint64_t next_id, int ndjson);
size_t api_format_heartbeat(char *buf, size_t len, double t, int ndjson);
size_t api_format_end(char *buf, size_t len, const char *reason, int ndjson);

/* ---- trajectory --------------------------------------------------------- */

/* A trajectory row: the named columns of core/table.h (SIM_TRAJECTORY_COLUMNS,
 * column 0 is t) then column_1 ... column_K, the per-column feed
 * displacement; API_HISTORY_WIDTH(K) doubles. The CLI writes the same. */
#define API_HISTORY_WIDTH(columns) ((size_t)SIM_TRAJECTORY_NAMED + (size_t)(columns))
/* One trajectory row from a status and the K per-column displacements
 * (borrowed; may be NULL when columns is 0). */
void api_history_row(const sim_status *st, const double *column_disp, int columns,
		     double *row);
/* n rows of API_HISTORY_WIDTH(columns) (borrowed) as JSON
 * {"fields","units","count","stride","rows"} or as CSV with a header line.
 * stride: the rows' spacing, s. malloc'd text. */
char *api_trajectory_json(const double *rows, size_t n, int columns, double stride);
char *api_trajectory_csv(const double *rows, size_t n, int columns);

/* ---- catalogue ------------------------------------------------------------- */

/* {"presets": [{name, params, scene, integrator}], "settings": [...],
 * "methods": [...]}. malloc'd text. */
char *api_presets_json(void);
/* GET /api/v1/health. */
typedef struct api_health {
	const char *status;   /* "ok" or "stopping" */
	double uptime;        /* s */
	int sessions, max_sessions;
	int stream_clients, max_streams;
	int pool_threads, pool_queued;
} api_health;
char *api_health_json(const api_health *h);
/* The OpenAPI 3.1 document of the HTTP API. malloc'd text. */
char *api_openapi_json(void);

/* experiments, sweeps, fits and the listings across replicas */
#include "api_jobs.h"

#endif
