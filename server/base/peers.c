/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers.c - listings across replicas. Replicas share nothing: each keeps
 * its own sessions, experiments and sweeps, and a proxy routes by the node
 * id in an id (--node-id). A list is the one thing no single replica
 * holds, so the replica that receives GET /api/v1/sessions (experiments,
 * sweeps) asks its --peers for theirs with ?scope=local and merges.
 *
 * The peers are asked at once: one non-blocking HTTP/1.0 GET each, driven
 * by one poll() loop with a 3-s deadline, so a dead peer costs at most
 * that and a refused connection nothing. The merging is api/'s
 * (list_json.c); this file only moves bytes.
 */
#include <errno.h>
#include <fcntl.h>
#include <netdb.h>
#include <poll.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/socket.h>
#include <unistd.h>

#include "peers.h"
#include "util.h"

#define PEER_DEADLINE 3.0             /* s for all peers together */
#define PEER_MAX_ANSWER (32u << 20)   /* bytes */

typedef struct peer {
	char url[128];                /* as given */
	char hostport[112];           /* the Host header */
	struct sockaddr_storage addr;
	socklen_t addrlen;
} peer;

static peer peers[SRV_PEERS_MAX];
static size_t npeers;

/* One peer's answer in progress. */
typedef struct fetch {
	int fd;
	int done;
	char request[1024];
	size_t request_len, sent;
	char *buf;
	size_t len, cap;
	char reason[96];              /* why it failed; "" if it did not */
} fetch;

/* Parse "http://HOST:PORT" (HOST may be [v6]) into p; -1 if malformed or
 * not resolvable. */
static int parse_peer(peer *p, const char *url, size_t n)
{
	char host[96], port[8];
	if (n >= sizeof p->url || strncmp(url, "http://", 7) != 0)
		return -1;
	snprintf(p->url, sizeof p->url, "%.*s", (int)n, url);
	const char *hp = p->url + 7, *colon = strrchr(hp, ':');
	if (!colon || colon == hp || strlen(colon + 1) == 0 ||
	    strlen(colon + 1) >= sizeof port || strchr(hp, '/'))
		return -1;
	snprintf(port, sizeof port, "%s", colon + 1);
	int hl = (int)(colon - hp);
	if (hp[0] == '[' && hl >= 2 && hp[hl - 1] == ']')
		snprintf(host, sizeof host, "%.*s", hl - 2, hp + 1);
	else
		snprintf(host, sizeof host, "%.*s", hl, hp);
	snprintf(p->hostport, sizeof p->hostport, "%.*s", (int)(n - 7), url + 7);
	struct addrinfo hints = {.ai_socktype = SOCK_STREAM}, *ai = NULL;
	if (getaddrinfo(host, port, &hints, &ai) != 0 || !ai)
		return -1;
	memcpy(&p->addr, ai->ai_addr, ai->ai_addrlen);
	p->addrlen = ai->ai_addrlen;
	freeaddrinfo(ai);
	return 0;
}

int srv_peers_init(const srv_config *cfg)
{
	npeers = 0;
	for (const char *s = cfg->peers; s && *s;) {
		size_t n = strcspn(s, ",");
		if (n && (npeers == SRV_PEERS_MAX ||
			  parse_peer(&peers[npeers++], s, n) != 0)) {
			fprintf(stderr, "convsimd: --peers takes up to %d "
					"http://HOST:PORT separated by commas; "
					"cannot use \"%.*s\"\n",
				SRV_PEERS_MAX, (int)n, s);
			return -1;
		}
		s += n + (s[n] == ',');
	}
	return 0;
}

/* Open a non-blocking connection to p for f; sets f->reason on failure. */
static void fetch_start(fetch *f, const peer *p, const char *member, int csv,
			const char *authorization)
{
	f->fd = -1;
	f->request_len = (size_t)snprintf(
		f->request, sizeof f->request,
		"GET /api/v1/%s?scope=local&format=%s HTTP/1.0\r\nHost: %s\r\n"
		"Accept: %s\r\nUser-Agent: convsimd-peers\r\n%s%s%s\r\n",
		member, csv ? "csv" : "json", p->hostport,
		csv ? "text/csv" : "application/json",
		authorization ? "Authorization: " : "",
		authorization ? authorization : "", authorization ? "\r\n" : "");
	if (f->request_len >= sizeof f->request) {
		snprintf(f->reason, sizeof f->reason, "request too long");
		return;
	}
	f->fd = socket(p->addr.ss_family, SOCK_STREAM | SOCK_NONBLOCK |
				 SOCK_CLOEXEC, 0);
	if (f->fd < 0 || (connect(f->fd, (const struct sockaddr *)&p->addr,
				  p->addrlen) != 0 && errno != EINPROGRESS))
		snprintf(f->reason, sizeof f->reason, "%s", strerror(errno));
}

/* Move f on after poll() said revents; done when it failed or closed. */
static void fetch_step(fetch *f, short revents)
{
	int err = 0;
	socklen_t el = sizeof err;
	if (f->sent < f->request_len) {
		if (getsockopt(f->fd, SOL_SOCKET, SO_ERROR, &err, &el) || err) {
			snprintf(f->reason, sizeof f->reason, "%s", strerror(err));
			return;
		}
		ssize_t k = send(f->fd, f->request + f->sent,
				 f->request_len - f->sent, MSG_NOSIGNAL);
		if (k < 0 && errno != EAGAIN)
			snprintf(f->reason, sizeof f->reason, "%s", strerror(errno));
		f->sent += k > 0 ? (size_t)k : 0;
		return;
	}
	if (!(revents & (POLLIN | POLLHUP | POLLERR)))
		return;
	if (f->len + 65536 > f->cap) {
		size_t cap = f->cap ? 2 * f->cap : 65536;
		char *b = cap <= PEER_MAX_ANSWER ? realloc(f->buf, cap + 1) : NULL;
		if (!b) {
			snprintf(f->reason, sizeof f->reason, "answer too large");
			return;
		}
		f->buf = b;
		f->cap = cap;
	}
	ssize_t k = recv(f->fd, f->buf + f->len, f->cap - f->len, 0);
	if (k > 0)
		f->len += (size_t)k;
	else if (k == 0)
		f->done = 1;
	else if (errno != EAGAIN)
		snprintf(f->reason, sizeof f->reason, "%s", strerror(errno));
}

/* Drive every fetch until each is done, failed or the deadline passed. */
static void fetch_all(fetch *f, size_t n)
{
	double deadline = srv_now() + PEER_DEADLINE;
	for (;;) {
		struct pollfd pf[SRV_PEERS_MAX];
		size_t idx[SRV_PEERS_MAX], m = 0;
		for (size_t i = 0; i < n; i++)
			if (!f[i].done && !f[i].reason[0]) {
				pf[m] = (struct pollfd){f[i].fd,
					f[i].sent < f[i].request_len ? POLLOUT
								     : POLLIN, 0};
				idx[m++] = i;
			}
		double left = deadline - srv_now();
		if (m == 0)
			return;
		if (left <= 0) {
			for (size_t j = 0; j < m; j++)
				snprintf(f[idx[j]].reason, sizeof f[idx[j]].reason,
					 "no answer within %g s", PEER_DEADLINE);
			return;
		}
		int k = poll(pf, (nfds_t)m, (int)(left * 1000) + 1);
		for (size_t j = 0; k > 0 && j < m; j++)
			if (pf[j].revents)
				fetch_step(&f[idx[j]], pf[j].revents);
	}
}

const char *srv_peer_answer(char *buf, size_t len, size_t *body_len, char *reason,
			    size_t reasonlen)
{
	if (!buf) {
		snprintf(reason, reasonlen, "empty answer");
		return NULL;
	}
	buf[len] = '\0';
	int status = 0;
	char *head_end = strstr(buf, "\r\n\r\n");
	if (sscanf(buf, "HTTP/1.%*d %d", &status) != 1 || !head_end) {
		snprintf(reason, reasonlen, "not an HTTP answer");
		return NULL;
	}
	if (status != 200) {
		snprintf(reason, reasonlen, "HTTP status %d", status);
		return NULL;
	}
	*body_len = len - (size_t)(head_end + 4 - buf);
	return head_end + 4;
}

/* The body of f's answer if its status is 200, else NULL and a reason. */
static const char *fetch_body(fetch *f, size_t *len)
{
	if (f->reason[0])
		return NULL;
	return srv_peer_answer(f->buf, f->len, len, f->reason, sizeof f->reason);
}

enum MHD_Result srv_peers_reply(srv_req *r, char *local, const char *member)
{
	const char *scope = srv_query(r, "scope");
	if (scope && strcmp(scope, "all") != 0 && strcmp(scope, "local") != 0) {
		free(local);
		return srv_fail(r, API_QUERY, "scope", "scope must be all or "
				"local, not \"%.40s\"", scope);
	}
	if (!local || npeers == 0 || (scope && strcmp(scope, "local") == 0))
		return srv_reply_result(r, local);
	api_list *l = api_list_new(member, r->csv, local);
	free(local);
	fetch f[SRV_PEERS_MAX];
	memset(f, 0, sizeof f);
	const char *auth = srv_header(r, MHD_HTTP_HEADER_AUTHORIZATION);
	for (size_t i = 0; i < npeers; i++)
		fetch_start(&f[i], &peers[i], member, r->csv, auth);
	fetch_all(f, npeers);
	char unreachable[SRV_PEERS_MAX * (sizeof peers[0].url + 2)] = "";
	for (size_t i = 0; i < npeers; i++) {
		size_t len = 0;
		const char *body = fetch_body(&f[i], &len);
		if (l && body && api_list_add(l, body, len) != 0)
			snprintf(f[i].reason, sizeof f[i].reason,
				 "its answer is not a %s list", member);
		if (l && f[i].reason[0]) {
			api_list_unreachable(l, peers[i].url, f[i].reason);
			size_t at = strlen(unreachable), k = strlen(peers[i].url);
			if (at + k + 3 < sizeof unreachable) {
				memcpy(unreachable + at, ", ", at ? 2 : 0);
				memcpy(unreachable + at + (at ? 2 : 0), peers[i].url, k + 1);
			}
			srv_log(SRV_LOG_WARN, "peer %s: %s", peers[i].url,
				f[i].reason);
		}
		if (f[i].fd >= 0)
			close(f[i].fd);
		free(f[i].buf);
	}
	return srv_reply_result_with(r, api_list_finish(l), "Convsim-Unreachable",
				     unreachable[0] ? unreachable : NULL);
}
