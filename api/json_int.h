/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * json_int.h - helpers shared inside api/ (not for the server): an exact
 * printer for cJSON trees, a growable text buffer, and the lookups that
 * tie JSON members to the core's settings table.
 */
#ifndef CONVSIM_API_JSON_INT_H
#define CONVSIM_API_JSON_INT_H

#include <cjson/cJSON.h>
#include <stddef.h>

#include "api.h"

/* Growable text; on allocation failure `failed` is set and appends stop. */
typedef struct api_buf {
	char *text;
	size_t len, cap;
	int failed;
} api_buf;

void api_buf_put(api_buf *b, const char *s, size_t n);
void api_buf_puts(api_buf *b, const char *s);
void api_buf_printf(api_buf *b, const char *fmt, ...)
	__attribute__((format(printf, 2, 3)));
void api_buf_double(api_buf *b, double v);
/* A JSON string literal, escaped. */
void api_buf_jstr(api_buf *b, const char *s);
/* Hand over the text (NULL if any append failed; then it is freed). */
char *api_buf_take(api_buf *b);

/* Print a cJSON tree compactly with exact doubles (null if not finite).
 * malloc'd text, NULL when out of memory. Does not free the tree. */
char *api_print(const cJSON *item);
/* Print and free the tree; NULL when tree is NULL or out of memory. */
char *api_print_free(cJSON *item);

/* The prologue of every body parser (body.c): parse len bytes as one JSON
 * object whose members are all among the NULL-terminated names. Returns
 * the tree (caller deletes it) or NULL with *pb set: 400 empty, blank,
 * malformed or not an object, 422 unknown member. */
cJSON *api_parse_body(const char *body, size_t len, const char *const *members,
		      api_problem *pb);

/* Length of the valid UTF-8 sequence at s of at most avail bytes (RFC
 * 3629: no overlong forms, no surrogates, nothing above U+10FFFF), 0 if
 * the bytes there are not one. */
size_t api_utf8_seq(const unsigned char *s, size_t avail);
/* Check len bytes of text against RFC 8259 and I-JSON (RFC 7493): the
 * grammar (no `01`, no `1.`), no raw control byte or invalid UTF-8 in a
 * string, no unpaired surrogate escape, no member name twice in one
 * object. API_OK, or API_MALFORMED (400) with *pb naming the byte where
 * it goes wrong (pb->position) and the duplicated name as the field. */
api_err api_json_check(const char *text, size_t len, api_problem *pb);

/* The settings-table entry of name in group, or NULL. */
const sim_setting *api_setting(const char *group, const char *name);
/* Apply one JSON member to the settings of its group ("params", "scene",
 * "integrator"), by its kind: numbers, booleans and enum strings. The
 * problem names the field as "group.name". */
api_err api_apply_setting(sim_params *p, sim_scene *s, sim_method *m,
			  const char *group, const cJSON *item,
			  api_problem *pb);
/* A value of setting name given in its user unit (the settings table's
 * unit: beta in deg), checked against spec's settings with sim_set on a
 * scratch copy (so range and message are the core's) and converted to SI
 * once, here: *out gets both. field is the member's JSON path for the
 * problem (the detail is prefixed with it when it differs from name). */
api_err api_user_value(const api_spec *spec, const char *name, double user,
		       const char *field, api_value *out, api_problem *pb);
/* The same for a JSON member, which must be a number (400 otherwise). */
api_err api_parse_user_value(const api_spec *spec, const char *name,
			     const cJSON *it, const char *field,
			     api_value *out, api_problem *pb);
/* An SI value of setting name in its user unit, for answers (the table's
 * scale, to 15 significant digits when it is not 1, so that 60 deg sent
 * is 60 shown; unchanged for an unknown name). */
double api_user_of(const char *name, double si);
/* Apply preset/params/scene/integrator members of obj (others ignored)
 * to *spec, starting from the preset (default czubak2016). */
api_err api_apply_model(const cJSON *obj, api_spec *spec, api_problem *pb);
/* The settings of one group with their current values as a JSON object. */
cJSON *api_settings_object(const sim_params *p, const sim_scene *s,
			   const sim_method *m, const char *group);
/* pace: a real-time factor in [0.001, 1000] or "max" (API_PACE_MAX). */
api_err api_parse_pace(const cJSON *it, const char *field, double *pace,
		       api_problem *pb);
/* A number within [lo, hi]; null gives 0 when null_ok. */
api_err api_parse_real(const cJSON *it, const char *field, double lo,
		       double hi, int null_ok, double *out, api_problem *pb);
/* pace, until, sample_rate of a session body, with their defaults. */
api_err api_apply_session_extras(const cJSON *root, api_spec *spec,
				 api_problem *pb);
/* Every member of obj must be one of the NULL-terminated names (422
 * naming prefix + member otherwise). body.c. */
api_err api_check_members(const cJSON *obj, const char *const *names,
			  const char *prefix, api_problem *pb);
/* obj must be an object (else a 400 for field: "NAME must be expected",
 * NAME being prefix without its final dot) of the names, as
 * api_check_members. body.c. */
api_err api_check_object(const cJSON *obj, const char *field, const char *prefix,
			 const char *expected, const char *const *names, api_problem *pb);
/* The varied settings of a sweep request (study_json.c): "vary", "lhs"
 * and "seed" members (each may be NULL) into req's points (nbeta,
 * betas, nvary, vary, values, lhs, seed); req->betas, when set, is the
 * "beta" member's grid, varied first. Needs req->spec and req->nrot. */
api_err api_parse_study(const cJSON *vary, const cJSON *lhs, const cJSON *seed,
			api_sweep_req *req, api_problem *pb);
/* sim_validate on the spec of a sweep, fit or experiment, as a 422
 * problem: feed_model column only (a session may take liggghts). */
api_err api_validate_spec(api_spec *spec, api_problem *pb);
/* The settings table as a JSON array of {name, group, kind, unit,
 * min, max | choices, doc}. */
cJSON *api_settings_array(void);
/* Add a number member; non-finite values become null. */
void api_add_number(cJSON *obj, const char *name, double v);
/* Add model_error, model_error_uncertainty (m/s, null unless checked),
 * model_checked and model_check_note (sim_model_check) to o. */
void api_add_model_error(cJSON *o, const sim_model_error *me);
/* The same as CSV cells (SIM_MODEL_ERROR_COLUMNS), each after a comma;
 * three empty cells where me is NULL (not known). */
void api_buf_model_error(api_buf *b, const sim_model_error *me);
/* Add "links": {"self": "/api/v1/COLLECTION/ID", "csv": the same with
 * ?format=csv} (a job's result, as JSON and as CSV). */
void api_add_result_links(cJSON *obj, const char *collection, const char *id);
/* One listing: {"member": [entry(view 0), ..., entry(view n - 1)]} of n
 * views of size bytes each (list_json.c). malloc'd text. */
char *api_list_json(const char *member, const void *views, size_t n, size_t size,
		    cJSON *(*entry)(const void *view));

/* The members each request body may have (NULL-terminated): the parsers
 * refuse any other, and openapi.c builds the request schemas from these
 * very lists. */
extern const char *const api_members_session_create[];
extern const char *const api_members_control[];
/* The control c as the object PATCH answers under "applied" and the
 * control event carries (control.c; the caller owns it). */
cJSON *api_control_object(const api_control *c);
extern const char *const api_members_experiment[];
extern const char *const api_members_experiment_session[];
extern const char *const api_members_segment[];
extern const char *const api_members_identify[];
extern const char *const api_members_exp_control[];
extern const char *const api_members_setpoint[];
extern const char *const api_members_controller[];
extern const char *const api_members_disturbance[];
/* The kind members of an experiment body (experiment_kind_json.c):
 * "identify", or "control" with "disturbances", into *ext and the schedule
 * they make in *req (identify: API_EXP_ID_SEGS segments per point; control:
 * one per setpoint, its beta filled by the server from the v(beta) curve).
 * API_OK with ext->kind API_EXP_SCHEDULE when root has neither. */
api_err api_parse_experiment_kind(const cJSON *root, api_experiment_req *req,
				  api_exp_ext *ext, api_problem *pb);
/* The kind's results into the experiment's JSON object o. */
void api_add_experiment_kind(cJSON *o, const api_exp_ext *ext, int nseg);
extern const char *const api_members_sweep[];
extern const char *const api_members_beta_range[];
extern const char *const api_members_fit[];
extern const char *const api_members_fit_free[];
extern const char *const api_members_fit_prior[];
extern const char *const api_members_fit_point[];
extern const char *const api_members_fit_peak[];

#endif
