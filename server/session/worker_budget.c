/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * worker_budget.c - the worker's phases of the CPU budget (budget.c):
 * the cost a simulated second measures, the hold on the paced cores that
 * follows it (paced down when far beyond it), the CPU grant (cpu_limit)
 * and the turn on a --max-busy slot of a pace "max" session. The loop
 * that calls them is worker.c.
 */
#include <math.h>
#include <stdio.h>
#include <time.h>

#include "metrics.h"
#include "util.h"
#include "worker_int.h"

/* The CPU clock is read at most this often (s of wall time): once per
 * batch of a paced session, every 10 ms of a flat-out one. */
#define CPU_READ_EVERY 0.01

/* A running session is paced down only when it measures more than this
 * times what it holds: a scene whose estimate was far off (a restored one
 * is admitted by the estimate alone, without the probe; a 16 x 64 feed
 * measured 12 times its estimate). A default session's measure differs
 * from its estimate by up to 3.3 times on this machine (a lone paced
 * session's wake-ups from an idle core have cost it 1.6-7 ms of CPU per
 * simulated s, hundreds of them 1.4-2.4 ms each, the estimate says 2.15), and
 * an admitted session keeps its pace through that: the budget's excess
 * then refuses the next session instead. */
#define PACE_DOWN_OVER 4.0

/* The CPU a simulated second costs this session, over windows of 50 ms of
 * CPU or 2 simulated s, whichever comes first; the mean of the last and
 * this window's (a session's cost changes with its state: a run-up, a
 * moving feed). */
#define COST_WINDOW_CPU 0.05
#define COST_WINDOW_T 2.0

static void measure_cost(srv_session *s, clocks *c)
{
	double cpu = s->budget.cpu_seconds - c->cost_cpu, t = s->st.t - c->cost_t;
	if (t <= 0 || (cpu < COST_WINDOW_CPU && t < COST_WINDOW_T)) {
		if (t < 0) /* not a window: start one */
			c->cost_cpu = s->budget.cpu_seconds, c->cost_t = s->st.t;
		return;
	}
	double cost = cpu / t;
	c->cost_cpu = s->budget.cpu_seconds;
	c->cost_t = s->st.t;
	/* the first window is the session's start: the shadow that measures
	 * the step error runs over its first 40 periods (1.6 s of a default
	 * session), which measured 3-4 ms of CPU per simulated s where it
	 * then runs at 2.3-2.6. A burst of creations checked against such
	 * measures refused sessions that fit by their steady cost, so it keeps
	 * the steady cost it was admitted for (the probe's: cpu_probe.c) but
	 * where it measures PACE_DOWN_OVER times that (a scene far off its
	 * estimate) */
	if (c->cost_windows++ == 0 && cost <= PACE_DOWN_OVER * s->budget.cpu_per_s)
		return;
	s->budget.cpu_per_s = s->budget.cpu_measured ? 0.5 * (s->budget.cpu_per_s + cost) : cost;
	s->budget.cpu_measured = 1;
}

/* The session measured more than it was admitted for: it goes on at the
 * pace that fits the cores for paced sessions (budget.c), taken as a
 * control would be (the stream's and the control log's "control" event),
 * so that it does not starve the others (lock held). */
static void pace_down(srv_session *s, clocks *c)
{
	double was = s->pace, cost = srv_paced_cost(s, was);
	double pace = srv_budget_fit_pace(&s->budget.paced_held, srv_paced_cost_of, s, was);
	if (pace >= was)
		return;
	api_control ctl = {.set = API_C_PACE, .pace = pace};
	char json[API_EVENT_MAX];
	api_control_event(json, sizeof json, &ctl, sim_effective_time(s->sim));
	s->pace = pace;
	srv_ring_event(s, "control", json);
	srv_control_log_append(s, json, SRV_LINE_FLUSH);
	s->persist.ckpt_dirty = 1;
	srv_worker_restart_clocks(c, s);
	srv_log(SRV_LOG_WARN, "session %s: %.3g CPU s per simulated s, more than "
			      "admitted; paced down from %g to %g to fit "
			      "--max-paced-cores", s->entry.id, cost, was, pace);
}

/* need: the session's hold on the paced cores follows what it needs now
 * (its state, pace and measured cost), even beyond the budget: admission
 * is checked where a request raises it (session.c), so that the sessions
 * admitted keep their pace and the next one is refused; only a measure
 * PACE_DOWN_OVER times its hold with no room left paces it down. Called in the same
 * turn as the commands phase (the lock is not let go in between), so that
 * a hold a handler raised for its queued command is kept until the worker
 * has applied it. */
void srv_worker_commit_need(srv_session *s, clocks *c)
{
	double need = srv_paced_need(s);
	if (need > PACE_DOWN_OVER * s->budget.paced_held && need > 1e-9)
		pace_down(s, c);
	else if (need != s->budget.paced_held)
		srv_budget_set_paced(&s->budget.paced_held, need);
}

/* The worker's CPU time into the session's cpu_seconds, on what it had
 * spent before a restart (cpu_base); a LIGGGHTS session's bed process's
 * CPU is the session's too. */
void srv_worker_read_cpu(srv_session *s)
{
	struct timespec ts;
	if (clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts) == 0)
		s->budget.cpu_seconds = s->budget.cpu_base + (double)ts.tv_sec +
					1e-9 * (double)ts.tv_nsec +
					(s->dem.link ? s->dem.bed.cpu_seconds : 0.0);
}

/* cpu: read the worker's CPU time; a running session that spent its
 * grant pauses. */
void srv_worker_check_cpu(srv_session *s, clocks *c)
{
	/* the time the loop read after its step (nothing between slept),
	 * else now */
	double now = isnan(c->stepped_wall) ? srv_now() : c->stepped_wall;
	c->stepped_wall = NAN;
	if (now - c->cpu_wall < CPU_READ_EVERY)
		return;
	c->cpu_wall = now;
	srv_worker_read_cpu(s);
	measure_cost(s, c);
	if (s->state != SRV_RUNNING || s->budget.cpu_seconds < s->budget.cpu_limit)
		return;
	s->state = SRV_PAUSED;
	s->budget.cpu_paused = 1;
	s->persist.ckpt_dirty = 1;
	srv_ring_event_at(s, "paused", "\"reason\":\"cpu-budget\"");
	srv_worker_publish(s, c);
	srv_log(SRV_LOG_INFO, "session %s paused: its CPU budget of %g s is "
			      "spent", s->entry.id, s->budget.cpu_limit);
}

/* turn: a running pace "max" session steps only while it holds a CPU
 * slot; any other gives its slot (or place in line) up. 1 if it must wait
 * (the loop then starts over, so that commands are seen at once). */
int srv_worker_take_turn(srv_session *s, clocks *c)
{
	if (s->state != SRV_RUNNING || s->pace != API_PACE_MAX || s->stop) {
		srv_cpu_leave(&s->budget.turn);
		s->budget.waiting_for_cpu = 0;
		return 0;
	}
	if (srv_cpu_turn_over(&s->budget.turn))
		srv_cpu_leave(&s->budget.turn); /* to the back of the line */
	if (srv_cpu_take(&s->budget.turn)) {
		s->budget.waiting_for_cpu = 0;
		return 0;
	}
	s->budget.waiting_for_cpu = 1;
	srv_worker_publish(s, c);
	struct timespec ts = srv_deadline(0.05); /* a missed signal costs 50 ms */
	pthread_cond_timedwait(&s->wake, &s->lock, &ts);
	srv_worker_restart_clocks(c, s);
	return 1;
}

