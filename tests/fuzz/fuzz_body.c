/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * fuzz_body.c - libFuzzer harness of the JSON request bodies: the bytes
 * are a request body handed to the API's real parser, as the server hands
 * it (api/body.c's prologue, then the member parsers and the settings
 * table's checks). A refused body must give a well-formed problem
 * (fuzz_check_problem); an accepted one must survive a round trip: what
 * it parsed to, written back as JSON by the API's own writers (the session
 * document, the control event, the experiment and sweep documents) and
 * parsed again, is the same request.
 *
 * One binary per body: the Makefile builds this file with -DFUZZ_BODY=
 * "session" (etc.); a new body is one row of bodies[] below and one word
 * of FUZZ_BODIES in the Makefile.
 */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fuzz_util.h"
#include "units.h"

#ifndef FUZZ_BODY
#error "build with -DFUZZ_BODY='\"session\"' (or control, experiment, sweep)"
#endif

/* POST /sessions. */
static void session_body(const char *body, size_t len)
{
	api_spec spec, again;
	api_problem pb;
	api_err e = api_parse_session(body, len, &spec, &pb);
	if (e != API_OK) {
		fuzz_check_problem(e, &pb);
		return;
	}
	char *text = fuzz_print(fuzz_spec_body(&spec, 1));
	e = api_parse_session(text, strlen(text), &again, &pb);
	FUZZ_CHECK(e == API_OK, "session written back is refused: %s\n%s", pb.detail, text);
	fuzz_same_spec(&spec, &again, 1, "session");
	free(text);
}

static int same_control(const api_control *a, const api_control *b)
{
	if (a->set != b->set)
		return 0;
	return (!(a->set & API_C_BETA) || (a->beta.si == b->beta.si && a->beta.user == b->beta.user)) &&
	       (!(a->set & API_C_BETA_RATE) ||
		(a->beta_rate.si == b->beta_rate.si && a->beta_rate.user == b->beta_rate.user)) &&
	       (!(a->set & API_C_ROTATION) || a->rotation == b->rotation) &&
	       (!(a->set & API_C_OMEGA_SS) || a->omega_ss == b->omega_ss) &&
	       (!(a->set & API_C_RUNNING) || a->running == b->running) &&
	       (!(a->set & API_C_MOTOR) || a->motor_on == b->motor_on) &&
	       (!(a->set & API_C_PACE) || a->pace == b->pace) &&
	       (!(a->set & API_C_UNTIL) || a->until == b->until);
}

/* PATCH /sessions/{id}, against a default session; written back through
 * the control event the stream and controls.ndjson carry. */
static void control_body(const char *body, size_t len)
{
	const api_spec *spec = fuzz_default_spec();
	api_control c, again;
	api_problem pb;
	api_err e = api_parse_control(body, len, spec, &c, &pb);
	if (e != API_OK) {
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(c.set != 0, "an accepted control changes nothing");
	char event[API_EVENT_MAX];
	int n = api_control_event(event, sizeof event, &c, 1.5);
	FUZZ_CHECK(n > 0 && (size_t)n < sizeof event, "control event of %d bytes", n);
	cJSON *o = cJSON_Parse(event);
	FUZZ_CHECK(cJSON_IsObject(o), "control event is not JSON: %s", event);
	const cJSON *te = cJSON_GetObjectItemCaseSensitive(o, "t_effective");
	FUZZ_CHECK(cJSON_IsNumber(te) && te->valuedouble == 1.5, "t_effective: %s", event);
	cJSON_DeleteItemFromObjectCaseSensitive(o, "t_effective");
	char *text = fuzz_print(o);
	e = api_parse_control(text, strlen(text), spec, &again, &pb);
	FUZZ_CHECK(e == API_OK, "control written back is refused: %s\n%s", pb.detail, text);
	FUZZ_CHECK(same_control(&c, &again), "control differs after the round trip: %s", text);
	free(text);
}

/* A line of a session's controls.ndjson as a restore reads it back to
 * replay it (api_parse_control_event, against a default session):
 * written again with the log's own writer, it parses to the same control,
 * time and experiment. */
static void controlline_body(const char *line, size_t len)
{
	const api_spec *spec = fuzz_default_spec();
	api_control c, again;
	double t, t2;
	char exp[64], exp2[64];
	api_problem pb;
	api_err e = api_parse_control_event(line, len, spec, &c, &t, exp, sizeof exp, &pb);
	if (e != API_OK) {
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(c.set != 0 && isfinite(t), "an accepted log line changes nothing, or at %g", t);
	char text[API_EVENT_MAX];
	int n = api_control_log_line(text, sizeof text, &c, t, exp);
	FUZZ_CHECK(n > 0 && (size_t)n < sizeof text - 1, "a log line of %d bytes", n);
	e = api_parse_control_event(text, (size_t)n, spec, &again, &t2, exp2, sizeof exp2, &pb);
	FUZZ_CHECK(e == API_OK, "a log line written again is refused: %s\n%s", pb.detail, text);
	FUZZ_CHECK(same_control(&c, &again) && t2 == sim_time_ns(t) && strcmp(exp, exp2) == 0,
		   "a log line differs written again: %s", text);
}

/* The request written back: the schedule from the experiment document,
 * the session as an id or as the create body of its spec. */
static char *experiment_text(const api_experiment_req *req)
{
	api_experiment_view v;
	memset(&v, 0, sizeof v);
	snprintf(v.id, sizeof v.id, "fedcba9876543210");
	snprintf(v.session_id, sizeof v.session_id, "%s", req->session_id);
	v.state = "waiting";
	v.nseg = req->nseg;
	v.seg = req->seg;
	char *doc = api_experiment_json(&v);
	FUZZ_CHECK(doc, "api_experiment_json gave NULL");
	cJSON *d = cJSON_Parse(doc);
	FUZZ_CHECK(cJSON_IsObject(d), "the experiment document is not JSON: %s", doc);
	free(doc);
	cJSON *body = cJSON_CreateObject();
	cJSON *sched = cJSON_AddArrayToObject(body, "schedule");
	const cJSON *seg;
	cJSON_ArrayForEach(seg, cJSON_GetObjectItemCaseSensitive(d, "segments"))
	{
		cJSON *s = cJSON_CreateObject();
		static const char *const keep[] = {"beta", "until"};
		for (size_t k = 0; k < 2; k++)
			cJSON_AddItemToObject(
				s, keep[k],
				cJSON_Duplicate(cJSON_GetObjectItemCaseSensitive(seg, keep[k]), 1));
		cJSON_AddItemToArray(sched, s);
	}
	cJSON_Delete(d);
	if (req->fresh)
		cJSON_AddItemToObject(body, "session", fuzz_spec_body(&req->spec, 0));
	else
		cJSON_AddStringToObject(body, "session", req->session_id);
	if (req->beta_rate.si != 0)
		cJSON_AddNumberToObject(body, "beta_rate", req->beta_rate.user);
	cJSON_AddBoolToObject(body, "keep_session", req->keep_session);
	return fuzz_print(body);
}

/* POST /experiments. */
static void experiment_body(const char *body, size_t len)
{
	static api_experiment_req req, again;
	static api_exp_ext ext, ext_again;
	api_problem pb;
	api_err e = api_parse_experiment(body, len, &req, &ext, &pb);
	if (e != API_OK) {
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(req.nseg >= 1 && req.nseg <= API_EXP_MAX_SEGMENTS, "%d segments", req.nseg);
	for (int i = 0; i < req.nseg; i++)
		FUZZ_CHECK(req.seg[i].until > (i ? req.seg[i - 1].until : 0),
			   "segment %d ends at %g", i, req.seg[i].until);
	char *text = experiment_text(&req);
	e = api_parse_experiment(text, strlen(text), &again, &ext_again, &pb);
	FUZZ_CHECK(e == API_OK, "experiment written back is refused: %s\n%s", pb.detail, text);
	FUZZ_CHECK(again.fresh == req.fresh && again.nseg == req.nseg &&
			   again.keep_session == req.keep_session &&
			   strcmp(again.session_id, req.session_id) == 0 &&
			   again.beta_rate.si == req.beta_rate.si,
		   "experiment differs after the round trip: %s", text);
	for (int i = 0; i < req.nseg; i++)
		FUZZ_CHECK(again.seg[i].beta.si == req.seg[i].beta.si &&
				   again.seg[i].until == req.seg[i].until,
			   "segment %d differs after the round trip: %s", i, text);
	if (req.fresh)
		fuzz_same_spec(&req.spec, &again.spec, 1, "experiment session");
	free(text);
}

/* The request written back: betas and rotations from the sweep document's
 * points (the server lays them out rotation by rotation), t_end from it,
 * the model from the spec. */
static char *sweep_text(const api_sweep_req *req)
{
	size_t total = (size_t)req->nbeta * (size_t)req->nrot;
	api_sweep_point *pt = calloc(total, sizeof *pt);
	FUZZ_CHECK(pt, "out of memory");
	for (int r = 0; r < req->nrot; r++)
		for (int b = 0; b < req->nbeta; b++) {
			pt[(size_t)r * (size_t)req->nbeta + (size_t)b].beta = req->betas[b];
			pt[(size_t)r * (size_t)req->nbeta + (size_t)b].rotation = req->rotations[r];
		}
	api_sweep_view v = {.id = "0011223344556677", .state = "queued", .total = total,
			    .t_end = req->t_end, .pt = pt};
	char *doc = api_sweep_json(&v);
	free(pt);
	FUZZ_CHECK(doc, "api_sweep_json gave NULL");
	cJSON *d = cJSON_Parse(doc);
	FUZZ_CHECK(cJSON_IsObject(d), "the sweep document is not JSON: %s", doc);
	free(doc);
	cJSON *body = fuzz_spec_body(&req->spec, 0);
	cJSON_DeleteItemFromObjectCaseSensitive(body, "pace");
	cJSON_DeleteItemFromObjectCaseSensitive(body, "sample_rate");
	cJSON *betas = cJSON_AddArrayToObject(body, "beta");
	cJSON *rots = cJSON_AddArrayToObject(body, "rotations");
	const cJSON *p;
	int i = 0;
	cJSON_ArrayForEach(p, cJSON_GetObjectItemCaseSensitive(d, "points"))
	{
		if (i < req->nbeta)
			cJSON_AddItemToArray(betas, cJSON_Duplicate(
				cJSON_GetObjectItemCaseSensitive(p, "beta"), 1));
		if (i % req->nbeta == 0)
			cJSON_AddItemToArray(rots, cJSON_Duplicate(
				cJSON_GetObjectItemCaseSensitive(p, "rotation"), 1));
		i++;
	}
	cJSON_AddItemToObject(body, "t_end",
			      cJSON_Duplicate(cJSON_GetObjectItemCaseSensitive(d, "t_end"), 1));
	cJSON_Delete(d);
	return fuzz_print(body);
}

/* POST /sweeps. */
static void sweep_body(const char *body, size_t len)
{
	api_sweep_req req, again;
	api_problem pb;
	api_err e = api_parse_sweep(body, len, &req, &pb);
	if (e != API_OK) {
		FUZZ_CHECK(!req.betas && !req.values, "a refused sweep keeps its betas or values");
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(req.nbeta >= 1 && req.nbeta * req.nrot <= API_SWEEP_MAX_POINTS &&
			   req.nrot >= 1 && req.nrot <= 2 &&
			   req.t_end > req.spec.scene.transient &&
			   req.nvary >= 1 && req.nvary <= SIM_STUDY_MAX_AXES && req.values,
		   "sweep of %d x %d points, t_end %g, %d varied", req.nbeta, req.nrot, req.t_end,
		   req.nvary);
	/* a study over other settings: every value within its setting's range */
	for (int k = 0; k < req.nbeta; k++)
		for (int a = 0; a < req.nvary; a++) {
			const sim_setting *t = sim_setting_find(req.vary[a]);
			double u = req.values[(size_t)k * (size_t)req.nvary + (size_t)a];
			FUZZ_CHECK(t && u >= t->min && u <= t->max, "%s = %g outside its range",
				   req.vary[a], u);
		}
	free(req.values);
	if (req.nvary != 1 || strcmp(req.vary[0], "beta") != 0) {
		free(req.betas);
		return; /* the round trip below is the plain v(beta) sweep's */
	}
	char *text = sweep_text(&req);
	e = api_parse_sweep(text, strlen(text), &again, &pb);
	FUZZ_CHECK(e == API_OK, "sweep written back is refused: %s\n%.2000s", pb.detail, text);
	FUZZ_CHECK(again.nbeta == req.nbeta && again.nrot == req.nrot &&
			   again.t_end == req.t_end && again.rotations[0] == req.rotations[0] &&
			   (req.nrot < 2 || again.rotations[1] == req.rotations[1]),
		   "sweep differs after the round trip: %.2000s", text);
	for (int i = 0; i < req.nbeta; i++)
		FUZZ_CHECK(again.betas[i].si == req.betas[i].si &&
				   again.betas[i].user == req.betas[i].user,
			   "beta %d differs after the round trip", i);
	api_spec a = req.spec, b = again.spec;
	a.pace = b.pace = 1;
	a.sample_rate = b.sample_rate = 1;
	fuzz_same_spec(&a, &b, 0, "sweep model");
	free(text);
	free(req.betas);
	free(again.betas);
	free(again.values);
}

/* POST /fits: a refused request keeps no points and is a well-formed
 * problem; an accepted one is one fit_check passes again, with its data
 * (points or peaks, not both) at least as many as its free parameters. */
static void fit_body(const char *body, size_t len)
{
	fit_request req;
	fit_point *points;
	api_problem pb;
	api_err e = api_parse_fit(body, len, &req, &points, &pb);
	if (e != API_OK) {
		FUZZ_CHECK(!points, "a refused fit keeps its points");
		fuzz_check_problem(e, &pb);
		return;
	}
	size_t data = req.npoints + (size_t)req.npeaks;
	FUZZ_CHECK(req.nfree >= 1 && req.nfree <= FIT_MAX_FREE && data >= (size_t)req.nfree &&
			   (req.npoints == 0 || req.npeaks == 0) &&
			   (req.npoints == 0) == (points == NULL),
		   "fit with %d free, %zu points, %d peaks", req.nfree, req.npoints, req.npeaks);
	char field[48], msg[FIT_MSG];
	FUZZ_CHECK(fit_check(&req, field, sizeof field, msg, sizeof msg) == SIM_OK,
		   "an accepted fit fails its check again: %s: %s", field, msg);
	free(points);
}

/* sessions/ID/spec.json as a restart reads it (api_parse_spec_file, the
 * first file it reads, a text anyone can edit): a refusal is a well-formed
 * problem; an accepted file, written again (api_spec_file) with what it
 * read, reads back as the same spec, creation time, owner and pick, in this
 * build's format. */
static void specfile_body(const char *body, size_t len)
{
	api_spec spec, again;
	double created, created2;
	int owned, owned2, format, format2, picked, picked2;
	sim_feed_choice pick, pick2;
	api_problem pb;
	api_err e = api_parse_spec_file(body, len, &spec, &created, &owned, &format, &pick,
					&picked, &pb);
	if (e != API_OK) {
		fuzz_check_problem(e, &pb);
		return;
	}
	FUZZ_CHECK(format >= 1 && format <= API_SPEC_FILE_FORMAT, "format %d accepted", format);
	char *text = api_spec_file(&spec, created, owned, picked ? &pick : NULL);
	FUZZ_CHECK(text, "out of memory");
	e = api_parse_spec_file(text, strlen(text), &again, &created2, &owned2, &format2, &pick2,
				&picked2, &pb);
	FUZZ_CHECK(e == API_OK, "spec.json written again is refused: %s\n%s", pb.detail, text);
	fuzz_same_spec(&spec, &again, 1, "spec.json");
	FUZZ_CHECK(format2 == API_SPEC_FILE_FORMAT && owned2 == owned && picked2 == picked &&
			   (created2 == created || (isnan(created2) && isnan(created))),
		   "spec.json written again: format %d, created %.17g (was %.17g), owned %d (%d), "
		   "picked %d (%d)\n%s", format2, created2, created, owned2, owned, picked2, picked,
		   text);
	FUZZ_CHECK(!picked || (pick2.model == pick.model && strcmp(pick2.why, pick.why) == 0),
		   "spec.json's pick written again differs\n%s", text);
	free(text);
}

typedef struct fuzz_body {
	const char *name;
	void (*run)(const char *body, size_t len);
} fuzz_body;

static const fuzz_body bodies[] = {
	{"session", session_body},
	{"control", control_body},
	{"controlline", controlline_body},
	{"experiment", experiment_body},
	{"sweep", sweep_body},
	{"fit", fit_body},
	{"specfile", specfile_body},
};

static const fuzz_body *chosen;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
	(void)argc;
	(void)argv;
	for (size_t i = 0; i < sizeof bodies / sizeof *bodies; i++)
		if (strcmp(bodies[i].name, FUZZ_BODY) == 0)
			chosen = &bodies[i];
	FUZZ_CHECK(chosen, "no body named %s in fuzz_body.c", FUZZ_BODY);
	return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
	char *body = fuzz_exact(data, size);
	chosen->run(body, size);
	free(body);
	return 0;
}
