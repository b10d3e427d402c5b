/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * stream_json.c - text of the session streams and of the trajectory.
 *
 * Streams are numeric and hot: records are written straight into the
 * caller's reused buffer with snprintf, no tree and no allocation. A
 * record is either Server-Sent Events (id, event, data lines) or one
 * NDJSON line carrying "type" and "id". Doubles round-trip
 * (api_fmt_double). The trajectory is a downsampled table of
 * the trajectory columns of core/table.h, written as JSON or CSV.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "json_int.h"


/* Bounded writer into a fixed buffer. */
typedef struct writer {
	char *buf;
	size_t len, at;
} writer;

static void w_str(writer *w, const char *s)
{
	size_t n = strlen(s);
	if (w->at + n >= w->len)
		n = w->at + 1 < w->len ? w->len - w->at - 1 : 0;
	memcpy(w->buf + w->at, s, n);
	w->at += n;
	w->buf[w->at] = '\0';
}

static void w_num(writer *w, const char *name, double v)
{
	char num[48];
	w_str(w, ",\"");
	w_str(w, name);
	w_str(w, "\":");
	api_fmt_double(num, sizeof num, v);
	w_str(w, num);
}

static void w_array(writer *w, const char *name, const double *v, int n)
{
	char num[48];
	w_str(w, ",\"");
	w_str(w, name);
	w_str(w, "\":[");
	for (int i = 0; i < n; i++) {
		if (i)
			w_str(w, ",");
		api_fmt_double(num, sizeof num, v[i]);
		w_str(w, num);
	}
	w_str(w, "]");
}

static const struct {
	const char *name;
	unsigned bit;
} field_names[] = {
	{"trough", API_F_TROUGH},     {"orbit", API_F_ORBIT},
	{"rotor", API_F_ROTOR},       {"eliminators", API_F_ELIMINATORS},
	{"feed", API_F_FEED},         {"energy", API_F_ENERGY},
	{"elements", API_F_ELEMENTS}, {"all", API_F_ALL},
	{"default", API_F_DEFAULT},
};

unsigned api_parse_fields(const char *list, api_problem *pb)
{
	unsigned mask = 0;
	const char *p = list;
	while (p && *p) {
		const char *comma = strchr(p, ',');
		size_t n = comma ? (size_t)(comma - p) : strlen(p);
		unsigned bit = 0;
		for (size_t i = 0; i < sizeof field_names / sizeof *field_names;
		     i++)
			if (strlen(field_names[i].name) == n &&
			    strncmp(field_names[i].name, p, n) == 0)
				bit = field_names[i].bit;
		if (!bit) {
			api_fail(pb, API_QUERY, "fields",
				 "unknown field group \"%.*s\"; expected a "
				 "comma list of trough, orbit, rotor, "
				 "eliminators, feed, energy, elements, all",
				 (int)(n > 40 ? 40 : n), p);
			return 0;
		}
		mask |= bit;
		p = comma ? comma + 1 : NULL;
	}
	if (!mask)
		api_fail(pb, API_QUERY, "fields", "fields must not be empty");
	return mask;
}

size_t api_record_max(int columns, int layers)
{
	size_t values = (size_t)columns + 2 * (size_t)columns * (size_t)layers;
	return 2048 + API_EVENT_MAX + values * 26;
}

int api_record_numbers(unsigned fields, int columns, int layers)
{
	int n = 3; /* t, beta, beta_target */
	n += (fields & API_F_TROUGH) ? 6 : 0;
	n += (fields & API_F_ORBIT) ? 4 : 0;
	n += (fields & API_F_ROTOR) ? 5 : 0;
	n += (fields & API_F_ELIMINATORS) ? 4 : 0;
	n += (fields & API_F_FEED) ? 8 + columns : 0;
	n += (fields & API_F_ENERGY) ? 5 : 0;
	if ((fields & API_F_ELEMENTS) && columns > 0)
		n += 1 + 2 * columns * layers;
	return n;
}

/* The members of a sample, as api_record_numbers counts them. */
static void sample_body(writer *w, const api_sample *s, unsigned f)
{
	const sim_status *st = &s->st;
	w_num(w, "beta", api_user_of("beta", st->beta));
	w_num(w, "beta_target", api_user_of("beta", st->beta_target));
	if (f & API_F_TROUGH) {
		w_num(w, "x", st->q[0]);
		w_num(w, "y", st->q[1]);
		w_num(w, "alpha", st->q[2]);
		w_num(w, "vx", st->qd[0]);
		w_num(w, "vy", st->qd[1]);
		w_num(w, "valpha", st->qd[2]);
	}
	if (f & API_F_ORBIT) {
		w_num(w, "deck_x", st->deck[0]);
		w_num(w, "deck_y", st->deck[1]);
		w_num(w, "deck_vx", st->deck_vel[0]);
		w_num(w, "deck_vy", st->deck_vel[1]);
	}
	if (f & API_F_ROTOR) {
		w_num(w, "phi", st->q[3]);
		w_num(w, "rotor_speed", st->rotor_speed);
		w_num(w, "motor_torque", st->motor_torque);
		w_num(w, "power", st->power);
		w_num(w, "omega_ss", st->omega_ss);
		w_str(w, st->rotation == SIM_CW ? ",\"rotation\":\"cw\""
						: ",\"rotation\":\"ccw\"");
		w_str(w, st->drive_on ? ",\"drive_on\":true"
				      : ",\"drive_on\":false");
	}
	if (f & API_F_ELIMINATORS) {
		w_num(w, "s1", st->q[4]);
		w_num(w, "s2", st->q[5]);
		w_num(w, "s1_dot", st->qd[4]);
		w_num(w, "s2_dot", st->qd[5]);
	}
	if (f & API_F_FEED) {
		w_num(w, "feed_displacement", st->feed_displacement);
		w_num(w, "feed_velocity", st->feed_velocity);
		w_num(w, "transport_velocity", st->transport_velocity);
		w_num(w, "transport_velocity_uncertainty",
		      st->transport_velocity_uncertainty);
		w_str(w, st->steady ? ",\"steady\":true" : ",\"steady\":false");
		w_num(w, "step_error", st->step_error);
		w_str(w, st->tol_met ? ",\"tol_met\":true" : ",\"tol_met\":false");
		w_num(w, "dt", st->dt);
		w_num(w, "substeps", st->substeps);
		w_array(w, "columns", s->column_disp, s->columns);
	}
	if (f & API_F_ENERGY) {
		w_num(w, "e_input", st->e_input);
		w_num(w, "e_kinetic", st->e_kinetic);
		w_num(w, "e_potential", st->e_potential);
		w_num(w, "e_dissipated", st->e_dissipated);
		w_num(w, "e_residual", st->e_residual);
	}
	if ((f & API_F_ELEMENTS) && s->columns > 0) {
		int n = s->columns * s->layers;
		w_num(w, "layers", s->layers);
		w_array(w, "xi", s->xi, n);
		w_array(w, "eta", s->eta, n);
	}
}

size_t api_format_record(char *buf, size_t len, const api_sample *s,
			 unsigned fields, int ndjson)
{
	writer w = {buf, len, 0};
	char head[96], num[48];
	const char *type = s->kind == API_REC_EVENT ? s->event_type : "sample";
	if (!len)
		return 0;
	buf[0] = '\0';
	if (ndjson) {
		snprintf(head, sizeof head, "{\"type\":\"%s\",\"id\":%llu", type,
			 (unsigned long long)s->index);
	} else {
		snprintf(head, sizeof head, "id: %llu\nevent: %s\ndata: {",
			 (unsigned long long)s->index, type);
	}
	w_str(&w, head);
	if (s->kind == API_REC_EVENT) {
		/* splice the event object's members in after our head */
		const char *inner = strchr(s->event, '{');
		inner = inner ? inner + 1 : "}";
		while (*inner == ' ')
			inner++;
		if (!ndjson) {
			w_str(&w, inner);
		} else {
			if (*inner != '}')
				w_str(&w, ",");
			w_str(&w, inner);
		}
	} else {
		api_fmt_time(num, sizeof num, s->st.t);
		w_str(&w, ndjson ? ",\"t\":" : "\"t\":");
		w_str(&w, num);
		sample_body(&w, s, fields);
		w_str(&w, "}");
	}
	w_str(&w, ndjson ? "\n" : "\n\n");
	return w.at;
}

size_t api_format_hello(char *buf, size_t len, const char *session, uint64_t next_id,
			const char *feed_warning, const sim_model_error *me, int ndjson)
{
	api_buf b = {0};
	api_buf_puts(&b, ndjson ? "{\"type\":\"hello\",\"session\":"
				: "retry: 1000\nevent: hello\ndata: {\"session\":");
	api_buf_jstr(&b, session);
	api_buf_printf(&b, ",\"next_id\":%llu,\"feed_warning\":", (unsigned long long)next_id);
	if (feed_warning)
		api_buf_jstr(&b, feed_warning);
	else
		api_buf_puts(&b, "null");
	if (me) {
		char num[40];
		api_fmt_double(num, sizeof num, me->checked ? me->error : NAN);
		api_buf_printf(&b, ",\"model_error\":%s", num);
		api_fmt_double(num, sizeof num, me->checked ? me->error_uncertainty : NAN);
		api_buf_printf(&b, ",\"model_error_uncertainty\":%s,\"model_checked\":%s,"
				   "\"model_check_note\":",
			       num, me->checked ? "true" : "false");
		api_buf_jstr(&b, me->note);
	}
	api_buf_puts(&b, ndjson ? "}\n" : "}\n\n");
	char *text = api_buf_take(&b);
	size_t n = text ? strlen(text) : 0;
	if (n >= len)
		n = 0;
	memcpy(buf, text ? text : "", n);
	if (len)
		buf[n] = '\0';
	free(text);
	return n;
}

size_t api_format_dropped(char *buf, size_t len, uint64_t missed,
			  uint64_t next_id, int ndjson)
{
	int n = snprintf(buf, len,
			 ndjson ? "{\"type\":\"dropped\",\"missed\":%llu,"
				  "\"next_id\":%llu}\n"
				: "event: dropped\ndata: {\"missed\":%llu,"
				  "\"next_id\":%llu}\n\n",
			 (unsigned long long)missed,
			 (unsigned long long)next_id);
	return n < 0 ? 0 : (size_t)n;
}

size_t api_format_heartbeat(char *buf, size_t len, double t, int ndjson)
{
	char num[48];
	api_fmt_time(num, sizeof num, t);
	int n = snprintf(buf, len,
			 ndjson ? "{\"type\":\"heartbeat\",\"t\":%s}\n"
				: ": heartbeat t=%s\n\n",
			 num);
	return n < 0 ? 0 : (size_t)n;
}

size_t api_format_end(char *buf, size_t len, const char *reason, int ndjson)
{
	int n = snprintf(buf, len,
			 ndjson ? "{\"type\":\"end\",\"reason\":\"%s\"}\n"
				: "event: end\ndata: {\"reason\":\"%s\"}\n\n",
			 reason);
	return n < 0 ? 0 : (size_t)n;
}

/* ---- trajectory ------------------------------------------------------ */

void api_history_row(const sim_status *st, const double *column_disp, int columns,
		     double *row)
{
	sim_trajectory_row(st, row);
	for (int k = 0; k < columns; k++)
		row[SIM_TRAJECTORY_NAMED + k] = column_disp[k];
}

/* Column c's name (column_1 ... past the named ones). */
static void put_column_name(api_buf *b, int c, int quoted)
{
	char name[32];
	if (c < SIM_TRAJECTORY_NAMED)
		snprintf(name, sizeof name, "%s", sim_trajectory_name(c));
	else
		snprintf(name, sizeof name, "column_%d", c - SIM_TRAJECTORY_NAMED + 1);
	if (quoted)
		api_buf_jstr(b, name);
	else
		api_buf_puts(b, name);
}

char *api_trajectory_json(const double *rows, size_t n, int columns, double stride)
{
	api_buf b = {0};
	int width = (int)API_HISTORY_WIDTH(columns);
	api_buf_puts(&b, "{\"fields\":[");
	for (int c = 0; c < width; c++) {
		if (c)
			api_buf_put(&b, ",", 1);
		put_column_name(&b, c, 1);
	}
	api_buf_puts(&b, "],\"units\":[");
	for (int c = 0; c < width; c++) {
		if (c)
			api_buf_put(&b, ",", 1);
		api_buf_jstr(&b, c < SIM_TRAJECTORY_NAMED ? sim_trajectory_unit(c) : "m");
	}
	api_buf_printf(&b, "],\"count\":%zu,\"stride\":", n);
	api_buf_double(&b, stride);
	api_buf_puts(&b, ",\"rows\":[");
	for (size_t i = 0; i < n; i++) {
		api_buf_puts(&b, i ? ",[" : "[");
		for (int c = 0; c < width; c++) {
			if (c)
				api_buf_put(&b, ",", 1);
			api_buf_double(&b, rows[i * (size_t)width + (size_t)c]);
		}
		api_buf_put(&b, "]", 1);
	}
	api_buf_puts(&b, "]}");
	return api_buf_take(&b);
}

char *api_trajectory_csv(const double *rows, size_t n, int columns)
{
	api_buf b = {0};
	int width = (int)API_HISTORY_WIDTH(columns);
	for (int c = 0; c < width; c++) {
		api_buf_puts(&b, c ? "," : "");
		put_column_name(&b, c, 0);
	}
	api_buf_put(&b, "\n", 1);
	for (size_t i = 0; i < n; i++) {
		for (int c = 0; c < width; c++) {
			if (c)
				api_buf_put(&b, ",", 1);
			double v = rows[i * (size_t)width + (size_t)c];
			if (isfinite(v))
				api_buf_double(&b, v);
		}
		api_buf_put(&b, "\n", 1);
	}
	return api_buf_take(&b);
}
