/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * stream.h - GET /api/v1/sessions/{id}/stream (SSE or NDJSON).
 */
#ifndef CONVSIM_STREAM_H
#define CONVSIM_STREAM_H

#include "config.h"
#include "reply.h"

/* cfg (borrowed for the daemon's life) gives --max-streams and
 * --heartbeat. */
void srv_streams_init(const srv_config *cfg);
enum MHD_Result srv_h_stream(srv_req *r);

#endif
