/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * static.h - the dashboard's files under --web-root.
 */
#ifndef CONVSIM_STATIC_H
#define CONVSIM_STATIC_H

#include "config.h"
#include "reply.h"

/* cfg (borrowed for the daemon's life) gives --web-root. */
void srv_static_init(const srv_config *cfg);
/* GET of any path outside /api/ and /metrics. */
enum MHD_Result srv_h_static(srv_req *r);

#endif
