/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * catalog.h - the read-only resources: presets, health, metrics, OpenAPI.
 */
#ifndef CONVSIM_CATALOG_H
#define CONVSIM_CATALOG_H

#include "config.h"
#include "reply.h"

/* Note the start time (health's uptime); cfg (borrowed for the daemon's
 * life) gives the limits health reports. */
void srv_catalog_init(const srv_config *cfg);
/* Free the cached OpenAPI text. */
void srv_catalog_shutdown(void);

enum MHD_Result srv_h_presets(srv_req *r);
enum MHD_Result srv_h_health(srv_req *r);
enum MHD_Result srv_h_metrics(srv_req *r);
enum MHD_Result srv_h_openapi(srv_req *r);
/* GET /api/v1/problems/SLUG: the HTML page that explains a problem type. */
enum MHD_Result srv_h_problem(srv_req *r);

#endif
