/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers.h - listings across replicas (--peers): a GET of the sessions,
 * experiments or sweeps gathers the entries of every peer with its own.
 */
#ifndef CONVSIM_PEERS_H
#define CONVSIM_PEERS_H

#include "config.h"
#include "reply.h"

/* Up to this many peers. */
#define SRV_PEERS_MAX 32

/* Read cfg->peers (a comma list of http://HOST:PORT; NULL: none) and
 * resolve each host once. Returns 0, or -1 with a message on stderr. */
int srv_peers_init(const srv_config *cfg);

/* Answer a listing: local is this replica's own (JSON with the array
 * member `member`, or CSV as r->csv says; taken). Without peers, or with
 * ?scope=local, that is the answer; otherwise every peer is asked for its
 * own (?scope=local, this request's Authorization passed on) at once,
 * within 3 s, and the answer is the merged list. A peer that cannot be
 * reached, answers another status or another shape is named in the JSON
 * member "unreachable" and in the header Convsim-Unreachable (its URLs,
 * comma-separated); the answer is still 200. */
enum MHD_Result srv_peers_reply(srv_req *r, char *local, const char *member);

/* A peer's whole answer (len bytes in buf, which has room for one more):
 * its body (*body_len bytes) if it is an HTTP answer of status 200, else
 * NULL and why in reason (the fan-out names the peer unreachable). */
const char *srv_peer_answer(char *buf, size_t len, size_t *body_len, char *reason,
			    size_t reasonlen);

#endif
