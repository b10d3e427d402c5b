/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * gate.h - the request gate: what every request must satisfy, seen once,
 * on its headers, before its body is read or a route runs.
 *
 * In order: Host names this daemon (421/400: DNS rebinding), Origin, when
 * sent, is ours or an --allow-origin (403), a CORS preflight for an
 * allowed origin is answered here (204), the bearer token when the daemon
 * has one (401; the dashboard's files and /api/v1/health are open), and a
 * JSON Content-Type on POST, PATCH, PUT and DELETE (415). See docs/operations.md
 * "Security".
 */
#ifndef CONVSIM_GATE_H
#define CONVSIM_GATE_H

#include "config.h"
#include "reply.h"

/* Read the token of cfg->token_file (refused when the file is not a
 * regular file, is accessible to group or others, or holds no usable
 * token) and refuse a non-loopback --listen without a token unless
 * --insecure. cfg is borrowed for the daemon's life. Returns 0, or -1
 * with a message on stderr. */
int srv_gate_init(const srv_config *cfg);
/* The TCP port actually bound (the Host and Origin checks name it). */
void srv_gate_set_port(int port);
/* Forget the token (zeroed). */
void srv_gate_shutdown(void);
/* Check a request's headers. Returns 1 when it may go on (r->cors_origin
 * is set when it carries an allowed Origin); 0 when the gate answered it,
 * *result then holds what the access handler returns. */
int srv_gate_check(srv_req *r, enum MHD_Result *result);

#endif
