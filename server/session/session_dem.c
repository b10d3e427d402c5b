/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_dem.c - a session whose feed is a LIGGGHTS bed (scene.feed_model
 * liggghts, docs/dem.md "LIGGGHTS as the feed model of a session"): the
 * machine is the session's sim instance, stepped by its worker as any
 * other; the bed runs in a child process, convsim-bed (dem/feed_remote.c),
 * and the two are coupled at every machine step by dem/couple.c, the
 * CLI's own coupling. LIGGGHTS never runs in this process: it ends its
 * process on a command it refuses and is not known to be thread-safe.
 *
 * Admission: the bed program must exist (--dem-bed, or convsim-bed next to
 * this executable; else 422 on scene.feed_model), the method must take a
 * fixed step (422 on integrator.method), and at most --max-dem-sessions
 * run at once (429, budget "dem-sessions"). A LIGGGHTS session holds at
 * least a whole core of the paced budget while it runs paced, --dem-ranks
 * of them under mpirun (session_int.h srv_paced_need): its bed process
 * uses that many. The worker counts the bed process's CPU time (all its
 * ranks') as the session's.
 *
 * Persistence: the machine is restored from its checkpoint like any
 * other; the bed is settled anew from its seed at the restored time
 * ("restored": "bed_resettled"), so the transport velocity and the
 * balances count from there.
 */
#include <limits.h>
#include <math.h>
#include <stdatomic.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "couple.h"
#include "session_int.h"
#include "util.h"

static const srv_config *cfg;
static char bed_path[PATH_MAX];
static atomic_int live; /* LIGGGHTS sessions, their slots reserved */

void srv_dem_init(const srv_config *config)
{
	cfg = config;
	if (cfg->dem_bed) {
		snprintf(bed_path, sizeof bed_path, "%s", cfg->dem_bed);
		return;
	}
	/* next to our own executable */
	char self[PATH_MAX];
	ssize_t n = readlink("/proc/self/exe", self, sizeof self - 1);
	if (n <= 0)
		return;
	self[n] = '\0';
	char *slash = strrchr(self, '/');
	if (slash)
		snprintf(bed_path, sizeof bed_path, "%.*s/convsim-bed", (int)(slash - self), self);
}

int srv_dem_wanted(const api_spec *spec)
{
	return spec->scene.feed && spec->scene.feed_model == SIM_FEED_EXTERNAL;
}

api_err srv_dem_admit(api_spec *spec, api_problem *pb)
{
	char msg[256], choices[96];
	if (!bed_path[0] || access(bed_path, X_OK) != 0) {
		/* auto picks among the models this daemon runs: column here */
		unsigned offered = 1u << SIM_FEED_COLUMN | 1u << SIM_FEED_AUTO;
		return api_fail_choices(pb, API_RANGE, "scene.feed_model",
					api_choices_of("feed_model", offered, choices, sizeof choices),
					"scene.feed_model liggghts needs the bed program %s, which "
					"this daemon does not find (built only where LIGGGHTS is "
					"installed: `make deps` then `make`; or --dem-bed PATH); column "
					"is offered",
					bed_path[0] ? bed_path : "convsim-bed");
	}
	if (spec->method.dt == 0.0) /* as `convsim run` couples it */
		spec->method.dt = DEM_COUPLED_DT;
	if (dem_coupled_check(&spec->scene, &spec->method, 1, spec->scene.transient, msg,
			      sizeof msg)) {
		/* the methods a bed couples to: those of a fixed step (the
		 * setting's choices are the registry's names, in its order) */
		size_t nm;
		const sim_method_info *const *mi = sim_methods(&nm);
		unsigned fixed = 0;
		for (size_t i = 0; i < nm && i < 32; i++)
			fixed |= mi[i]->adaptive ? 0u : 1u << i;
		return api_fail_choices(pb, API_RANGE, "integrator.method",
					api_choices_of("method", fixed, choices, sizeof choices), "%s",
					msg);
	}
	/* the bed's cost: its grains over its DEM step, which shrinks as the
	 * contact stiffens (k/m = k_c / m_n); the cost grows as sqrt(k_c) */
	dem_bed_spec bed;
	dem_bed_spec_default(&spec->params, (double)spec->scene.layers, &bed);
	double cost = dem_bed_spec_cost(&bed);
	if (!(cost <= cfg->max_dem_cost)) {
		double k_max = spec->params.k_c * (cfg->max_dem_cost / cost) *
			       (cfg->max_dem_cost / cost);
		const sim_setting *t = sim_setting_find("k_c");
		return api_fail_range(pb, "params.k_c", t ? t->min : 0.0, k_max,
				      "the LIGGGHTS bed of %d grains at k_c/m_n = %.3g 1/s^2 takes "
				      "DEM steps of %.2g s: about %.3g CPU s a simulated second, more "
				      "than --max-dem-cost %g; k_c at most %.3g N/m at this m_n (or "
				      "fewer layers)",
				      bed.grains, bed.k_over_m, dem_bed_spec_dt(&bed), cost,
				      cfg->max_dem_cost, k_max);
	}
	int n = atomic_load(&live);
	do {
		if (n >= cfg->max_dem_sessions) {
			api_fail(pb, API_LIMIT, "scene.feed_model",
				 "%d LIGGGHTS session%s run%s, the limit (--max-dem-sessions %d): "
				 "each runs a bed process that holds a core; delete one first", n,
				 api_plural(n, "", "s"), api_plural(n, "s", ""), cfg->max_dem_sessions);
			return api_budget(pb, "dem-sessions", cfg->max_dem_sessions, 5);
		}
	} while (!atomic_compare_exchange_weak(&live, &n, n + 1));
	return API_OK;
}

api_err srv_dem_pick(srv_session *s, api_spec *spec, api_problem *pb)
{
	sim_feed_choice *pick = &s->pick;
	dem_bed_spec bed;
	dem_bed_spec_default(&spec->params, (double)spec->scene.layers, &bed);
	sim_feed_liggghts lg = {
		.available = bed_path[0] && access(bed_path, X_OK) == 0,
		.unavailable = "this daemon does not find its bed program convsim-bed (built "
			       "where LIGGGHTS is installed, or --dem-bed PATH)",
		.cost = dem_bed_spec_cost(&bed),
		.max_cost = cfg->max_dem_cost,
		.limit = "--max-dem-cost",
	};
	if (sim_feed_pick(&spec->params, &spec->scene, &lg, pick) != 0) {
		return api_fail_range(pb, "scene.model_tol",
				      isfinite(pick->min) ? pick->min : 0.0, 1.0, "%s", pick->why);
	}
	spec->scene.feed_model = pick->model;
	s->picked = 1;
	srv_log(SRV_LOG_INFO, "session %s: feed_model auto: %s", s->entry.id, pick->why);
	return API_OK;
}

void srv_dem_hold(void)
{
	atomic_fetch_add(&live, 1);
}

void srv_dem_release(void)
{
	atomic_fetch_sub(&live, 1);
}

int srv_dem_start(srv_session *s, int restored, char *msg, size_t msglen)
{
	const api_spec *sp = &s->spec;
	dem_bed_spec bed;
	dem_bed_spec_default(&sp->params, (double)sp->scene.layers, &bed);
	int left = 0;
	dem_feed *f = dem_feed_remote(bed_path, &bed, cfg->worker_nice, cfg->dem_ranks,
				      cfg->dem_timeout, restored ? -1 : s->create_fd, &left, msg,
				      msglen);
	if (!f)
		return left ? 1 : -1;
	s->dem.link = dem_coupled_attach(s->sim, 0, f, &sp->params, &sp->scene, 1,
				    sp->scene.transient, msg, msglen);
	if (!s->dem.link)
		return -1;
	s->dem.bed.resettled = restored;
	s->dem.cores = cfg->dem_ranks;
	srv_dem_read(s, &s->st, &s->dem.bed);
	srv_log(SRV_LOG_INFO, "session %s: bed process %ld, %d grains, %d rank%s%s", s->entry.id,
		dem_feed_pid(f), bed.grains, cfg->dem_ranks, cfg->dem_ranks > 1 ? "s" : "",
		restored ? ", settled anew at the restored time" : "");
	return 0;
}

int srv_dem_step(srv_session *s, double t_next, char *msg, size_t msglen)
{
	return dem_coupled_advance(s->dem.link, dem_coupled_interval_end(s->dem.link, t_next), NULL, msg,
				   msglen);
}

void srv_dem_controlled(srv_session *s, const sim_status *st)
{
	if (!s->dem.restart || st->beta != st->beta_target)
		return;
	s->dem.restart = 0;
	dem_coupled_restart_transport(s->dem.link);
}

void srv_dem_read(const srv_session *s, sim_status *st, api_bed *b)
{
	dem_coupled_status cs;
	dem_coupled_get(s->dem.link, &cs);
	/* the feed's figures are the bed's: its mean x and velocity relative
	 * to the deck, and the transport velocity fitted to its x */
	st->transport_velocity = cs.transport_velocity;
	st->transport_velocity_uncertainty = NAN;
	st->feed_displacement = cs.displacement;
	st->feed_velocity = cs.bed_velocity;
	int resettled = b->resettled;
	*b = (api_bed){
		.grains = cs.grains,
		.pid = dem_feed_pid(dem_coupled_bed(s->dem.link)),
		.interval = cs.interval,
		.intervals = cs.intervals,
		.displacement = cs.displacement,
		.velocity = cs.bed_velocity,
		.cpu_seconds = dem_coupled_bed(s->dem.link)->cpu,
		.weight = cs.weight,
		.load_mean_y = cs.load_mean_y,
		.work_machine = cs.work_machine,
		.work_bed = cs.work_bed,
		.bed_energy = cs.bed_energy,
		.resettled = resettled,
	};
}

void srv_dem_kill(srv_session *s)
{
	if (s->dem.link)
		dem_feed_kill(dem_coupled_bed(s->dem.link));
}

void srv_dem_free(srv_session *s)
{
	if (!s->dem.link)
		return;
	dem_coupled_free(s->dem.link); /* kills and reaps the bed process */
	s->dem.link = NULL;
}
