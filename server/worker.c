/*
 * worker.c - a session's worker thread: the only thread that touches the
 * session's sim instance.
 *
 * The worker applies queued controls between steps (reading
 * sim_effective_time() for the acknowledgement), advances the core one
 * sample interval (1/sample_rate simulated seconds) at a time with
 * sim_advance, and publishes under the session lock: the status
 * snapshot, a record in the bounded ring (samples and control events,
 * indexed by a sequence number that never repeats) and, every stride, a
 * trajectory row (the stride doubles whenever the history fills). Pacing
 * holds simulated time to pace x wall time without catching up after a
 * stall, or runs flat out for pace "max" up to "until". Achieved steps/s
 * and real-time factor are measured over half-second windows.
 */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "session_int.h"
#include "units.h"

static api_sample *push_slot(srv_session *s)
{
	api_sample *slot = &s->ring[s->head % s->ring_cap];
	slot->index = s->head++;
	return slot;
}

void srv_session_push_event(srv_session *s, const char *type,
			    const char *json)
{
	api_sample *slot = push_slot(s);
	slot->kind = API_REC_EVENT;
	slot->st = s->st;
	snprintf(slot->event_type, sizeof slot->event_type, "%s", type);
	snprintf(slot->event, sizeof slot->event, "%s", json);
}

static void push_event_reason(srv_session *s, const char *type,
			      const char *detail)
{
	char json[API_EVENT_MAX], t[40];
	api_fmt_double(t, sizeof t, s->st.t);
	snprintf(json, sizeof json, "{\"t\":%s%s%s}", t, detail ? "," : "",
		 detail ? detail : "");
	srv_session_push_event(s, type, json);
}

static void record_history(srv_session *s)
{
	if (s->st.t < s->hist_next - 1e-12 || !s->hist_cap)
		return;
	if (s->hist_n == s->hist_cap) {
		/* full: keep every other row, double the stride */
		size_t k = 0;
		for (size_t i = 0; i < s->hist_n; i += 2, k++)
			memmove(s->hist + k * API_HISTORY_COLS,
				s->hist + i * API_HISTORY_COLS,
				API_HISTORY_COLS * sizeof(double));
		s->hist_n = k;
		s->hist_stride *= 2;
	}
	api_history_row(&s->st, s->hist + s->hist_n * API_HISTORY_COLS);
	s->hist_n++;
	s->hist_next = s->st.t + s->hist_stride;
}

static void record_sample(srv_session *s)
{
	api_sample *slot = push_slot(s);
	slot->kind = API_REC_SAMPLE;
	slot->st = s->st;
	slot->event_type[0] = '\0';
	size_t n = (size_t)s->columns +
		   2 * (size_t)s->columns * (size_t)s->layers;
	if (n)
		memcpy(slot->column_disp, s->scratch.column_disp,
		       n * sizeof(double));
	record_history(s);
}

/* Copy the feed arrays out of the instance (worker, no lock needed). */
static void gather_feed(srv_session *s)
{
	if (!s->columns)
		return;
	sim_column_displacement(s->sim, s->scratch.column_disp);
	sim_feed_state(s->sim, s->scratch.xi, s->scratch.eta);
}

/* Apply queued controls (lock held). Returns 1 if pacing must restart. */
static int apply_commands(srv_session *s)
{
	int reanchor = 0;
	srv_cmd *cmd;
	while ((cmd = s->cmd_head)) {
		s->cmd_head = cmd->next;
		if (!s->cmd_head)
			s->cmd_tail = NULL;
		const api_control *c = &cmd->c;
		double t_eff = sim_effective_time(s->sim);
		int rc = SIM_OK;
		if (c->set & (API_C_BETA | API_C_BETA_RATE)) {
			double target = (c->set & API_C_BETA)
						? c->beta
						: s->st.beta_target * DEG_PER_RAD;
			double rate =
				(c->set & API_C_BETA_RATE) ? c->beta_rate : 0;
			rc = sim_set_beta(s->sim, sim_rad_from_deg(target),
					  sim_rad_from_deg(rate));
		}
		if (rc == SIM_OK && (c->set & API_C_ROTATION))
			rc = sim_set_rotation(s->sim, c->rotation);
		if (rc == SIM_OK && (c->set & API_C_OMEGA_SS))
			rc = sim_set_omega_ss(s->sim, c->omega_ss);
		if (rc == SIM_OK && (c->set & API_C_MOTOR))
			rc = sim_set_drive_on(s->sim, c->motor_on);
		if (rc == SIM_OK && (c->set & API_C_PACE)) {
			s->pace = c->pace;
			reanchor = 1;
		}
		if (rc == SIM_OK && (c->set & API_C_UNTIL)) {
			s->until = c->until;
			if (s->state == SRV_FINISHED &&
			    (s->until == 0 || s->until > s->st.t))
				s->state = SRV_RUNNING;
		}
		if (rc == SIM_OK && (c->set & API_C_RUNNING)) {
			if (!c->running && s->state == SRV_RUNNING)
				s->state = SRV_PAUSED;
			else if (c->running && s->state == SRV_PAUSED)
				s->state = SRV_RUNNING;
			reanchor = 1;
		}
		if (s->pace == API_PACE_MAX && s->until == 0)
			s->until = s->st.t + API_DEFAULT_MAX_UNTIL;
		if (rc == SIM_OK) {
			char json[API_EVENT_MAX];
			api_control_event(json, sizeof json, c, t_eff);
			srv_session_push_event(s, "control", json);
		}
		cmd->rc = rc;
		cmd->t_eff = t_eff;
		cmd->done = 1;
	}
	pthread_cond_broadcast(&s->data);
	return reanchor;
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

void *srv_worker_main(void *arg)
{
	srv_session *s = arg;
	double anchor_wall = srv_now(), anchor_t = 0;
	double rate_wall = anchor_wall, rate_t = 0;
	uint64_t rate_steps = 0;
	sim_status st;

	gather_feed(s);
	pthread_mutex_lock(&s->lock);
	sim_get_status(s->sim, &s->st);
	record_sample(s);
	pthread_cond_broadcast(&s->data);
	for (;;) {
		if (s->cmd_head && apply_commands(s)) {
			anchor_wall = rate_wall = srv_now();
			anchor_t = rate_t = s->st.t;
			rate_steps = s->st.steps;
		}
		if (s->stop)
			break;
		if (s->exp && !s->exp_started && s->state != SRV_FAILED) {
			srv_exp_begin(s->exp, s->sim, &s->st, s);
			s->exp_started = 1;
			pthread_cond_broadcast(&s->data);
		}
		if (s->state == SRV_RUNNING && s->until > 0 &&
		    s->st.t >= s->until) {
			s->state = SRV_FINISHED;
			push_event_reason(s, "finished", NULL);
			pthread_cond_broadcast(&s->data);
		}
		if (s->state != SRV_RUNNING) {
			s->steps_per_s = s->rtf = 0;
			pthread_cond_wait(&s->wake, &s->lock);
			anchor_wall = rate_wall = srv_now();
			anchor_t = rate_t = s->st.t;
			rate_steps = s->st.steps;
			continue;
		}
		double t_next = next_time(s);
		if (s->pace != API_PACE_MAX) {
			double due = anchor_wall + (t_next - anchor_t) / s->pace;
			double now = srv_now();
			if (now < due - 1e-4) {
				struct timespec ts = srv_deadline(due - now);
				pthread_cond_timedwait(&s->wake, &s->lock, &ts);
				continue;
			}
			if (now - due > 0.25) { /* behind: do not catch up */
				anchor_wall = now;
				anchor_t = s->st.t;
			}
		}
		pthread_mutex_unlock(&s->lock);
		int rc = sim_advance(s->sim, t_next);
		sim_get_status(s->sim, &st);
		gather_feed(s);
		pthread_mutex_lock(&s->lock);
		if (st.steps > s->st.steps)
			atomic_fetch_add(&srv_stats.steps, st.steps - s->st.steps);
		s->st = st;
		record_sample(s);
		if (s->exp && s->exp_started &&
		    srv_exp_step(s->exp, s->sim, &s->st, s)) {
			s->exp = NULL;
			s->exp_started = 0;
		}
		if (rc != SIM_OK) {
			s->state = SRV_FAILED;
			snprintf(s->error, sizeof s->error, "%s: %s",
				 sim_strerror(rc),
				 sim_last_error(s->sim) ? sim_last_error(s->sim)
							: "");
			push_event_reason(s, "failed", NULL);
			if (s->exp) {
				srv_exp_abort(s->exp, s->error);
				s->exp = NULL;
			}
			srv_log(SRV_LOG_WARN, "session %s failed: %s", s->id,
				s->error);
		}
		double now = srv_now();
		if (now - rate_wall >= 0.5) {
			s->steps_per_s = (double)(st.steps - rate_steps) /
					 (now - rate_wall);
			s->rtf = (st.t - rate_t) / (now - rate_wall);
			rate_wall = now;
			rate_t = st.t;
			rate_steps = st.steps;
		}
		pthread_cond_broadcast(&s->data);
	}
	if (s->exp) {
		srv_exp_abort(s->exp, "the session was deleted or the daemon "
				      "stopped");
		s->exp = NULL;
	}
	pthread_cond_broadcast(&s->data);
	pthread_mutex_unlock(&s->lock);
	return NULL;
}

