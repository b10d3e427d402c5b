/*
 * openapi.c - the OpenAPI 3.1 description of the HTTP API, served at
 * /api/v1/openapi.json. The paths are written out here as JSON text; the
 * schemas of the "params", "scene" and "integrator" objects are generated
 * from the core's settings table, so names, units and ranges never drift
 * from what the daemon accepts.
 */
#include <stdio.h>
#include <string.h>

#include "json_int.h"

/* Shorthands used in the text below. */
#define PROBLEM_REF "{\"$ref\":\"#/components/responses/Problem\"}"
#define JSON_OF(schema)                                                       \
	"{\"description\":\"OK\",\"content\":{\"application/json\":{"        \
	"\"schema\":" schema "}}}"
#define ID_PARAM "{\"$ref\":\"#/components/parameters/Id\"}"
#define BODY(schema)                                                          \
	"\"requestBody\":{\"required\":true,\"content\":{\"application/"     \
	"json\":{\"schema\":" schema "}}}"
#define REF(name) "{\"$ref\":\"#/components/schemas/" name "\"}"
#define NUM_OR_NULL(desc)                                                     \
	"{\"type\":[\"number\",\"null\"],\"description\":\"" desc "\"}"

static const char doc_text[] =
	"{\"openapi\":\"3.1.0\","
	"\"info\":{\"title\":\"convsim daemon API\",\"version\":\"1\","
	"\"description\":\"Simulation sessions of a reversible vibratory "
	"conveyor (Czubak 2016): beta on the fly, streams, experiments, "
	"sweeps. Errors are RFC 9457 problem details.\"},"
	"\"paths\":{"
	"\"/api/v1/sessions\":{"
	"\"post\":{\"summary\":\"Create a session and start its worker\","
	BODY(REF("SessionCreate")) ","
	"\"responses\":{\"201\":" JSON_OF(REF("Session")) ","
	"\"400\":" PROBLEM_REF ",\"413\":" PROBLEM_REF ",\"415\":" PROBLEM_REF
	",\"422\":" PROBLEM_REF ",\"429\":" PROBLEM_REF ",\"503\":" PROBLEM_REF
	"}},"
	"\"get\":{\"summary\":\"List sessions with live status\","
	"\"responses\":{\"200\":" JSON_OF(
		"{\"type\":\"object\",\"properties\":{\"sessions\":{\"type\":"
		"\"array\",\"items\":" REF("Session") "}}}") "}}},"
	"\"/api/v1/sessions/{id}\":{\"parameters\":[" ID_PARAM "],"
	"\"get\":{\"summary\":\"Spec and live status\",\"responses\":{"
	"\"200\":" JSON_OF(REF("Session")) ",\"404\":" PROBLEM_REF "}},"
	"\"patch\":{\"summary\":\"Change beta, rotation, omega_ss, motor_on, running, "
	"pace or until while it runs; answers the simulated time the change "
	"takes effect\"," BODY(REF("Control")) ","
	"\"responses\":{\"200\":" JSON_OF(REF("Session")) ","
	"\"400\":" PROBLEM_REF ",\"404\":" PROBLEM_REF ",\"409\":" PROBLEM_REF
	",\"415\":" PROBLEM_REF ",\"422\":" PROBLEM_REF ",\"503\":" PROBLEM_REF
	"}},"
	"\"delete\":{\"summary\":\"Stop and remove the session\","
	"\"responses\":{\"204\":{\"description\":\"deleted\"},\"404\":"
	PROBLEM_REF "}}},"
	"\"/api/v1/sessions/{id}/stream\":{\"parameters\":[" ID_PARAM ","
	"{\"name\":\"format\",\"in\":\"query\",\"schema\":{\"enum\":[\"sse\","
	"\"ndjson\"]}},"
	"{\"name\":\"fields\",\"in\":\"query\",\"description\":\"comma list "
	"of trough, orbit, rotor, eliminators, feed, energy, elements, all\","
	"\"schema\":{\"type\":\"string\"}},"
	"{\"name\":\"rate\",\"in\":\"query\",\"description\":\"samples per "
	"simulated second\",\"schema\":{\"type\":\"number\"}},"
	"{\"name\":\"limit\",\"in\":\"query\",\"schema\":{\"type\":"
	"\"integer\",\"minimum\":1}},"
	"{\"name\":\"since\",\"in\":\"query\",\"description\":\"resume after "
	"this record id (as Last-Event-ID)\",\"schema\":{\"type\":"
	"\"integer\",\"minimum\":0}},"
	"{\"name\":\"Last-Event-ID\",\"in\":\"header\",\"schema\":{\"type\":"
	"\"integer\",\"minimum\":0}}],"
	"\"get\":{\"summary\":\"Server-Sent Events or NDJSON of samples and "
	"control events\",\"responses\":{\"200\":{\"description\":\"stream\","
	"\"content\":{\"text/event-stream\":{},\"application/x-ndjson\":{}}},"
	"\"400\":" PROBLEM_REF ",\"404\":" PROBLEM_REF ",\"429\":" PROBLEM_REF
	"}}},"
	"\"/api/v1/sessions/{id}/trajectory\":{\"parameters\":[" ID_PARAM ","
	"{\"name\":\"from\",\"in\":\"query\",\"schema\":{\"type\":\"number\"}},"
	"{\"name\":\"to\",\"in\":\"query\",\"schema\":{\"type\":\"number\"}},"
	"{\"name\":\"format\",\"in\":\"query\",\"schema\":{\"enum\":[\"json\","
	"\"csv\"]}}],"
	"\"get\":{\"summary\":\"Recorded, downsampled history\","
	"\"responses\":{\"200\":{\"description\":\"rows\",\"content\":{"
	"\"application/json\":{},\"text/csv\":{}}},\"400\":" PROBLEM_REF
	",\"404\":" PROBLEM_REF "}}},"
	"\"/api/v1/experiments\":{"
	"\"post\":{\"summary\":\"Run a beta schedule; per segment the steady "
	"transport velocity and the reversal time\","
	BODY(REF("ExperimentCreate")) ","
	"\"responses\":{\"201\":" JSON_OF(REF("Experiment")) ",\"400\":"
	PROBLEM_REF ",\"404\":" PROBLEM_REF ",\"409\":" PROBLEM_REF ",\"422\":"
	PROBLEM_REF ",\"429\":" PROBLEM_REF "}},"
	"\"get\":{\"summary\":\"List experiments\",\"responses\":{\"200\":"
	JSON_OF("{\"type\":\"object\"}") "}}},"
	"\"/api/v1/experiments/{id}\":{\"parameters\":[" ID_PARAM "],"
	"\"get\":{\"summary\":\"Progress and results\",\"responses\":{\"200\":"
	JSON_OF(REF("Experiment")) ",\"404\":" PROBLEM_REF "}}},"
	"\"/api/v1/sweeps\":{"
	"\"post\":{\"summary\":\"Measure v(beta) for both rotations on the "
	"worker pool\"," BODY(REF("SweepCreate")) ","
	"\"responses\":{\"202\":" JSON_OF(REF("Sweep")) ",\"400\":" PROBLEM_REF
	",\"422\":" PROBLEM_REF ",\"429\":" PROBLEM_REF "}},"
	"\"get\":{\"summary\":\"List sweeps\",\"responses\":{\"200\":"
	JSON_OF("{\"type\":\"object\"}") "}}},"
	"\"/api/v1/sweeps/{id}\":{\"parameters\":[" ID_PARAM ","
	"{\"name\":\"format\",\"in\":\"query\",\"schema\":{\"enum\":[\"json\","
	"\"csv\"]}}],"
	"\"get\":{\"summary\":\"Progress and results\",\"responses\":{\"200\":"
	"{\"description\":\"results\",\"content\":{\"application/json\":{"
	"\"schema\":" REF("Sweep") "},\"text/csv\":{}}},\"404\":" PROBLEM_REF
	"}},"
	"\"delete\":{\"summary\":\"Cancel and forget\",\"responses\":{\"204\":"
	"{\"description\":\"deleted\"},\"404\":" PROBLEM_REF "}}},"
	"\"/api/v1/presets\":{\"get\":{\"summary\":\"Presets, the settings "
	"table, integrators\",\"responses\":{\"200\":" JSON_OF(
		"{\"type\":\"object\"}") "}}},"
	"\"/api/v1/health\":{\"get\":{\"summary\":\"Liveness\",\"responses\":"
	"{\"200\":" JSON_OF("{\"type\":\"object\"}") ",\"503\":{\"description\":"
	"\"shutting down\"}}}},"
	"\"/api/v1/openapi.json\":{\"get\":{\"summary\":\"This document\","
	"\"responses\":{\"200\":" JSON_OF("{\"type\":\"object\"}") "}}},"
	"\"/metrics\":{\"get\":{\"summary\":\"Prometheus text format\","
	"\"responses\":{\"200\":{\"description\":\"metrics\",\"content\":{"
	"\"text/plain\":{}}}}}}"
	"},"
	"\"components\":{"
	"\"parameters\":{\"Id\":{\"name\":\"id\",\"in\":\"path\",\"required\":"
	"true,\"schema\":{\"type\":\"string\"}}},"
	"\"responses\":{\"Problem\":{\"description\":\"RFC 9457 problem\","
	"\"content\":{\"application/problem+json\":{\"schema\":"
	REF("Problem") "}}}},"
	"\"schemas\":{"
	"\"Problem\":{\"type\":\"object\",\"properties\":{"
	"\"type\":{\"type\":\"string\"},\"title\":{\"type\":\"string\"},"
	"\"status\":{\"type\":\"integer\"},\"detail\":{\"type\":\"string\"},"
	"\"instance\":{\"type\":\"string\"},\"field\":{\"type\":\"string\"},"
	"\"min\":{\"type\":\"number\"},\"max\":{\"type\":\"number\"},"
	"\"choices\":{\"type\":\"array\",\"items\":{\"type\":\"string\"}}}},"
	"\"Pace\":{\"oneOf\":[{\"type\":\"number\",\"minimum\":0.001,"
	"\"maximum\":1000},{\"const\":\"max\"}]},"
	"\"SessionCreate\":{\"type\":\"object\",\"additionalProperties\":false,"
	"\"properties\":{\"preset\":{\"type\":\"string\"},"
	"\"params\":" REF("Params") ",\"scene\":" REF("Scene") ","
	"\"integrator\":" REF("Integrator") ",\"pace\":" REF("Pace") ","
	"\"until\":{\"type\":[\"number\",\"null\"],\"description\":\"simulated "
	"end time, s (pace max defaults to 60)\"},"
	"\"sample_rate\":{\"type\":\"number\",\"minimum\":1,\"maximum\":10000}"
	"}},"
	"\"Control\":{\"type\":\"object\",\"additionalProperties\":false,"
	"\"minProperties\":1,\"properties\":{"
	"\"beta\":{\"type\":\"number\",\"description\":\"deg\"},"
	"\"beta_rate\":{\"type\":\"number\",\"description\":\"deg/s\"},"
	"\"rotation\":{\"enum\":[\"cw\",\"ccw\"]},"
	"\"omega_ss\":{\"type\":\"number\",\"description\":\"rad/s\"},"
	"\"running\":{\"type\":\"boolean\"},"
	"\"motor_on\":{\"type\":\"boolean\",\"description\":\"drive on/off\"},"
	"\"pace\":" REF("Pace") ","
	"\"until\":{\"type\":[\"number\",\"null\"]}}},"
	"\"Session\":{\"type\":\"object\",\"properties\":{"
	"\"id\":{\"type\":\"string\"},\"state\":{\"enum\":[\"running\","
	"\"paused\",\"finished\",\"failed\"]},\"pace\":" REF("Pace") ","
	"\"until\":{\"type\":[\"number\",\"null\"]},\"status\":"
	REF("Status") ",\"spec\":{\"type\":\"object\"},\"t_effective\":{"
	"\"type\":[\"number\",\"null\"]},\"applied\":" REF("Control") "}},"
	"\"Status\":{\"type\":\"object\",\"description\":\"Live state at the "
	"simulated time t; SI units but beta, beta_target (deg) and beta_dot "
	"(deg/s); null where not defined yet\",\"properties\":{"
	"\"t\":{\"type\":\"number\"},\"t_integrator\":{\"type\":\"number\"},"
	"\"beta\":{\"type\":\"number\"},\"beta_target\":{\"type\":\"number\"},"
	"\"beta_dot\":{\"type\":\"number\"},"
	"\"rotation\":{\"enum\":[\"cw\",\"ccw\"]},\"drive_on\":{\"type\":"
	"\"boolean\"},\"omega_ss\":{\"type\":\"number\"},"
	"\"rotor_speed\":{\"type\":\"number\",\"description\":\"rad/s, "
	"positive for clockwise (the paper's sense)\"},"
	"\"motor_torque\":{\"type\":\"number\"},\"power\":{\"type\":"
	"\"number\"},"
	"\"rotor_speed_mean\":" NUM_OR_NULL("rad/s, mean over the transport "
	"estimate's whole periods") ","
	"\"motor_torque_mean\":" NUM_OR_NULL("N m, the same mean") ","
	"\"power_mean\":" NUM_OR_NULL("W, the same mean") ","
	"\"transport_velocity\":" NUM_OR_NULL("m/s, slope of the mean feed "
	"displacement over the whole periods since scene.transient (or the "
	"last estimator restart)") ","
	"\"transport_velocity_uncertainty\":" NUM_OR_NULL("m/s, the "
	"estimate's error bar; null before 4 batches of periods") ","
	"\"steady\":{\"type\":\"boolean\",\"description\":\"the estimate "
	"spans at least 8 periods and shows no drift beyond its scatter\"},"
	"\"transport_periods\":{\"type\":\"number\"},"
	"\"feed_velocity\":" NUM_OR_NULL("m/s, last whole period") ","
	"\"feed_displacement\":{\"type\":\"number\"},"
	"\"period\":" NUM_OR_NULL("s") ","
	"\"steps\":{\"type\":\"number\"},\"rhs_evals\":{\"type\":\"number\"},"
	"\"dt\":{\"type\":\"number\"},\"substeps\":{\"type\":\"integer\"},"
	"\"steps_per_s\":{\"type\":\"number\"},\"rtf\":{\"type\":\"number\"},"
	"\"n_dof\":{\"type\":\"integer\"},\"reductions\":{\"type\":\"array\","
	"\"items\":{\"type\":\"string\"}},\"reduction_figures\":{\"type\":"
	"\"array\"},\"energy\":{\"type\":\"object\",\"description\":\"J, "
	"changes since t = 0: input, kinetic, potential, dissipated, "
	"residual\"}}},"
	"\"ExperimentCreate\":{\"type\":\"object\",\"required\":[\"schedule\"],"
	"\"properties\":{\"session\":{\"oneOf\":[{\"type\":\"string\"},"
	REF("SessionCreate") "]},\"beta_rate\":{\"type\":\"number\"},"
	"\"schedule\":{\"type\":\"array\",\"minItems\":1,\"maxItems\":32,"
	"\"items\":{\"type\":\"object\",\"required\":[\"beta\",\"until\"],"
	"\"properties\":{\"beta\":{\"type\":\"number\"},\"until\":{\"type\":"
	"\"number\"}}}}}},"
	"\"Experiment\":{\"type\":\"object\",\"properties\":{\"id\":{\"type\":"
	"\"string\"},\"session\":{\"type\":\"string\"},\"state\":{\"enum\":["
	"\"waiting\",\"running\",\"done\",\"aborted\"]},\"progress\":{\"type\":"
	"\"number\"},\"segments\":{\"type\":\"array\",\"items\":{\"type\":"
	"\"object\",\"properties\":{\"beta\":{\"type\":\"number\"},\"until\":{"
	"\"type\":\"number\"},\"t_command\":{\"type\":[\"number\",\"null\"]},"
	"\"steady_velocity\":{\"type\":[\"number\",\"null\"]},"
	"\"mean_velocity\":" NUM_OR_NULL("m/s, transport estimate over the "
	"segment") ","
	"\"uncertainty\":" NUM_OR_NULL("m/s, error bar of mean_velocity") ","
	"\"steady\":{\"type\":[\"boolean\",\"null\"],\"description\":"
	"\"mean_velocity showed no drift (null until the segment is done)\"},"
	"\"reversal_time\":{\"type\":[\"number\",\"null\"]}}}}}},"
	"\"SweepCreate\":{\"type\":\"object\",\"properties\":{\"preset\":{"
	"\"type\":\"string\"},\"params\":" REF("Params") ",\"scene\":"
	REF("Scene") ",\"integrator\":" REF("Integrator") ","
	"\"beta\":{\"oneOf\":[{\"type\":\"array\",\"items\":{\"type\":"
	"\"number\"}},{\"type\":\"object\",\"properties\":{\"from\":{\"type\":"
	"\"number\"},\"to\":{\"type\":\"number\"},\"step\":{\"type\":"
	"\"number\"}}}]},\"rotations\":{\"type\":\"array\",\"items\":{\"enum\":"
	"[\"cw\",\"ccw\"]}},\"t_end\":{\"type\":\"number\",\"maximum\":600,"
	"\"description\":\"simulated s per point; must exceed scene.transient; "
	"default scene.transient + 4\"}}},"
	"\"Sweep\":{\"type\":\"object\",\"properties\":{\"id\":{\"type\":"
	"\"string\"},\"state\":{\"enum\":[\"queued\",\"running\",\"done\","
	"\"cancelled\"]},\"total\":{\"type\":\"integer\"},\"done\":{\"type\":"
	"\"integer\"},\"t_end\":{\"type\":\"number\"},\"points\":{\"type\":"
	"\"array\",\"items\":{\"type\":\"object\",\"properties\":{"
	"\"beta\":{\"type\":\"number\",\"description\":\"deg\"},"
	"\"rotation\":{\"enum\":[\"cw\",\"ccw\"]},\"state\":{\"enum\":["
	"\"pending\",\"running\",\"done\",\"failed\"]},"
	"\"velocity\":" NUM_OR_NULL("m/s") ","
	"\"uncertainty\":" NUM_OR_NULL("m/s, error bar of velocity") ","
	"\"steady\":{\"type\":[\"boolean\",\"null\"]},"
	"\"error\":{\"type\":\"string\"}}}},\"series\":{\"type\":"
	"\"object\"}}}"
	"}}}";

/* A JSON Schema object for one group of the settings table, with the
 * czubak2016 preset's values as defaults. */
static cJSON *group_schema(const char *group)
{
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	sim_params pp;
	sim_scene ps;
	sim_method pm;
	cJSON *defaults = sim_preset("czubak2016", &pp, &ps, &pm) == SIM_OK
				  ? api_settings_object(&pp, &ps, &pm, group)
				  : NULL;
	cJSON *schema = cJSON_CreateObject();
	cJSON_AddStringToObject(schema, "type", "object");
	cJSON_AddBoolToObject(schema, "additionalProperties", 0);
	cJSON *props = cJSON_AddObjectToObject(schema, "properties");
	for (size_t i = 0; tab && i < n; i++) {
		if (strcmp(tab[i].group, group) != 0)
			continue;
		cJSON *p = cJSON_CreateObject();
		switch (tab[i].kind) {
		case SIM_KIND_BOOL:
			cJSON_AddStringToObject(p, "type", "boolean");
			break;
		case SIM_KIND_ENUM: {
			cJSON *e = cJSON_AddArrayToObject(p, "enum");
			char choices[256];
			snprintf(choices, sizeof choices, "%s",
				 tab[i].choices ? tab[i].choices : "");
			char *save = NULL;
			for (char *t = strtok_r(choices, "|", &save); t;
			     t = strtok_r(NULL, "|", &save))
				cJSON_AddItemToArray(e, cJSON_CreateString(t));
			break;
		}
		default:
			cJSON_AddStringToObject(p, "type",
						tab[i].kind == SIM_KIND_INT
							? "integer"
							: "number");
			api_add_number(p, "minimum", tab[i].min);
			api_add_number(p, "maximum", tab[i].max);
		}
		char desc[320];
		snprintf(desc, sizeof desc, "%s%s%s%s",
			 tab[i].doc ? tab[i].doc : "",
			 tab[i].unit && tab[i].unit[0] ? " [" : "",
			 tab[i].unit ? tab[i].unit : "",
			 tab[i].unit && tab[i].unit[0] ? "]" : "");
		cJSON_AddStringToObject(p, "description", desc);
		const cJSON *dv = cJSON_GetObjectItemCaseSensitive(defaults,
								   tab[i].name);
		if (dv && !cJSON_IsNull(dv))
			cJSON_AddItemToObject(p, "default",
					      cJSON_Duplicate(dv, 1));
		cJSON_AddItemToObject(props, tab[i].name, p);
	}
	cJSON_Delete(defaults);
	if (strcmp(group, "integrator") == 0 &&
	    !cJSON_GetObjectItemCaseSensitive(props, "method")) {
		size_t nm = 0;
		const sim_method_info *const *mi = sim_methods(&nm);
		cJSON *p = cJSON_CreateObject();
		cJSON *e = cJSON_AddArrayToObject(p, "enum");
		for (size_t i = 0; mi && i < nm; i++)
			cJSON_AddItemToArray(e, cJSON_CreateString(mi[i]->name));
		cJSON_AddItemToObject(props, "method", p);
	}
	return schema;
}

char *api_openapi_json(void)
{
	cJSON *doc = cJSON_Parse(doc_text);
	cJSON *schemas = doc ? cJSON_GetObjectItemCaseSensitive(
				       cJSON_GetObjectItemCaseSensitive(
					       doc, "components"),
				       "schemas")
			     : NULL;
	if (!schemas) {
		cJSON_Delete(doc);
		return NULL;
	}
	cJSON_AddItemToObject(schemas, "Params", group_schema("params"));
	cJSON_AddItemToObject(schemas, "Scene", group_schema("scene"));
	cJSON_AddItemToObject(schemas, "Integrator", group_schema("integrator"));
	return api_print_free(doc);
}
