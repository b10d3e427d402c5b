/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session.c - sessions: lifetime (create, restore, delete, reap), the
 * control entry point and attaching an experiment. The registry of
 * sessions and what reads it are session_list.c; their files are
 * session_store.c and session_load.c, which this file calls and which
 * never call back.
 *
 * Sessions live in a registry (registry.c) and are reference counted: the
 * registry, each handler while it works and each stream hold one. Handlers
 * never call the core: controls go through the worker's command queue
 * (worker.c) and wait for its acknowledgement; everything else is read
 * from what the worker publishes under the session lock, which never
 * leaves this file and worker.c. Lock order: see registry.h.
 */
#include <errno.h>
#include <malloc.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cpu_probe.h"
#include "experiment.h"
#include "metrics.h"
#include "session_int.h"
#include "store.h"
#include "util.h"

static void destroy(srv_entry *en);
#define sessions srv_sessions_registry /* session_list.c's */
static const srv_config *cfg;

void srv_sessions_init(const srv_config *config)
{
	cfg = config;
	srv_dem_init(config);
	srv_session_control_init(config);
	sessions.destroy = destroy;
	srv_registry_open(&sessions, (size_t)cfg->max_sessions);
}

/* ---- lifetime ---------------------------------------------------------- */

/* The lock and conditions of a session fresh from calloc, and its control
 * log not open yet. */
static void session_locks_init(srv_session *s)
{
	pthread_mutex_init(&s->lock, NULL);
	pthread_cond_init(&s->wake, NULL);
	pthread_cond_init(&s->data, NULL);
	pthread_cond_init(&s->log.cond, NULL);
	s->log.fd = -1;
}

static void session_free(srv_session *s)
{
	if (!s)
		return;
	int buffers = s->sim || s->ring.hist;
	srv_dem_free(s); /* the bed process ends before its machine */
	if (s->dem.slot)
		srv_dem_release();
	sim_free(s->sim);
	srv_budget_give(s->budget.mem_reserved);
	srv_budget_set_paced(&s->budget.paced_held, 0);
	srv_sample_free(&s->scratch);
	srv_ring_free(s);
	srv_control_log_close(s);
	free(s->controls);
	free(s->restore.replay);
	pthread_cond_destroy(&s->log.cond);
	pthread_mutex_destroy(&s->lock);
	pthread_cond_destroy(&s->wake);
	pthread_cond_destroy(&s->data);
	free(s);
	/* a session's buffers are megabytes: give the pages back to the
	 * system rather than keep them in the allocator (glibc); a creation
	 * refused before its instance was built has none (and a trim costs a
	 * refusal a tenth of its CPU) */
	if (buffers)
		malloc_trim(0);
}

/* Tell the worker to stop and every waiter to look again. */
static void signal_stop(srv_session *s)
{
	pthread_mutex_lock(&s->lock);
	s->stop = 1;
	pthread_cond_broadcast(&s->wake);
	pthread_cond_broadcast(&s->data);
	pthread_mutex_unlock(&s->lock);
}

static void stop_worker(srv_session *s)
{
	signal_stop(s);
	/* a worker waiting for its bed process's answer sees its stop at once */
	srv_dem_kill(s);
	if (s->worker_started) {
		pthread_join(s->worker, NULL);
		s->worker_started = 0;
	}
}

static void destroy(srv_entry *en)
{
	srv_session *s = SRV_CONTAINER(en, srv_session, entry);
	stop_worker(s);
	session_free(s);
}

/* A paced creation whose estimate does not fit the room the running paced
 * sessions leave is refused here, before sim_new builds and settles its
 * instance (most of what a refusal cost: a flood of refused creations took
 * the cores of the sessions that run): the estimate from what the instance
 * would integrate (srv_budget_cpu_preview) is the one session_init makes,
 * so the answer is the one the whole path would give. One that fits holds
 * its estimate from here on (raised to its probe's measure below, given
 * back if it fails): creations that come meanwhile see the room taken
 * rather than each spend a settling and a probe and all but one be
 * refused at the end. A LIGGGHTS bed's session is charged its bed's cores
 * (session_init; --max-dem-sessions bounds their settling). At any pace:
 * work no worker's grant or stop would interrupt (a sample, the settling);
 * last a --max-settling slot, held while its instance is built, settled
 * and probed (srv_session_create gives it back). 1 with *pb. */
static int refused_early(srv_session *s, const api_spec *spec, double before, api_problem *pb)
{
	double cpu;
	if (srv_dem_wanted(spec))
		return 0;
	if (srv_budget_cpu_preview(spec, before, &cpu, pb) != API_OK)
		return 1;
	if (spec->pace != API_PACE_MAX &&
	    srv_budget_take_paced(&s->budget.paced_held, cpu, spec->pace, "pace", "created",
				  pb) != API_OK)
		return 1;
	return srv_budget_take_settling(&s->budget.settling, pb) != API_OK;
}

/* Build s for spec: its sim instance, the initial status and the buffers
 * (lock and conditions are initialised), within --max-cpu-seconds less
 * before, the CPU s this thread spent on the request before. 0, or -1
 * with *pb, or 1 when its client left while its LIGGGHTS bed settled. */
static int session_init(srv_session *s, const api_spec *spec, double before, api_problem *pb)
{
	char msg[256] = "";
	int err = SIM_OK;
	s->spec = *spec;
	s->created = srv_unix_time();
	s->pace = spec->pace;
	s->until = spec->until;
	s->state = SRV_RUNNING;
	s->budget.cpu_limit = cfg->max_cpu_seconds;
	s->budget.turn.wake = &s->wake;
	if (refused_early(s, spec, before, pb))
		return -1;
	/* the settling and the probe stop at --max-cpu-seconds of this
	 * thread's CPU whatever the method (the estimate above cannot know an
	 * adaptive method's steps: core/cpu_bound.c), less what the request
	 * spent before them: one request, one bound */
	double left = before > 0 ? fmax(cfg->max_cpu_seconds - before, 0) : cfg->max_cpu_seconds;
	double cpu0 = srv_thread_cpu(), deadline = cpu0 + left, settled = 0;
	if (srv_cpu_settle_peek(spec, cpu0, deadline, &s->sim, pb))
		return -1;
	if (!s->sim)
		s->sim = sim_new_bounded(&spec->params, &spec->scene, &spec->method, deadline,
					 &settled, &err, msg, sizeof msg);
	if (!s->sim) {
		if (err == SIM_ECPU)
			srv_budget_settle_stopped(spec, before, srv_thread_cpu() - cpu0, settled,
						  pb);
		else
			api_fail(pb, api_from_sim(err ? err : SIM_ENOMEM), NULL, "%s",
				 msg[0] ? msg : sim_strerror(err));
		return -1;
	}
	/* the worker has not run yet: publish the initial state ourselves (the
	 * 201 shows beta, rotation and the equilibrium); the settling's cost */
	sim_get_status(s->sim, &s->st);
	if (spec->scene.feed) {
		s->columns = sim_columns(s->sim);
		s->layers = sim_layers(s->sim);
	}
	srv_log(SRV_LOG_DEBUG, "session %s: built and settled in %.3g CPU s, settling estimated "
		"at %.3g", s->entry.id, srv_thread_cpu() - cpu0,
		srv_budget_settle_cpu(spec, &s->st, s->layers));
	int bed = srv_dem_wanted(spec) ? srv_dem_start(s, 0, msg, sizeof msg) : 0;
	if (bed < 0)
		api_fail(pb, API_UNAVAILABLE, "scene.feed_model",
			 "the LIGGGHTS bed did not start: %s", msg);
	if (bed) /* or 1: its client left while the bed settled */
		return bed;
	/* what a simulated second costs: the larger of the estimate and a short
	 * run of a copy (cpu_probe.c). A threshold (the measurement only beyond
	 * twice the estimate) made a large scene's hold jump to the estimate
	 * when a busy machine's probe fell just below it; --cpu-probe 0: the
	 * estimate alone */
	s->budget.cpu_per_s = srv_budget_cpu_estimate(spec, &s->st, s->columns, s->layers);
	/* the hold raised to this estimate before the probe (the early one
	 * holds the same figure but where the instance differs from its
	 * preview, and a LIGGGHTS session has none): refused here where it
	 * does not fit, before a probe and a ring are spent on it */
	if (s->pace != API_PACE_MAX &&
	    srv_budget_take_paced(&s->budget.paced_held, s->budget.cpu_per_s, s->pace, "pace",
				  "created", pb) != API_OK)
		return -1;
	double probed = cfg->cpu_probe > 0 ? srv_cpu_probe(s->sim, spec, s->columns, s->layers,
							   cfg->cpu_probe, deadline, s->entry.id)
					   : -1.0;
	if (probed > s->budget.cpu_per_s)
		s->budget.cpu_per_s = probed;
	/* a bed process: its cores a simulated second until measured */
	if (s->dem.link && s->budget.cpu_per_s < s->dem.cores)
		s->budget.cpu_per_s = s->dem.cores;
	if (srv_ring_alloc(s, cfg->ring, cfg->history)) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return -1;
	}
	return 0;
}

/* The 429 of a creation beyond --max-sessions. */
static void sessions_full(api_problem *pb)
{
	int n = cfg->max_sessions;
	api_fail(pb, API_LIMIT, NULL, "%d session%s exist%s, the limit (--max-sessions); delete one "
		 "first", n, api_plural(n, "", "s"), api_plural(n, "s", ""));
	api_budget(pb, "sessions", n, 1);
}

srv_session *srv_session_create(const api_spec *request, srv_experiment *exp, int client_fd,
				double before, api_problem *pb)
{
	api_spec copy = *request;
	const api_spec *spec = &copy;
	srv_session *s = calloc(1, sizeof *s);
	if (!s) {
		api_fail(pb, API_UNAVAILABLE, NULL, "out of memory");
		return NULL;
	}
	s->create_fd = -1;
	session_locks_init(s);
	if (srv_registry_reserve(&sessions, &s->entry, NULL)) {
		session_free(s);
		sessions_full(pb);
		return NULL;
	}
	/* feed_model auto: the model the session runs, picked once here */
	if (copy.scene.feed_model == SIM_FEED_AUTO && srv_dem_pick(s, &copy, pb) != API_OK)
		goto fail;
	/* a LIGGGHTS bed: its program, its method and one of its slots */
	if (srv_dem_wanted(spec)) {
		if (srv_dem_admit(&copy, pb) != API_OK)
			goto fail;
		s->dem.slot = 1;
	}
	int feed = spec->scene.feed && spec->scene.columns > 0 &&
		   spec->scene.layers > 0;
	if (srv_budget_take_session(feed ? spec->scene.columns : 0,
				    feed ? spec->scene.layers : 0,
				    &s->budget.mem_reserved, pb) != API_OK) {
		s->budget.mem_reserved = 0;
		goto fail;
	}
	s->create_fd = client_fd;
	int bad = session_init(s, spec, before, pb);
	s->create_fd = -1;
	srv_budget_give_settling(&s->budget.settling); /* built, or not at all */
	/* a client gone while s settled reads no 201 (bad > 0: its bed saw it go) */
	if (bad < 0 || srv_client_left(client_fd, bad > 0, &srv_stats.sessions_abandoned, "session",
				       s->entry.id, "created", "settled", pb))
		goto fail;
	/* the cores it needs at its pace, before it runs */
	if (s->pace != API_PACE_MAX &&
	    srv_budget_take_paced(&s->budget.paced_held, s->budget.cpu_per_s, s->pace, "pace",
				  "created", pb) != API_OK)
		goto fail;
	s->exp = exp;
	s->owned = exp && !srv_exp_keeps_session(exp);
	if (exp) /* before its worker can end it and write its result */
		srv_exp_set_session(exp, s->entry.id);
	/* its directory now, its name durable: the spec is written in it
	 * below, the control log at the first control */
	if (srv_store_enabled()) {
		char dir[64];
		snprintf(dir, sizeof dir, "sessions/%s", s->entry.id);
		if (srv_store_make_dir(dir) != 0)
			snprintf(s->persist.store_error, sizeof s->persist.store_error,
				 "cannot create %s: %s", dir, strerror(errno));
	}
	s->last_access = s->persist.ckpt_wall = srv_now();
	s->persist.ckpt_dirty = 1;
	/* its spec on disk before it runs and before its 201: a crash after
	 * the answer keeps it (written here, beside the store's queue) */
	srv_persist_spec(s, 1);
	if (pthread_create(&s->worker, NULL, srv_worker_main, s) != 0) {
		api_fail(pb, API_UNAVAILABLE, NULL,
			 "cannot start the session's worker thread");
		srv_persist_remove(s); /* never answered: not restored either */
		goto fail;
	}
	s->worker_started = 1;
	srv_registry_publish(&sessions, &s->entry);
	atomic_fetch_add(&srv_stats.sessions_created, 1);
	srv_log(SRV_LOG_INFO, "session %s created", s->entry.id);
	return s;
fail:
	srv_registry_cancel(&sessions, &s->entry);
	session_free(s);
	return NULL;
}

/* A restored LIGGGHTS session: its slot (even beyond --max-dem-sessions:
 * it existed before) and a bed settled anew at the machine's restored
 * time; without one it fails with the reason. */
static void adopt_bed(srv_session *s)
{
	char msg[256];
	srv_dem_hold();
	s->dem.slot = 1;
	if (srv_dem_start(s, !s->restore.rebuilt, msg, sizeof msg) == 0) {
		if (s->budget.cpu_per_s < s->dem.cores)
			s->budget.cpu_per_s = s->dem.cores;
		return;
	}
	s->state = SRV_FAILED;
	snprintf(s->error, sizeof s->error, "the LIGGGHTS bed did not start again: %.200s", msg);
	srv_log(SRV_LOG_WARN, "session %s: %s", s->entry.id, s->error);
}

int srv_session_adopt(srv_session *s)
{
	s->last_access = s->persist.ckpt_wall = srv_now();
	srv_restore_budget(s, cfg->max_cpu_seconds);
	s->budget.turn.wake = &s->wake;
	if (s->damaged) {
		s->state = SRV_FAILED;
	} else {
		sim_get_status(s->sim, &s->st);
		if (s->spec.scene.feed) {
			s->columns = sim_columns(s->sim);
			s->layers = sim_layers(s->sim);
		}
		/* its worker commits the cores it needs, even beyond the
		 * budget: it existed before */
		s->budget.cpu_per_s = srv_budget_cpu_estimate(&s->spec, &s->st, s->columns, s->layers);
		if (srv_dem_wanted(&s->spec))
			adopt_bed(s);
	}
	if (srv_registry_reserve(&sessions, &s->entry, NULL)) {
		srv_log(SRV_LOG_WARN, "session %s not restored: --max-sessions "
				      "reached or id taken", s->entry.id);
		goto fail;
	}
	/* what it had before the restart: reserved even beyond the budget */
	s->budget.mem_reserved = srv_budget_session_need(s->columns, s->layers);
	srv_budget_take(s->budget.mem_reserved, "a restored session", 1, NULL);
	if (srv_ring_alloc(s, cfg->ring, cfg->history)) {
		srv_registry_cancel(&sessions, &s->entry);
		goto fail;
	}
	srv_registry_publish(&sessions, &s->entry);
	srv_registry_put(&sessions, &s->entry); /* the registry's stays */
	return 0;
fail:
	if (s->exp)
		srv_exp_abort(s->exp, "its session could not be restored");
	session_free(s);
	return -1;
}

/* Unlink s and stop its worker; its files go too unless the daemon
 * stops (then they are what the next start restores). 1, or 0 when
 * another call unlinked it first (and nothing is done). */
static int remove_session(srv_session *s, int files)
{
	if (!srv_registry_remove(&sessions, &s->entry))
		return 0;
	stop_worker(s);
	/* its bed process ends and is reaped now, and its slot is free for
	 * the next LIGGGHTS session at once, not when the last reader lets
	 * go of the session */
	srv_dem_free(s);
	if (s->dem.slot) {
		s->dem.slot = 0;
		srv_dem_release();
	}
	if (files)
		srv_persist_remove(s); /* after the worker's last write */
	if (files) {
		atomic_fetch_add(&srv_stats.sessions_deleted, 1);
		srv_log(SRV_LOG_INFO, "session %s deleted", s->entry.id);
	} else {
		srv_log(SRV_LOG_INFO, "session %s closed", s->entry.id);
	}
	return 1;
}

int srv_session_delete(srv_session *s)
{
	return remove_session(s, 1);
}

void srv_sessions_shutdown(void)
{
	/* stop all workers first (in parallel), then remove each */
	for (;;) {
		srv_session **all = NULL;
		size_t n = srv_sessions_all(&all);
		for (size_t i = 0; i < n; i++)
			signal_stop(all[i]);
		for (size_t i = 0; i < n; i++)
			remove_session(all[i], 0);
		srv_sessions_release(all, n);
		if (n == 0)
			break;
	}
}

size_t srv_sessions_reap(double idle_timeout)
{
	srv_session **all = NULL;
	size_t n = srv_sessions_all(&all), reaped = 0;
	double now = srv_now();
	for (size_t i = 0; i < n; i++) {
		srv_session *s = all[i];
		pthread_mutex_lock(&s->lock);
		int idle = idle_timeout > 0 && s->streams == 0 && !s->exp &&
			   now - s->last_access > idle_timeout;
		int go = s->expire || idle;
		pthread_mutex_unlock(&s->lock);
		if (!go)
			continue;
		srv_log(SRV_LOG_INFO, "session %s %s", s->entry.id,
			idle ? "expired (--idle-timeout)"
			     : "removed: its experiment ended");
		srv_session_delete(s);
		reaped++;
	}
	srv_sessions_release(all, n);
	return reaped;
}

size_t srv_sessions_restore(const srv_exp_finder *ef)
{
	if (!srv_store_enabled())
		return 0;
	char **names = NULL;
	size_t n = srv_store_list_ids("sessions", 1, &names), count = 0;
	for (size_t i = 0; i < n; i++) {
		char dir[64];
		snprintf(dir, sizeof dir, "sessions/%.40s", names[i]);
		/* no file in it: the daemon died creating it, before its spec
		 * was on disk, so before its 201 (which waits for the spec) */
		if (srv_store_dir_unwritten(dir)) {
			srv_log(SRV_LOG_INFO, "session %s: created but never answered (no spec "
					      "on disk); its empty directory is removed", names[i]);
			srv_store_remove(dir);
			free(names[i]);
			continue;
		}
		srv_session *s = calloc(1, sizeof *s);
		if (s) {
			s->create_fd = -1; /* no client waits for a restore */
			session_locks_init(s);
			srv_persist_load(s, names[i], ef);
			if (s->damaged)
				srv_log(SRV_LOG_WARN, "session %s %s", names[i],
					s->error);
			if (srv_session_adopt(s) == 0)
				count++;
		}
		free(names[i]);
	}
	free(names);
	/* all in first: the restore does not compete with running workers */
	srv_sessions_start_restored();
	return count;
}
