/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * catalog_json.c - what the daemon offers: presets with their full
 * settings, the settings table (names, groups, units, ranges, docs) and
 * the integrators. Read by clients to build forms and validate early.
 */
#include <string.h>

#include "json_int.h"

static const char *kind_name(sim_kind k)
{
	switch (k) {
	case SIM_KIND_REAL: return "real";
	case SIM_KIND_INT: return "int";
	case SIM_KIND_BOOL: return "bool";
	case SIM_KIND_ENUM: return "enum";
	}
	return "real";
}

cJSON *api_settings_array(void)
{
	size_t n = 0;
	const sim_setting *tab = sim_settings(&n);
	cJSON *arr = cJSON_CreateArray();
	for (size_t i = 0; tab && i < n; i++) {
		cJSON *o = cJSON_CreateObject();
		cJSON_AddStringToObject(o, "name", tab[i].name);
		cJSON_AddStringToObject(o, "group", tab[i].group);
		cJSON_AddStringToObject(o, "kind", kind_name(tab[i].kind));
		cJSON_AddStringToObject(o, "unit", tab[i].unit ? tab[i].unit : "");
		if (tab[i].kind == SIM_KIND_ENUM && tab[i].choices) {
			cJSON *ch = cJSON_AddArrayToObject(o, "choices");
			const char *p = tab[i].choices;
			while (*p) {
				const char *bar = strchr(p, '|');
				size_t len = bar ? (size_t)(bar - p) : strlen(p);
				char name[48];
				if (len >= sizeof name)
					len = sizeof name - 1;
				memcpy(name, p, len);
				name[len] = '\0';
				cJSON_AddItemToArray(ch, cJSON_CreateString(name));
				p = bar ? bar + 1 : p + strlen(p);
			}
		} else if (tab[i].kind != SIM_KIND_BOOL) {
			api_add_number(o, "min", tab[i].min);
			api_add_number(o, "max", tab[i].max);
		}
		cJSON_AddStringToObject(o, "doc", tab[i].doc ? tab[i].doc : "");
		cJSON_AddItemToArray(arr, o);
	}
	return arr;
}

char *api_presets_json(void)
{
	static const char *const groups[] = {"params", "scene", "integrator"};
	cJSON *o = cJSON_CreateObject();
	cJSON *presets = cJSON_AddArrayToObject(o, "presets");
	for (int i = 0; sim_preset_names[i]; i++) {
		sim_params p;
		sim_scene s;
		sim_method m;
		if (sim_preset(sim_preset_names[i], &p, &s, &m) != SIM_OK)
			continue;
		cJSON *po = cJSON_CreateObject();
		cJSON_AddStringToObject(po, "name", sim_preset_names[i]);
		for (int g = 0; g < 3; g++)
			cJSON_AddItemToObject(po, groups[g],
					      api_settings_object(&p, &s, &m,
								  groups[g]));
		cJSON_AddItemToArray(presets, po);
	}
	cJSON_AddItemToObject(o, "settings", api_settings_array());
	cJSON *methods = cJSON_AddArrayToObject(o, "methods");
	size_t nm = 0;
	const sim_method_info *const *mi = sim_methods(&nm);
	for (size_t i = 0; mi && i < nm; i++) {
		cJSON *mo = cJSON_CreateObject();
		cJSON_AddStringToObject(mo, "name", mi[i]->name);
		cJSON_AddNumberToObject(mo, "order", mi[i]->order);
		cJSON_AddBoolToObject(mo, "adaptive", mi[i]->adaptive);
		cJSON_AddStringToObject(mo, "doc", mi[i]->doc ? mi[i]->doc : "");
		cJSON_AddItemToArray(methods, mo);
	}
	return api_print_free(o);
}

char *api_health_json(const api_health *h)
{
	cJSON *o = cJSON_CreateObject();
	cJSON_AddStringToObject(o, "status", h->status);
	api_add_number(o, "uptime", h->uptime);
	cJSON_AddNumberToObject(o, "sessions", h->sessions);
	cJSON_AddNumberToObject(o, "max_sessions", h->max_sessions);
	cJSON_AddNumberToObject(o, "stream_clients", h->stream_clients);
	cJSON_AddNumberToObject(o, "max_streams", h->max_streams);
	cJSON_AddNumberToObject(o, "pool_threads", h->pool_threads);
	cJSON_AddNumberToObject(o, "pool_queued", h->pool_queued);
	cJSON_AddStringToObject(o, "api", "v1");
	return api_print_free(o);
}
