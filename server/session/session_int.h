/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_int.h - the inside of a session, shared by session.c (registry,
 * lifetime, readers) and worker.c (the thread that steps the core).
 */
#ifndef CONVSIM_SESSION_INT_H
#define CONVSIM_SESSION_INT_H

#include <math.h>
#include <pthread.h>

#include "budget.h"
#include "budget_turns.h"
#include "records.h"
#include "registry.h"
#include "session.h"
#include "worker.h"

/* A control of the log to apply again once the integrator reaches at. */
typedef struct srv_replay {
	srv_cmd cmd;
	double at;   /* its t_effective, s */
	int exp_own; /* sent by the experiment the checkpoint resumed: not
			applied here, the experiment sends it again itself */
	char exp[SRV_ID_LEN]; /* the experiment that sent it, or "" */
} srv_replay;

/* A slot of the record ring: a sample's or event's status; its feed
 * arrays are in the ring's store, an event's text in its events, at the
 * same place. */
typedef struct srv_slot {
	uint64_t index;
	int kind;                 /* API_REC_SAMPLE or API_REC_EVENT */
	sim_status st;
} srv_slot;
typedef struct srv_slot_event {
	char type[16];            /* api_sample's event_type */
	char json[API_EVENT_MAX]; /* api_sample's event */
} srv_slot_event;

/* A session's record ring and trajectory history (ring.c: their memory,
 * the worker's writers and the readers), guarded by the session lock. */
typedef struct srv_session_records {
	srv_slot *slots;
	double *store;            /* the slots' feed arrays, cap of them */
	size_t cap, bytes;        /* slots' and store's mapping: bytes */
	srv_slot_event *events;   /* cap of them, a mapping of ev_bytes whose
				     pages are made only where an event is
				     written */
	size_t ev_bytes;
	uint64_t head;
	uint64_t event_head;      /* head after the newest event record */
	uint64_t published;       /* head when readers were last woken */
	double wake_t;            /* s: the earliest sample time a waiting
				     stream wants (INFINITY: none waits) */
	double plan_t;            /* s: the simulated time a paced worker
				     sleeps until (INFINITY: it does not);
				     a stream that wants an earlier sample
				     wakes it (worker.c pace) */
	double *hist;
	size_t hist_cap, hist_n;
	double hist_stride, hist_next;
} srv_session_records;

/* The control log on disk (control_log.c), guarded by the session lock. */
typedef struct srv_control_log {
	pthread_cond_t cond;      /* a sync round ended */
	int fd;                   /* -1 until its first sync opens it */
	size_t synced;            /* bytes of controls on disk, synced */
	int syncing;              /* a thread leads a sync round */
	int flush_queued;         /* a flush of lines nobody waits for is
				     queued on the store's writer */
} srv_control_log;

/* A LIGGGHTS session's bed (session_dem.c). */
typedef struct srv_session_dem {
	struct dem_coupled *link; /* worker only (created before it starts,
				     freed after it ends): the coupling to the
				     bed process; NULL for the column model */
	int slot;                 /* holds one of --max-dem-sessions */
	double cores;             /* cores its bed process holds (--dem-ranks) */
	int restart;              /* worker only: a control changed the machine;
				     the bed's transport estimate restarts once
				     its beta ramp is over */
	api_bed bed;              /* what the worker last read of it (lock) */
} srv_session_dem;

/* A restored session's replay of the controls logged after its checkpoint:
 * session_load.c fills it at the restore; the worker (worker.c) applies
 * the controls and ends the catch-up; guarded by the session's lock. */
typedef struct srv_session_restore {
	srv_replay *replay;       /* controls logged after the checkpoint it
				     was restored from, in order: applied
				     again as the integrator reaches each
				     (session_load.c loads, worker.c runs) */
	size_t nreplay, replayed;
	size_t exp_relogged;      /* lines of the resumed experiment in the
				     log after its checkpoint: its commands
				     that many times are not logged again */
	int rebuilt;              /* re-created from its spec, its checkpoint
				     unusable (another build): the whole log
				     is replayed */
	double catch_up_t;        /* restored with controls to replay: runs
				     flat out until its time reaches where
				     it was (0: not; then it answers) */
	double replay_wall, replay_seconds; /* when the replay began, how
				     long it took (NAN until over) */
	int upgrade;              /* restore: a file of an earlier format
				     (store.h), written again in this one */
	double replay_t0;         /* s: the time it was restored at */
	int exp_after_catch_up;   /* its experiment, attached again at the
				     restore, begins once it is back where
				     it was (srv_session_readopt) */
	double cpu_seconds;       /* CPU s its checkpoint counted (NAN: it
				     kept none: format 2, or no checkpoint) */
	double cpu_limit;         /* CPU s: the count its checkpoint would
				     pause it at */
	double cpu_grant;         /* CPU s: without a count kept, the last
				     grant of the controls its checkpoint
				     holds (0: none), from 0 again */
	int cpu_paused;           /* restored paused by its CPU budget: its
				     checkpoint says so, or without one that
				     kept it, its client's last running was
				     not false (srv_restore_budget) */
} srv_session_restore;

/* What a session holds of the daemon's budgets (budget.c keeps the
 * totals) and the CPU it measures: worker.c owns it (its CPU clock, the
 * cost measure, the hold on the paced cores, its CPU turn at pace max);
 * session.c only takes the memory at creation and gives all back at the
 * end. Guarded by the session's lock but for turn (worker only). */
typedef struct srv_session_budget {
	size_t mem_reserved;      /* bytes of the memory budget it holds */
	srv_cpu_turn turn;        /* worker only: its CPU turn at pace max */
	int waiting_for_cpu;      /* its turn has not come */
	double cpu_seconds;       /* the CPU it spent, s: its worker's CPU
				     time on cpu_base */
	double cpu_base;          /* CPU s it had spent when its worker
				     started (its checkpoint's, restored) */
	double cpu_limit;         /* pauses when cpu_seconds reaches it */
	int cpu_paused;           /* paused because cpu_limit was reached */
	double cpu_per_s;         /* CPU s per simulated s: estimated at
				     creation, then measured by the worker */
	int cpu_measured;         /* cpu_per_s is the worker's measure */
	double paced_held;        /* cores of the paced budget it holds */
	int settling;             /* holds a --max-settling slot (creation) */
	srv_stream_charge *streams; /* its open streams' charges, linked
				       (budget_stream.c): held with its
				       own while it runs paced */
} srv_session_budget;

/* The state of a session's files: session_store.c owns it (writes the
 * checkpoints and the spec, keeps the last failure); the worker and the
 * control handlers only mark a change (ckpt_dirty) and the control log
 * reports its failures into store_error. Guarded by the session's lock. */
typedef struct srv_session_persist {
	double ckpt_wall;         /* srv_now() of the last checkpoint */
	int ckpt_dirty;           /* a control or state change since */
	char store_error[256];    /* the last failed write, "" */
	int spec_unwritten;       /* spec.json failed to be written: the
				     session stays "error" until a rewrite
				     (queued at the next write that works)
				     is on disk */
	int spec_retrying;        /* that rewrite is queued */
} srv_session_persist;

struct srv_session {
	srv_entry entry;          /* id and references: the registry */
	api_spec spec;            /* immutable */
	double created;
	int columns, layers;      /* feed size, 0 without feed */
	sim *sim;                 /* worker only */
	pthread_t worker;
	int worker_started;
	int first_applied;        /* its worker has applied what was due at its
				     start (the controls logged after a restored
				     checkpoint): srv_sessions_start_restored
				     waits for it (lock) */
	api_sample scratch;       /* worker only */

	pthread_mutex_t lock;
	pthread_cond_t wake;      /* worker: commands, stop */
	pthread_cond_t data;      /* streams and waiting handlers */
	/* guarded by lock */
	int stop;
	int state;
	char error[256];
	double pace, until;
	srv_cmd *cmd_head, *cmd_tail;
	sim_status st;
	double steps_per_s, rtf;
	srv_session_records ring; /* records and history (ring.c) */
	int streams;
	srv_experiment *exp;
	srv_cmd *exp_cmd;         /* the experiment's command while queued */
	int exp_started;
	/* lifetime and persistence (session_store.c) */
	int damaged;              /* restored without a usable spec or
				     checkpoint: listed, failed, no worker */
	int owned;                /* created by an experiment that does not
				     keep it: removed when it ends */
	int expire;               /* remove at the next reap */
	double last_access;       /* srv_now() of the last request */
	char *controls;           /* every acknowledged control, one JSON
				     line each (controls.ndjson) */
	size_t controls_len, controls_cap;
	srv_control_log log;      /* the log on disk (control_log.c), lock */
	srv_session_persist persist; /* its files' state (session_store.c) */
	srv_session_restore restore; /* a restored session's replay (session_load.c) */
	srv_session_budget budget; /* what it holds of the budgets (worker.c) */
	srv_session_dem dem;      /* a LIGGGHTS session (session_dem.c) */
	sim_feed_choice pick;     /* feed_model auto's pick (srv_dem_pick) */
	int picked;               /* 1: auto was asked and pick holds it */
	int create_fd;            /* while created: the client's socket or -1
				     (a bed's settling ends when it leaves) */
};

/* ---- session_control.c: a control's admission and wait -------------------- */

/* cfg (borrowed for the daemon's life) gives --max-cpu-seconds. */
void srv_session_control_init(const srv_config *cfg);

/* Whether an until of `until` s (> 0) would end s before the end of its
 * experiment, begun (lock held): admission refuses it, and so does the
 * worker where the experiment began after the control was admitted (an
 * experiment attached but still waiting has no end yet). */
int srv_until_cuts_experiment(const srv_session *s, double until);

/* ---- session_dem.c: a LIGGGHTS session's bed process ------------------ */

/* Find the bed program (--dem-bed, or convsim-bed next to the daemon). */
void srv_dem_init(const srv_config *cfg);
/* The spec asks for a LIGGGHTS bed (feed on, feed_model liggghts). */
int srv_dem_wanted(const api_spec *spec);
/* Admit a LIGGGHTS session: the bed program exists (else 422 on
 * scene.feed_model), a fixed-step method (a dt of 0 becomes the CLI's
 * coupled step; else 422 on integrator.method), one of --max-dem-sessions
 * taken (else 429): give it back with srv_dem_release. */
api_err srv_dem_admit(api_spec *spec, api_problem *pb);
/* feed_model auto (sim_feed_pick, docs/feed-models.md "feed_model=auto"):
 * the spec's feed model becomes the pick, which s->pick says (s->picked
 * 1, logged), a LIGGGHTS bed offered where its program exists and its
 * expected cost is within --max-dem-cost; none fits: 422 on
 * scene.model_tol with the why. */
api_err srv_dem_pick(srv_session *s, api_spec *spec, api_problem *pb);
/* A restored session's slot, taken even beyond the limit; and giving one
 * back. */
void srv_dem_hold(void);
void srv_dem_release(void);
/* Start s's bed process and couple it to s->sim (at t = 0, or at a
 * restored machine's time: restored = 1, the bed settled anew); s->st and
 * s->dem.bed show it. 0, or -1 with msg, or 1 when the creating client
 * (s->create_fd) left while the bed settled; either way the bed process
 * is ended and reaped and s->dem.link stays NULL. */
int srv_dem_start(srv_session *s, int restored, char *msg, size_t msglen);
/* Worker, lock released: advance machine and bed to the end of the
 * coupling interval at or after t_next (s). 0, or -1 with msg (the bed
 * process ended or failed, the machine froze). */
int srv_dem_step(srv_session *s, double t_next, char *msg, size_t msglen);
/* Worker, lock released: a control changed the machine (restart = 1):
 * once beta has reached its target (status st), the bed's transport
 * estimate restarts, as the core's does. */
void srv_dem_controlled(srv_session *s, const sim_status *st);
/* Worker: the bed's figures into a status of the machine (transport
 * velocity, feed displacement and velocity) and into *b. */
void srv_dem_read(const srv_session *s, sim_status *st, api_bed *b);
/* End the bed process now (any thread: a worker inside an advance then
 * fails and sees its stop). */
void srv_dem_kill(srv_session *s);
/* Free the coupling, ending and reaping the bed process. */
void srv_dem_free(srv_session *s);

/* CPU s per simulated s a session is charged in the paced budget at
 * pace: its worker's and its open streams' (lock held). */
static inline double srv_paced_cost(const srv_session *s, double pace)
{
	return s->budget.cpu_per_s + srv_budget_streams_cpu(s->budget.streams, pace);
}

/* srv_paced_cost as the paced budget takes it (budget.h srv_pace_cost). */
static inline double srv_paced_cost_of(const void *s, double pace)
{
	return srv_paced_cost(s, pace);
}

/* Cores a session needs from the paced budget as it is now: its CPU s per
 * simulated s and its streams' times its pace while it runs paced (at
 * least its bed process's cores for a LIGGGHTS session), else none (lock
 * held). */
static inline double srv_paced_need(const srv_session *s)
{
	if (s->state != SRV_RUNNING || s->pace == API_PACE_MAX || s->stop)
		return 0;
	double need = srv_paced_cost(s, s->pace) * s->pace;
	/* a LIGGGHTS session's bed process holds its cores */
	return s->dem.link && need < s->dem.cores ? s->dem.cores : need;
}

/* The state control c leaves a session in, from its state, whether its
 * CPU budget paused it and its time t: until raised past t resumes a
 * finished session, running pauses or resumes, and a new CPU budget (or
 * running = true) resumes one its budget paused. The one rule for the
 * worker, which applies c (worker.c apply_commands), and for admission,
 * which must know beforehand whether the session will run paced
 * (session.c admit_control). */
static inline int srv_state_after(int state, int cpu_paused, double t, const api_control *c)
{
	if ((c->set & API_C_UNTIL) && state == SRV_FINISHED && (c->until == 0 || c->until > t))
		state = SRV_RUNNING;
	if ((c->set & API_C_RUNNING) && !c->running && state == SRV_RUNNING)
		state = SRV_PAUSED;
	else if ((c->set & API_C_RUNNING) && c->running && state == SRV_PAUSED)
		state = SRV_RUNNING;
	if (((c->set & API_C_CPU) || ((c->set & API_C_RUNNING) && c->running)) && cpu_paused &&
	    state == SRV_PAUSED)
		state = SRV_RUNNING;
	return state;
}

/* The feed arrays of slot i (column displacements, then xi, then eta). */
static inline double *srv_ring_feed(const srv_session *s, size_t i)
{
	size_t per = (size_t)s->columns +
		     2 * (size_t)s->columns * (size_t)s->layers;
	return s->ring.store + i * per;
}

/* ---- ring.c: the ring's memory ------------------------------------------ */

/* Allocate s's record ring (ring records, at least 16, its slots' pages
 * made now) and trajectory history (history rows) for its feed's size,
 * and the history's stride from its sample rate; 0, or -1 out of memory
 * (srv_ring_free frees what was made). */
int srv_ring_alloc(srv_session *s, int ring, int history);
void srv_ring_free(srv_session *s);

/* ---- ring.c: the worker's writers (session lock held) ----------------- */

/* Push an event record: type ("control", "finished", ...) and its JSON. */
void srv_ring_event(srv_session *s, const char *type, const char *json);
/* Push an event {"t": now, detail...}; detail (may be NULL) is more JSON
 * members. */
void srv_ring_event_at(srv_session *s, const char *type, const char *detail);
/* Push a sample of the published status and the scratch feed arrays, and
 * a trajectory row when one is due. */
void srv_ring_sample(srv_session *s);
/* Copy the feed arrays out of the instance into the scratch record
 * (worker; no lock needed). */
void srv_ring_gather(srv_session *s);

/* ---- session_store.c, session_load.c: the session's files (store.h) --- */

/* Write the spec files: spec.json now, on this thread (now: a creation,
 * before its worker runs; its answer follows it, and a failure puts it in
 * store_error), or queued (an upgrade, a rewrite after a failure); then
 * spec.bin queued. */
void srv_persist_spec(srv_session *s, int now);

/* ---- control_log.c: the control log on disk ----------------------------- */

/* How a line appended to the control log reaches the disk: a flush
 * queued on the store's writer; a handler that waits for it makes it
 * durable before it answers; or with the next sync that comes (a PATCH's,
 * a checkpoint's, a flush's: the file stays a prefix of the log), for a
 * line whose control is sent again after a restore (a closed loop's
 * per-period beta). */
enum { SRV_LINE_FLUSH, SRV_LINE_WAITED, SRV_LINE_LATER };
/* Append a control's event line to s's log in memory (worker, lock held):
 * the log's length with it, for srv_control_log_sync (0 without a data
 * directory); durable: SRV_LINE_*. */
size_t srv_control_log_append(srv_session *s, const char *json, int durable);
/* Make s's log durable up to end bytes (lock not held): by group commit,
 * one pwrite and one fdatasync for every line appended before the round
 * began. 0, or an errno (ETIMEDOUT after timeout_s, the write's failure,
 * also shown in store_error). */
int srv_control_log_sync(srv_session *s, size_t end, double timeout_s);
/* Close the log's file (the session is freed). */
void srv_control_log_close(srv_session *s);
/* Queue a checkpoint now if one is due: the interval has passed, or the
 * session stopped running with changes since the last one (worker, lock
 * held, after the commands phase). */
void srv_persist_checkpoint(srv_session *s, int force);
/* Queue the removal of the session's files. */
void srv_persist_remove(const srv_session *s);
/* The path of a session's file in the data directory, "sessions/ID/FILE"
 * (file NULL: its directory), shared by session_store.c and
 * session_load.c. */
void srv_session_file(char *out, size_t len, const char *id, const char *file);

/* An experiment no checkpoint of s carried but whose record names s
 * (ef->readopt), attached again from its first segment at the restore,
 * before the worker starts (session_control.c): see docs/operations.md
 * "What a crash can lose". */
void srv_session_readopt(srv_session *s, const srv_exp_finder *ef);
/* Build session id from its files into s (calloc'd, lock initialised;
 * session_load.c):
 * spec, checkpoint (or the previous one, or a fresh start from the spec),
 * the experiment it ran resumed; s->damaged with the reason in s->error
 * when they do not pass their checks. */
void srv_persist_load(srv_session *s, const char *id, const srv_exp_finder *ef);
/* The CPU budget s goes on with after its restore (srv_session_adopt;
 * session_load.c), with at most max_cpu (--max-cpu-seconds) left of its
 * grant: the count and limit its checkpoint kept, else a count from 0
 * with the grant of the controls its checkpoint holds; a running: true
 * replayed from its log grants max_cpu from the count, as when it was
 * acknowledged. */
void srv_restore_budget(srv_session *s, double max_cpu);

/* checkpoint.bin's head and trailer: srv_ckpt_record, srv_ckpt_trailer
 * (records.h, with every stored layout). */
/* The files read back, checked without touching a session (the restore
 * uses these; so does the fuzz harness tests/fuzz/fuzz_store.c). A spec
 * file's payload (len bytes, borrowed): 0 with the spec, its creation
 * time and whether an experiment owns it, or -1 with why (another size, a
 * spec the API would refuse: api_check_spec). A checkpoint file's payload:
 * 0 with its head in *r (strings terminated; the experiment's state and
 * the core's checkpoint follow it in p), or -1 with why (cut off,
 * inconsistent lengths, an unknown run state). */
int srv_spec_decode(const void *p, size_t len, api_spec *spec, double *created,
		    int *owned, char *why, size_t whylen);
int srv_ckpt_decode(const char *p, size_t len, srv_ckpt_record *r, char *why,
		    size_t whylen);

/* The registry of sessions (session_list.c; session.c sets its destroy). */
extern srv_registry srv_sessions_registry;

/* session.c: publish a session built by session_load.c: s has its
 * registry id set in s->entry.id, spec, sim (NULL when damaged), state;
 * buffers are allocated here. 0 or -1 (s freed). Its worker starts with
 * srv_sessions_start_restored, once every session is in. */
int srv_session_adopt(srv_session *s);
/* Start the workers of the adopted sessions. Returns how many. */
size_t srv_sessions_start_restored(void);


#endif
