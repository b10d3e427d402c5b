/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_json.c - sessions in JSON: the session document (spec and live
 * status) that GET, POST and PATCH answer. The PATCH body is control.c's.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"
#include "table.h"

static void put_pace(cJSON *o, const char *name, double pace)
{
	if (pace == API_PACE_MAX)
		cJSON_AddStringToObject(o, name, "max");
	else
		api_add_number(o, name, pace);
}

static cJSON *status_object(const api_view *v)
{
	const sim_status *st = &v->st;
	cJSON *o = cJSON_CreateObject();
	api_add_number(o, "t", sim_time_ns(st->t));
	api_add_number(o, "t_integrator", sim_time_ns(st->t_int));
	api_add_number(o, "beta", api_user_of("beta", st->beta));
	api_add_number(o, "beta_target", api_user_of("beta", st->beta_target));
	api_add_number(o, "beta_dot", api_user_of("beta_rate", st->beta_dot));
	cJSON_AddStringToObject(o, "rotation",
				st->rotation == SIM_CW ? "cw" : "ccw");
	cJSON_AddBoolToObject(o, "drive_on", st->drive_on);
	api_add_number(o, "omega_ss", st->omega_ss);
	api_add_number(o, "m_n", st->m_n);
	api_add_number(o, "mu", st->mu);
	api_add_number(o, "rotor_speed", st->rotor_speed);
	api_add_number(o, "motor_torque", st->motor_torque);
	api_add_number(o, "power", st->power);
	/* means over the transport estimate's whole periods (null before one) */
	api_add_number(o, "rotor_speed_mean", st->rotor_speed_mean);
	api_add_number(o, "motor_torque_mean", st->motor_torque_mean);
	api_add_number(o, "power_mean", st->power_mean);
	api_add_number(o, "transport_velocity", st->transport_velocity);
	api_add_number(o, "transport_velocity_uncertainty",
		       st->transport_velocity_uncertainty);
	cJSON_AddBoolToObject(o, "steady", st->steady);
	api_add_number(o, "step_error", st->step_error);
	api_add_number(o, "tol", st->tol);
	cJSON_AddBoolToObject(o, "tol_met", st->tol_met);
	api_add_number(o, "transport_periods", st->transport_periods);
	api_add_number(o, "feed_velocity", st->feed_velocity);
	api_add_number(o, "feed_displacement", st->feed_displacement);
	api_add_number(o, "period", st->period);
	api_add_number(o, "steps", (double)st->steps);
	api_add_number(o, "rhs_evals", (double)st->rhs_evals);
	api_add_number(o, "dt", st->dt);
	cJSON_AddNumberToObject(o, "substeps", st->substeps);
	api_add_number(o, "steps_per_s", v->steps_per_s);
	api_add_number(o, "rtf", v->rtf);
	cJSON_AddNumberToObject(o, "n_dof", st->n_dof);
	cJSON *red = cJSON_AddArrayToObject(o, "reductions");
	cJSON *fig = cJSON_AddArrayToObject(o, "reduction_figures");
	for (int b = 0; sim_reduction(b); b++) {
		if (!(st->reductions & (1u << b)))
			continue;
		const sim_reduction_info *r = sim_reduction(b);
		cJSON_AddItemToArray(red, cJSON_CreateString(r->name));
		cJSON *f = cJSON_CreateObject();
		cJSON_AddStringToObject(f, "name", r->name);
		cJSON_AddStringToObject(f, "drops", r->drops);
		api_add_number(f, "speedup", r->speedup);
		api_add_number(f, "error", r->v_error);
		cJSON_AddItemToArray(fig, f);
	}
	/* how far the column model is from a DEM bed at the scene as its
	 * controls now stand (docs/dem.md "Model error"); feed_warning is the
	 * note where the scene is not checked */
	sim_model_error me;
	int mc = api_model_check(v->spec, st, &me);
	api_add_model_error(o, &me);
	if (mc == 0)
		cJSON_AddStringToObject(o, "feed_warning", me.note);
	else
		cJSON_AddNullToObject(o, "feed_warning");
	cJSON *en = cJSON_AddObjectToObject(o, "energy");
	api_add_number(en, "input", st->e_input);
	api_add_number(en, "kinetic", st->e_kinetic);
	api_add_number(en, "potential", st->e_potential);
	api_add_number(en, "dissipated", st->e_dissipated);
	api_add_number(en, "residual", st->e_residual);
	/* the part of input the feed's disturbances brought (sim_set_feed) */
	api_add_number(en, "disturbance", st->e_disturb);
	return o;
}

/* The settings of sp by group: params, scene, integrator. */
static void add_settings(cJSON *o, const api_spec *sp)
{
	static const char *const groups[] = {"params", "scene", "integrator"};
	for (size_t g = 0; g < sizeof groups / sizeof *groups; g++)
		cJSON_AddItemToObject(o, groups[g],
				      api_settings_object(&sp->params, &sp->scene,
							  &sp->method, groups[g]));
}

/* feed_model auto's pick: {model, why, expected_cpu_s_per_s}. */
static cJSON *pick_object(const sim_feed_choice *k)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "model", k->model == SIM_FEED_EXTERNAL ? "liggghts" : "column");
	cJSON_AddStringToObject(o, "why", k->why);
	api_add_number(o, "expected_cpu_s_per_s", k->expected_cpu_s_per_s);
	return o;
}

/* pick_object's member of o back into *k: 1, or 0 if absent or not one. */
static int read_pick(const cJSON *o, sim_feed_choice *k)
{
	const cJSON *p = cJSON_GetObjectItemCaseSensitive(o, "feed_model_pick");
	const cJSON *m = cJSON_GetObjectItemCaseSensitive(p, "model");
	const cJSON *w = cJSON_GetObjectItemCaseSensitive(p, "why");
	const cJSON *c = cJSON_GetObjectItemCaseSensitive(p, "expected_cpu_s_per_s");
	if (!cJSON_IsString(m) || !cJSON_IsString(w) || !(cJSON_IsNumber(c) || cJSON_IsNull(c)))
		return 0;
	int column = strcmp(m->valuestring, "column") == 0;
	if (!column && strcmp(m->valuestring, "liggghts") != 0)
		return 0;
	memset(k, 0, sizeof *k);
	k->model = column ? SIM_FEED_COLUMN : SIM_FEED_EXTERNAL;
	k->min = NAN;
	k->expected_cpu_s_per_s = cJSON_IsNumber(c) ? c->valuedouble : NAN;
	snprintf(k->why, sizeof k->why, "%s", w->valuestring);
	return 1;
}

char *api_spec_file(const api_spec *spec, double created, int owned,
		    const sim_feed_choice *pick)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "format", API_SPEC_FILE_FORMAT);
	api_add_number(o, "created", created);
	cJSON_AddBoolToObject(o, "owned", owned);
	cJSON *body = cJSON_AddObjectToObject(o, "session");
	cJSON_AddStringToObject(body, "preset", spec->preset);
	put_pace(body, "pace", spec->pace);
	if (spec->until > 0)
		api_add_number(body, "until", spec->until);
	else
		cJSON_AddNullToObject(body, "until");
	api_add_number(body, "sample_rate", spec->sample_rate);
	add_settings(body, spec);
	if (pick)
		cJSON_AddItemToObject(o, "feed_model_pick", pick_object(pick));
	return api_print_free(o);
}

api_err api_parse_spec_file(const char *text, size_t len, api_spec *spec,
			    double *created, int *owned, int *format, sim_feed_choice *pick,
			    int *picked, api_problem *pb)
{
	cJSON *o = cJSON_ParseWithLength(text, len);
	const cJSON *f = cJSON_GetObjectItemCaseSensitive(o, "format");
	*format = f ? -1 : 1; /* format 1 had no member */
	/* an int before the cast (1e300 is none) */
	if (cJSON_IsNumber(f) && fabs(f->valuedouble) < 1e9 && f->valuedouble == (int)f->valuedouble)
		*format = (int)f->valuedouble;
	if (*format < 1 || *format > API_SPEC_FILE_FORMAT) {
		int n = *format;
		cJSON_Delete(o);
		if (n > API_SPEC_FILE_FORMAT)
			return api_fail(pb, API_MALFORMED, "format", "format %d, a newer build's "
					"(this one reads 1 to %d)", n, API_SPEC_FILE_FORMAT);
		return api_fail(pb, API_MALFORMED, "format", "format is not a format number "
				"(1 to %d)", API_SPEC_FILE_FORMAT);
	}
	const cJSON *c = cJSON_GetObjectItemCaseSensitive(o, "created");
	const cJSON *w = cJSON_GetObjectItemCaseSensitive(o, "owned");
	const cJSON *b = cJSON_GetObjectItemCaseSensitive(o, "session");
	/* created finite: written again, an infinite one (1e999) would be null */
	int inf = cJSON_IsNumber(c) && !isfinite(c->valuedouble);
	char *body = cJSON_IsNumber(c) && !inf && cJSON_IsBool(w) && cJSON_IsObject(b)
			     ? api_print(b)
			     : NULL;
	*created = cJSON_IsNumber(c) ? c->valuedouble : 0;
	*owned = cJSON_IsTrue(w);
	*picked = read_pick(o, pick);
	cJSON_Delete(o);
	if (inf)
		return api_fail(pb, API_MALFORMED, "created", "created is no finite time (unix s)");
	if (!body)
		return api_fail(pb, API_MALFORMED, NULL, "not a session's spec "
				"(created, owned and session expected)");
	api_err e = api_parse_session(body, strlen(body), spec, pb);
	free(body);
	return e;
}

/* A LIGGGHTS session's bed process and the balances between it and the
 * machine. */
static cJSON *bed_object(const api_bed *b)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddNumberToObject(o, "grains", b->grains);
	api_add_number(o, "pid", (double)b->pid);
	api_add_number(o, "coupling_interval", b->interval);
	api_add_number(o, "intervals", (double)b->intervals);
	api_add_number(o, "displacement", b->displacement);
	api_add_number(o, "velocity", b->velocity);
	api_add_number(o, "cpu_seconds", b->cpu_seconds);
	cJSON *bal = cJSON_AddObjectToObject(o, "balance");
	api_add_number(bal, "weight", b->weight);
	api_add_number(bal, "load_mean_y", b->load_mean_y);
	api_add_number(bal, "work_machine", b->work_machine);
	api_add_number(bal, "work_bed", b->work_bed);
	api_add_number(bal, "bed_energy", b->bed_energy);
	return o;
}

static cJSON *session_object(const api_view *v, int with_spec)
{
	cJSON *o = cJSON_CreateObject();
	char link[96];
	cJSON_AddStringToObject(o, "id", v->id);
	cJSON_AddStringToObject(o, "state", v->state);
	if (v->error[0])
		cJSON_AddStringToObject(o, "error", v->error);
	api_add_number(o, "created", v->created);
	cJSON_AddStringToObject(o, "preset", v->spec->preset);
	put_pace(o, "pace", v->pace);
	if (v->until > 0)
		api_add_number(o, "until", v->until);
	else
		cJSON_AddNullToObject(o, "until");
	api_add_number(o, "sample_rate", v->spec->sample_rate);
	cJSON_AddNumberToObject(o, "columns", v->columns);
	cJSON_AddNumberToObject(o, "layers", v->layers);
	api_add_number(o, "samples", (double)v->samples);
	cJSON_AddNumberToObject(o, "streams", v->streams);
	api_add_number(o, "cpu_seconds", v->cpu_seconds);
	api_add_number(o, "cpu_limit", v->cpu_limit);
	if (v->pause_reason)
		cJSON_AddStringToObject(o, "pause_reason", v->pause_reason);
	else
		cJSON_AddNullToObject(o, "pause_reason");
	cJSON_AddBoolToObject(o, "waiting_for_cpu", v->waiting_for_cpu);
	if (v->replayed) {
		cJSON_AddStringToObject(o, "restored", "replayed");
		api_add_number(o, "replay_seconds", v->replay_seconds);
	} else if (v->has_bed && v->bed.resettled) {
		cJSON_AddStringToObject(o, "restored", "bed_resettled");
	}
	if (v->has_bed)
		cJSON_AddItemToObject(o, "bed", bed_object(&v->bed));
	if (v->pick) /* feed_model auto: what it took and why */
		cJSON_AddItemToObject(o, "feed_model_pick", pick_object(v->pick));
	if (v->experiment[0])
		cJSON_AddStringToObject(o, "experiment", v->experiment);
	else
		cJSON_AddNullToObject(o, "experiment");
	if (v->has_status)
		cJSON_AddItemToObject(o, "status", status_object(v));
	else
		cJSON_AddNullToObject(o, "status");
	cJSON *links = cJSON_AddObjectToObject(o, "links");
	snprintf(link, sizeof link, "/api/v1/sessions/%s", v->id);
	cJSON_AddStringToObject(links, "self", link);
	snprintf(link, sizeof link, "/api/v1/sessions/%s/stream", v->id);
	cJSON_AddStringToObject(links, "stream", link);
	snprintf(link, sizeof link, "/api/v1/sessions/%s/trajectory", v->id);
	cJSON_AddStringToObject(links, "trajectory", link);
	if (with_spec)
		add_settings(cJSON_AddObjectToObject(o, "spec"), v->spec);
	return o;
}

char *api_session_json(const api_view *v, int with_spec)
{
	return api_print_free(session_object(v, with_spec));
}

/* A listing's entry. */
static cJSON *session_entry(const void *view)
{
	return session_object(view, 0);
}

char *api_session_list_json(const api_view *v, size_t n)
{
	return api_list_json("sessions", v, n, sizeof *v, session_entry);
}

char *api_control_result_json(const api_view *v, const api_control *c,
			      int acked, double t_effective)
{
	cJSON *o = session_object(v, 0);
	cJSON_AddItemToObject(o, "applied", api_control_object(c));
	cJSON_AddBoolToObject(o, "acknowledged", acked);
	if (acked)
		api_add_number(o, "t_effective", sim_time_ns(t_effective));
	else
		cJSON_AddNullToObject(o, "t_effective");
	return api_print_free(o);
}

char *api_session_csv(const api_view *v, size_t n)
{
	api_buf b = {0};
	api_buf_puts(&b, "id,state");
	for (int c = 0; c < SIM_TRAJECTORY_NAMED; c++)
		api_buf_printf(&b, ",%s", sim_trajectory_name(c));
	api_buf_puts(&b, ",steady,transport_periods,rotor_speed_mean,motor_torque_mean,"
			 "power_mean\n");
	for (size_t i = 0; i < n; i++) {
		const sim_status *st = &v[i].st;
		double row[SIM_TRAJECTORY_NAMED];
		api_buf_printf(&b, "%s,%s", v[i].id, v[i].state);
		sim_trajectory_row(st, row);
		const double means[] = {st->transport_periods, st->rotor_speed_mean,
					st->motor_torque_mean, st->power_mean};
		for (int c = 0; c < SIM_TRAJECTORY_NAMED; c++) {
			api_buf_put(&b, ",", 1);
			if (v[i].has_status && isfinite(row[c]))
				api_buf_double(&b, row[c]);
		}
		api_buf_puts(&b, !v[i].has_status ? "," : st->steady ? ",true" : ",false");
		for (int c = 0; c < 4; c++) {
			api_buf_put(&b, ",", 1);
			if (v[i].has_status && isfinite(means[c]))
				api_buf_double(&b, means[c]);
		}
		api_buf_put(&b, "\n", 1);
	}
	return api_buf_take(&b);
}
