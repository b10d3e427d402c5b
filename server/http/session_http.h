/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * session_http.h - the session resources.
 */
#ifndef CONVSIM_SESSION_HTTP_H
#define CONVSIM_SESSION_HTTP_H

#include "reply.h"

/* POST/GET /api/v1/sessions, GET/PATCH/DELETE /api/v1/sessions/{id},
 * GET /api/v1/sessions/{id}/trajectory. */
enum MHD_Result srv_h_sessions_create(srv_req *r);
enum MHD_Result srv_h_sessions_list(srv_req *r);
enum MHD_Result srv_h_session_get(srv_req *r);
enum MHD_Result srv_h_session_patch(srv_req *r);
enum MHD_Result srv_h_session_delete(srv_req *r);
enum MHD_Result srv_h_trajectory(srv_req *r);

#endif
