/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker.c - a session's worker thread: the only thread that touches the
 * session's sim instance. It runs below the request and stream threads
 * (--worker-nice, srv_thread_background): when the sessions want more CPU
 * than there is, they fall behind before the answers do.
 *
 * The loop runs a few named phases per turn, with the session lock held
 * except while the core advances (libuv's uv_run is the model):
 *
 *   job start   an experiment attached since the last turn begins: its first
 *               segment's command joins the queue
 *   commands    queued controls (PATCH, experiment segments) are applied in
 *               order and acknowledged, reading sim_effective_time(); each
 *               is appended to the session's control log
 *   checkpoint  with --data-dir, every --checkpoint-interval of wall time
 *               (and before going idle after a change) the session's
 *               state is serialised and handed to the store's writer
 *               (session_store.c); no file is touched here
 *   until       a running session that reached "until" finishes
 *   idle        a session that is not running sleeps until woken
 *   turn        a pace "max" session steps only while it holds one of the
 *               --max-busy CPU slots (budget.c), giving it up after each
 *               slice when others wait; any other session holds none
 *   pacing      simulated time is held to pace x wall time (no catching up
 *               after a stall; pace "max" runs flat out up to "until"): a
 *               paced session steps every sample due when it wakes (a
 *               batch), then sleeps until the sample a stream waits for
 *               is due or 0.1 s (pace())
 *   step        sim_advance by one sample interval (1/sample_rate simulated
 *               seconds, cut at "until" and at experiment boundaries), then
 *               publish the status snapshot and a record in the bounded ring
 *               (samples and control events, indexed by a sequence number
 *               that never repeats) and, every stride, a trajectory row (the
 *               stride doubles whenever the history fills); the readers are
 *               woken once per batch (every 10 ms of a flat-out session),
 *               and only when a record one of them waits for exists
 *   job step    the experiment records the step and, at a segment boundary,
 *               hands over the next segment's command
 *   failure     a core error fails the session and aborts its experiment
 *   cpu         the worker's CPU time is read (CLOCK_THREAD_CPUTIME_ID: the
 *               worker steps this session only), at most every 10 ms of
 *               wall time; a session that spent its grant (cpu_limit)
 *               pauses with pause_reason "cpu-budget"
 *   meter       achieved steps/s and real-time factor over half-second
 *               windows
 *
 * The command queue, and the attached experiment's command in it, are
 * worker_queue.c; the commands phase, the PATCH controls' apply column,
 * worker_control.c; the budget's phases (turn, need, cpu),
 * worker_budget.c.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "experiment.h"
#include "metrics.h"
#include "session_int.h"
#include "worker_int.h"
#include "util.h"

/* A flat-out session wakes its readers this often (s of wall time); a
 * paced one once per batch, before it sleeps. */
#define PUBLISH_EVERY 0.01

/* Let the session run at least up to t_end (s): raise until, resume a
 * finished session (lock held). */
static void extend_until(srv_session *s, double t_end)
{
	if (s->until > 0 && s->until < t_end)
		s->until = t_end;
	if (s->state == SRV_FINISHED && s->st.t < t_end)
		s->state = SRV_RUNNING;
}

/* Next simulated time to advance to (lock held). */
static double next_time(srv_session *s)
{
	double t = s->st.t;
	double dt = 1.0 / s->spec.sample_rate;
	double t_next = (floor(t / dt + 1e-6) + 1) * dt;
	if (s->until > 0 && t_next > s->until)
		t_next = s->until;
	if (s->exp) {
		double b = srv_exp_boundary(s->exp);
		if (b > t && b < t_next)
			t_next = b;
	}
	return t_next;
}

/* ---- the phases --------------------------------------------------------------- */

/* job start: an experiment attached since the last turn begins. */
static void start_job(srv_session *s)
{
	if (!s->exp || s->exp_started || s->state == SRV_FAILED || s->stop ||
	    (s->restore.exp_after_catch_up && s->restore.catch_up_t > 0))
		return;
	double t_end;
	srv_cmd *cmd = srv_exp_begin(s->exp, &s->st, &t_end);
	extend_until(s, t_end);
	srv_worker_queue_exp_command(s, cmd);
	s->exp_started = 1;
	pthread_cond_broadcast(&s->data);
}

/* replay: the controls logged after the checkpoint the session was
 * restored from go through the commands phase again, each once the
 * integrator reaches its t_effective, so that no acknowledged control is
 * lost to a crash. */
static void run_replay(srv_session *s)
{
	double t = sim_effective_time(s->sim);
	while (s->restore.replayed < s->restore.nreplay && s->restore.replay[s->restore.replayed].at <= t) {
		srv_replay *rp = &s->restore.replay[s->restore.replayed++];
		if (rp->exp_own)
			continue; /* its experiment sends it again */
		rp->cmd.replay = 1;
		srv_worker_queue(s, &rp->cmd);
	}
}

/* caught up: a restored session (session_load.c catch_up) ran flat out
 * to where it was, or a replayed control stopped it short of that, or it
 * failed: from here on it keeps its pace and answers. */
static void check_caught_up(srv_session *s, clocks *c)
{
	if (!(s->restore.catch_up_t > 0) ||
	    (s->st.t < s->restore.catch_up_t && s->state != SRV_FAILED && !s->stop &&
	     (s->restore.replayed < s->restore.nreplay || s->state == SRV_RUNNING)))
		return;
	s->restore.catch_up_t = 0;
	s->restore.replay_seconds = srv_now() - s->restore.replay_wall;
	srv_worker_restart_clocks(c, s);
	srv_log(SRV_LOG_INFO, "session %s: replayed to t = %g s in %.3f s",
		s->entry.id, s->st.t, s->restore.replay_seconds);
}

/* commands: apply what is queued; pacing restarts after pace or pause. */
static void run_commands(srv_session *s, clocks *c)
{
	if (s->cmd_head && srv_worker_apply_commands(s))
		srv_worker_restart_clocks(c, s);
}

/* until: a running session that reached until finishes there. */
static void check_until(srv_session *s, clocks *c)
{
	if (s->state == SRV_RUNNING && s->until > 0 && s->st.t >= s->until) {
		s->state = SRV_FINISHED;
		s->persist.ckpt_dirty = 1;
		srv_ring_event_at(s, "finished", NULL);
		srv_worker_publish(s, c);
	}
}

/* idle: a session that is not running sleeps until woken; 1 if it slept. */
static int idle(srv_session *s, clocks *c)
{
	if (s->state == SRV_RUNNING)
		return 0;
	srv_cpu_leave(&s->budget.turn);
	s->budget.waiting_for_cpu = 0;
	s->steps_per_s = s->rtf = 0;
	/* the CPU it stopped at: the loop reads it only every 10 ms, and a
	 * short pace "max" run finishes in less */
	srv_worker_read_cpu(s);
	srv_persist_checkpoint(s, 1); /* what it stopped at, exactly */
	srv_worker_publish(s, c);
	pthread_cond_wait(&s->wake, &s->lock);
	srv_worker_restart_clocks(c, s);
	return 1;
}

/* meter: steps/s and real-time factor over the last half second, as of
 * wall time now: a paced session's is taken at the end of a batch as of
 * its start (it stepped what was due by then; a thread put off the CPU
 * while it stepped has not fallen behind for that). */
static void meter(srv_session *s, clocks *c, double now)
{
	if (now - c->rate_wall < 0.5)
		return;
	s->steps_per_s = (double)(s->st.steps - c->rate_steps) /
			 (now - c->rate_wall);
	s->rtf = (s->st.t - c->rate_t) / (now - c->rate_wall);
	c->rate_wall = now;
	c->rate_t = s->st.t;
	c->rate_steps = s->st.steps;
}

/* A paced session steps in batches, each of every sample due by the time
 * it wakes, and sleeps in between until the first of:
 *   - the next sample a waiting stream wants is due (wake_t; a stream that
 *     starts waiting for an earlier one than the worker sleeps to, plan_t,
 *     wakes it: ring.c), so that a stream's samples leave on time, not
 *     early nor late by a batch;
 *   - the next PACE_TICK of simulated time is due, or PACE_TICK of wall
 *     time has passed: the status and the CPU measure stay that fresh;
 * and never sooner than PACE_MIN after the batch before (a stream of every
 * sample gets them in batches of that). Waking costs more than the
 * simulation of a default session (a context switch of a thread among
 * hundreds): at 250 Hz sampling one wake-up a sample was 250 a second,
 * batches of 20 ms ahead 50, a 10-Hz stream now 10. */
#define PACE_TICK 0.1
#define PACE_MIN 0.02

/* The wall time of simulated time t at the session's pace. */
static double due_at(const srv_session *s, const clocks *c, double t)
{
	return c->anchor_wall + (t - c->anchor_t) / s->pace;
}

/* pacing: step t_next now if it is due within the current batch, else
 * sleep until the next batch and start it; 1 if it slept (the loop then
 * starts over, so that commands are seen at once). */
static int pace(srv_session *s, clocks *c, double t_next)
{
	if (s->pace == API_PACE_MAX || s->restore.catch_up_t > 0)
		return 0;
	double due = due_at(s, c, t_next);
	if (due <= c->batch_end)
		return 0;
	srv_worker_publish_batch(s, c); /* the batch is over */
	if (s->cmd_head || s->stop)
		return 1; /* came while the lock was let go */
	if (c->batch_start > c->rate_wall)
		meter(s, c, c->batch_start); /* as of when it began */
	double tick = (floor(s->st.t / PACE_TICK + 1e-6) + 1) * PACE_TICK;
	double plan = due_at(s, c, tick);
	if (c->batch_start + PACE_TICK < plan)
		plan = c->batch_start + PACE_TICK;
	if (s->ring.wake_t < INFINITY && due_at(s, c, s->ring.wake_t) < plan)
		plan = due_at(s, c, s->ring.wake_t);
	if (c->want_all && c->batch_start + PACE_MIN < plan)
		plan = c->batch_start + PACE_MIN;
	if (plan < c->batch_start + PACE_MIN)
		plan = c->batch_start + PACE_MIN;
	if (plan < due)
		plan = due;
	double now = srv_now();
	if (now < plan) {
		s->ring.plan_t = c->anchor_t + (plan - c->anchor_wall) * s->pace;
		struct timespec ts = srv_deadline(plan - now);
		pthread_cond_timedwait(&s->wake, &s->lock, &ts);
		s->ring.plan_t = INFINITY;
		return 1;
	}
	if (now - due > 0.25 + PACE_TICK) { /* behind: do not catch up */
		c->anchor_wall = now;
		c->anchor_t = s->st.t;
	}
	c->batch_start = c->batch_end = now;
	c->batch_steps = 0;
	return 0;
}

/* step: advance to t_next with the lock released, then publish the status
 * and push a sample (its readers are woken once per batch: publish). A
 * LIGGGHTS session advances machine and bed together to the end of the
 * coupling interval at or after t_next (session_dem.c), its status
 * showing the bed's feed. Returns the core's code; a bed that failed
 * gives SIM_EDIVERGED with its reason in why. */
static int step(srv_session *s, double t_next, char *why, size_t whylen)
{
	sim_status st;
	api_bed bed = s->dem.bed;
	int rc = SIM_OK;
	uint64_t steps = s->st.steps;
	pthread_mutex_unlock(&s->lock);
	if (!s->dem.link)
		rc = sim_advance(s->sim, t_next);
	else if (srv_dem_step(s, t_next, why, whylen))
		rc = SIM_EDIVERGED;
	if (s->dem.link) {
		sim_get_status(s->sim, &st);
		srv_dem_controlled(s, &st);
		srv_dem_read(s, &st, &bed);
	}
	srv_ring_gather(s);
	pthread_mutex_lock(&s->lock);
	if (s->dem.link) {
		s->st = st;
		s->dem.bed = bed;
	} else {
		/* straight into the session's status: one copy of it a sample
		 * fewer (the worker alone touches the sim) */
		sim_get_status(s->sim, &s->st);
	}
	if (s->st.steps > steps)
		atomic_fetch_add(&srv_stats.steps, s->st.steps - steps);
	srv_ring_sample(s);
	return rc;
}

/* A paced batch reads the clock after every this many steps (and at its
 * start, pace()), so that a batch that runs long (its thread put off the
 * CPU) still wakes its readers every PUBLISH_EVERY. */
#define BATCH_CLOCK_EVERY 16

/* After a step: a flat-out session reads the clock (the cpu phase, next,
 * takes it), meters and wakes its readers every PUBLISH_EVERY; a paced
 * one's batch began at a time read once (pace()), which stands for now
 * but every BATCH_CLOCK_EVERY steps, and its readers are woken at the
 * batch's end, or every PUBLISH_EVERY of a long batch (a read of the
 * clock a sample was 1.8 % of a daemon of paced sessions:
 * docs/performance.md). A step that failed wakes them at once. */
static void after_step(srv_session *s, clocks *c, int rc)
{
	double since = c->publish_wall;
	if (s->pace == API_PACE_MAX || s->restore.catch_up_t > 0) {
		c->stepped_wall = srv_now();
		meter(s, c, c->stepped_wall); /* paced: pace() */
	} else if (++c->batch_steps % BATCH_CLOCK_EVERY == 0) {
		c->stepped_wall = srv_now();
		since = fmax(since, c->batch_start);
	} else {
		c->stepped_wall = c->batch_start;
		since = INFINITY;
	}
	if (rc != SIM_OK || c->stepped_wall - since >= PUBLISH_EVERY)
		srv_worker_publish(s, c);
}

/* job step: the experiment sees the step; it may end or hand over the
 * next segment's command. */
static void run_job(srv_session *s)
{
	if (!s->exp || !s->exp_started)
		return;
	int over = 0;
	srv_worker_queue_exp_command(s, srv_exp_step(s->exp, &s->st, &over));
	if (over) {
		srv_worker_detach_exp(s, NULL);
		s->persist.ckpt_dirty = 1;
		if (s->owned) /* created by it and not kept */
			s->expire = 1;
	}
}

/* failure: the core refused to go on, or a LIGGGHTS session's bed did
 * (why, else ""); the session fails for good. A bed ended by the
 * session's own stop (deleted, the daemon stopping) is no failure. */
static void fail(srv_session *s, int rc, const char *why)
{
	if (s->stop && why[0])
		return;
	s->state = SRV_FAILED;
	s->persist.ckpt_dirty = 1;
	if (s->owned)
		s->expire = 1;
	if (why[0])
		snprintf(s->error, sizeof s->error, "the LIGGGHTS bed: %.220s", why);
	else
		snprintf(s->error, sizeof s->error, "%s: %s", sim_strerror(rc),
			 sim_last_error(s->sim) ? sim_last_error(s->sim) : "");
	srv_ring_event_at(s, "failed", NULL);
	srv_worker_detach_exp(s, s->error);
	srv_log(SRV_LOG_WARN, "session %s failed: %s", s->entry.id, s->error);
}

void *srv_worker_main(void *arg)
{
	srv_session *s = arg;
	clocks clk = {0};
	srv_thread_background("session");
	srv_ring_gather(s);
	pthread_mutex_lock(&s->lock);
	sim_get_status(s->sim, &s->st);
	srv_ring_sample(s);
	srv_worker_restart_clocks(&clk, s);
	clk.cpu_wall = -INFINITY;
	clk.stepped_wall = NAN;
	/* the thread's CPU clock starts at 0 (on what a restored session had
	 * spent); a LIGGGHTS bed's settling, done before the first step, is
	 * no cost of simulated time (counted, it made a 92-grain bed's first
	 * window 25 CPU s a simulated second and paced the session down to
	 * 0.04) */
	clk.cost_t = s->st.t;
	clk.cost_cpu = s->budget.cpu_base + (s->dem.link ? s->dem.bed.cpu_seconds : 0.0);
	srv_worker_publish(s, &clk);
	for (;;) {
		start_job(s);
		run_replay(s);
		run_commands(s, &clk);
		if (!s->first_applied) {
			/* what was due at the start is in: the status shows it */
			s->first_applied = 1;
			pthread_cond_broadcast(&s->data);
		}
		check_caught_up(s, &clk);
		if (s->stop)
			break;
		srv_persist_checkpoint(s, 0);
		check_until(s, &clk);
		srv_worker_check_cpu(s, &clk);
		srv_worker_commit_need(s, &clk);
		if (idle(s, &clk) || srv_worker_take_turn(s, &clk))
			continue;
		double t_next = next_time(s);
		if (pace(s, &clk, t_next))
			continue;
		char why[256] = "";
		int rc = step(s, t_next, why, sizeof why);
		run_job(s);
		if (rc != SIM_OK)
			fail(s, rc, why);
		after_step(s, &clk, rc);
	}
	if (srv_stopping()) { /* the next start continues from here */
		/* the log first, here: the session has left the registry, so
		 * the store's writer can no longer find it to sync the lines
		 * nobody waited for before the checkpoint */
		size_t logged = s->controls_len;
		pthread_mutex_unlock(&s->lock);
		srv_control_log_sync(s, logged, 30.0);
		pthread_mutex_lock(&s->lock);
		s->persist.ckpt_dirty = 1;
		srv_worker_read_cpu(s); /* the CPU it spent, to the end */
		srv_persist_checkpoint(s, 1);
	}
	srv_worker_detach_exp(s, "the session was deleted or the daemon stopped");
	srv_cpu_leave(&s->budget.turn);
	srv_budget_set_paced(&s->budget.paced_held, 0);
	pthread_cond_broadcast(&s->data);
	pthread_mutex_unlock(&s->lock);
	return NULL;
}
