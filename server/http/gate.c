/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * gate.c - the request gate (see gate.h): Host, Origin, CORS preflight,
 * bearer token and the JSON Content-Type of mutating requests, checked on
 * the headers alone so that a refused request is never read further and
 * changes nothing.
 *
 * The token is read once at start-up from --token-file and compared in
 * constant time (the time depends on the token's length only, never on
 * where the first differing byte is). Host must name the address the
 * daemon listens on with its port (any IP literal when it listens on
 * every interface; "localhost" on loopback) or a --server-name: a page
 * whose name was rebound to this machine's address still sends its own
 * name and is refused with 421. The daemon's own origins are http:// and
 * https:// followed by a Host that passed.
 */
#include <arpa/inet.h>
#include <errno.h>
#include <fcntl.h>
#include <stdatomic.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/stat.h>
#include <unistd.h>

#include "gate.h"

#define TOKEN_MIN 16

static const srv_config *cfg;
static char token[512];
static size_t token_len; /* 0: no token asked */
static atomic_int bound_port;

/* 1 if addr is 127.0.0.0/8, ::1 or ::ffff:127.x.y.z. */
static int is_loopback(const char *addr)
{
	struct in_addr a4;
	struct in6_addr a6;
	if (inet_pton(AF_INET, addr, &a4) == 1)
		return (ntohl(a4.s_addr) >> 24) == 127;
	if (inet_pton(AF_INET6, addr, &a6) != 1)
		return 0;
	if (IN6_IS_ADDR_LOOPBACK(&a6))
		return 1;
	return IN6_IS_ADDR_V4MAPPED(&a6) && a6.s6_addr[12] == 127;
}

static int is_wildcard(const char *addr)
{
	return strcmp(addr, "0.0.0.0") == 0 || strcmp(addr, "::") == 0;
}

/* Read and check the token file; -1 with a message. */
static int load_token(const char *file)
{
	int fd = open(file, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
	struct stat sb;
	if (fd < 0) {
		fprintf(stderr, "convsimd: --token-file %s: %s\n", file,
			strerror(errno));
		return -1;
	}
	const char *why = NULL;
	ssize_t n = 0;
	if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode))
		why = "is not a regular file";
	else if (sb.st_mode & (S_IRWXG | S_IRWXO))
		why = "may be read or written by group or others; "
		      "chmod 600 it";
	else if ((n = read(fd, token, sizeof token)) < 0)
		why = strerror(errno);
	else if ((size_t)n == sizeof token)
		why = "holds more than 511 bytes";
	close(fd);
	while (!why && n > 0 && strchr(" \t\r\n", token[n - 1]))
		n--;
	for (ssize_t i = 0; !why && i < n; i++)
		if (token[i] < 0x21 || token[i] > 0x7e)
			why = "holds a character that is not printable ASCII "
			      "(spaces are not allowed)";
	if (!why && n < TOKEN_MIN)
		why = n == 0 ? "is empty" : "holds fewer than 16 characters";
	if (why) {
		fprintf(stderr, "convsimd: --token-file %s %s (mode %04o)\n",
			file, why, (unsigned)(sb.st_mode & 07777));
		memset(token, 0, sizeof token);
		return -1;
	}
	token_len = (size_t)n;
	token[token_len] = '\0';
	return 0;
}

int srv_gate_init(const srv_config *config)
{
	cfg = config;
	atomic_store(&bound_port, cfg->port);
	if (cfg->token_file && load_token(cfg->token_file))
		return -1;
	if (!cfg->token_file && !cfg->insecure && !is_loopback(cfg->listen)) {
		fprintf(stderr,
			"convsimd: --listen %s reaches beyond this machine: "
			"give --token-file FILE, or --insecure to serve "
			"without a token\n",
			cfg->listen);
		return -1;
	}
	return 0;
}

void srv_gate_set_port(int port)
{
	atomic_store(&bound_port, port);
}

void srv_gate_shutdown(void)
{
	memset(token, 0, sizeof token);
	token_len = 0;
}

/* Split a Host header into its name (brackets of an IPv6 literal
 * removed) and port (80 when absent). 0 if malformed. */
static int split_host(const char *host, char *name, size_t cap, long *port)
{
	const char *end, *colon;
	if (host[0] == '[') {
		end = strchr(host, ']');
		if (!end)
			return 0;
		host++;
		colon = end[1] == ':' ? end + 1 : NULL;
		if (end[1] && !colon)
			return 0;
	} else {
		colon = strchr(host, ':');
		end = colon ? colon : host + strlen(host);
	}
	size_t n = (size_t)(end - host);
	if (n == 0 || n >= cap)
		return 0;
	memcpy(name, host, n);
	name[n] = '\0';
	*port = 80;
	if (colon) {
		/* 1 to 5 digits without a leading zero, as clients write a
		 * port: no sign, no space, no 032100 */
		const char *digits = colon + 1;
		size_t k = strspn(digits, "0123456789");
		if (k == 0 || k > 5 || digits[k] || (digits[0] == '0' && k > 1))
			return 0;
		*port = strtol(digits, NULL, 10);
		if (*port > 65535)
			return 0;
	}
	return 1;
}

/* 1 if the IP literal name is the listening address (any, on a
 * wildcard); -1 if name is no IP literal. */
static int same_address(const char *name)
{
	unsigned char a[16], l[16];
	int fam = strchr(name, ':') ? AF_INET6 : AF_INET;
	if (inet_pton(fam, name, a) != 1)
		return -1;
	if (is_wildcard(cfg->listen))
		return 1;
	size_t n = fam == AF_INET6 ? 16 : 4;
	return inet_pton(fam, cfg->listen, l) == 1 && memcmp(a, l, n) == 0;
}

/* Does the Host header name this daemon? */
static int host_ok(const char *host)
{
	char name[256];
	long port;
	for (int i = 0; i < cfg->server_names.n; i++)
		if (strcasecmp(host, cfg->server_names.v[i]) == 0)
			return 1;
	if (!split_host(host, name, sizeof name, &port))
		return 0;
	if (port != atomic_load(&bound_port))
		return 0;
	for (int i = 0; i < cfg->server_names.n; i++)
		if (strcasecmp(name, cfg->server_names.v[i]) == 0)
			return 1;
	int same = same_address(name);
	if (same >= 0)
		return same;
	return strcasecmp(name, "localhost") == 0 &&
	       (is_loopback(cfg->listen) || is_wildcard(cfg->listen));
}

/* Is origin ours (http or https with a Host that passed) or allowed? */
static int origin_ok(const char *origin, const char *host)
{
	static const char *const schemes[] = {"http://", "https://"};
	for (size_t i = 0; i < 2; i++) {
		size_t n = strlen(schemes[i]);
		if (strncasecmp(origin, schemes[i], n) == 0 &&
		    strcasecmp(origin + n, host) == 0)
			return 1;
	}
	for (int i = 0; i < cfg->allow_origins.n; i++)
		if (strcasecmp(origin, cfg->allow_origins.v[i]) == 0)
			return 1;
	return 0;
}

/* given (n bytes) equals the token, in time that depends on the token's
 * length only. */
static int token_equal(const char *given, size_t n)
{
	volatile unsigned char diff = (unsigned char)(n != token_len);
	for (size_t i = 0; i < token_len; i++)
		diff |= (unsigned char)(token[i] ^ (i < n ? given[i] : 0));
	return diff == 0;
}

/* 0: no Authorization; 1: the right bearer token; -1: another. */
static int bearer(const char *auth)
{
	if (!auth)
		return 0;
	while (*auth == ' ')
		auth++;
	if (strncasecmp(auth, "Bearer ", 7) != 0)
		return -1;
	auth += 7;
	while (*auth == ' ')
		auth++;
	size_t n = strlen(auth);
	while (n > 0 && auth[n - 1] == ' ')
		n--;
	return token_equal(auth, n) ? 1 : -1;
}

/* Routes that need the token: the API but its health, and /metrics. */
static int needs_token(const char *url)
{
	if (strcmp(url, "/api/v1/health") == 0)
		return 0;
	return strncmp(url, "/api/", 5) == 0 || strcmp(url, "/api") == 0 ||
	       strcmp(url, "/metrics") == 0;
}

static int json_type(const char *ct)
{
	static const char *const types[] = {"application/json",
					    "application/merge-patch+json",
					    "application/problem+json"};
	while (*ct == ' ')
		ct++;
	for (size_t i = 0; i < sizeof types / sizeof *types; i++) {
		size_t n = strlen(types[i]);
		if (strncasecmp(ct, types[i], n) == 0 &&
		    (ct[n] == '\0' || ct[n] == ';' || ct[n] == ' '))
			return 1;
	}
	return 0;
}

static int mutating(const char *method)
{
	return strcmp(method, "POST") == 0 || strcmp(method, "PATCH") == 0 ||
	       strcmp(method, "PUT") == 0 || strcmp(method, "DELETE") == 0;
}

/* 204 to a preflight of an allowed origin. */
static enum MHD_Result preflight(srv_req *r)
{
	struct MHD_Response *resp =
		MHD_create_response_from_buffer(0, NULL, MHD_RESPMEM_PERSISTENT);
	if (!resp)
		return MHD_NO;
	MHD_add_response_header(resp, "Access-Control-Allow-Methods",
				"GET, HEAD, POST, PATCH, PUT, DELETE");
	MHD_add_response_header(resp, "Access-Control-Allow-Headers",
				"Authorization, Content-Type, Accept, "
				"Last-Event-ID");
	MHD_add_response_header(resp, "Access-Control-Max-Age", "600");
	return srv_queue(r, 204, resp);
}

/* The checks before the token: Host, then Origin and the preflight.
 * 1: go on; 0: answered. */
static int check_peer(srv_req *r, enum MHD_Result *result)
{
	const char *host = srv_header(r, MHD_HTTP_HEADER_HOST);
	const char *origin = srv_header(r, "Origin");
	if (!host) {
		*result = srv_fail(r, API_BADREQUEST, "Host",
				   "the request has no Host header");
		return 0;
	}
	if (srv_header_count(r, MHD_HTTP_HEADER_HOST) > 1) {
		*result = srv_fail(r, API_BADREQUEST, "Host",
				   "Host is given more than once (RFC 9112 "
				   "section 3.2)");
		return 0;
	}
	if (!host_ok(host)) {
		*result = srv_fail(r, API_MISDIRECTED, "Host",
				   "Host \"%.100s\" names neither the address "
				   "this daemon listens on nor a --server-name",
				   host);
		return 0;
	}
	if (origin && !origin_ok(origin, host)) {
		*result = srv_fail(r, API_FORBIDDEN, "Origin",
				   "origin \"%.100s\" may not call this daemon: "
				   "only its own origin and those given with "
				   "--allow-origin may",
				   origin);
		return 0;
	}
	r->cors_origin = origin;
	if (origin && strcmp(r->method, "OPTIONS") == 0) {
		*result = preflight(r);
		return 0;
	}
	return 1;
}

int srv_gate_check(srv_req *r, enum MHD_Result *result)
{
	if (!check_peer(r, result))
		return 0;
	int auth = token_len && needs_token(r->url)
			   ? bearer(srv_header(r, MHD_HTTP_HEADER_AUTHORIZATION))
			   : 1;
	if (auth != 1) {
		api_problem pb;
		api_fail(&pb, API_UNAUTHORIZED, "Authorization", "%s",
			 auth == 0 ? "this route needs Authorization: Bearer "
				     "TOKEN (the daemon runs with --token-file)"
				   : "the bearer token is not this daemon's");
		*result = srv_reply_problem_with(
			r, &pb, MHD_HTTP_HEADER_WWW_AUTHENTICATE,
			auth == 0 ? "Bearer realm=\"convsim\""
				  : "Bearer realm=\"convsim\", "
				    "error=\"invalid_token\"");
		return 0;
	}
	const char *ct = srv_header(r, MHD_HTTP_HEADER_CONTENT_TYPE);
	if (mutating(r->method) && !(ct && json_type(ct))) {
		*result = srv_fail(r, API_MEDIATYPE, "Content-Type",
				   "%s needs Content-Type: application/json, "
				   "even with an empty body (got \"%.60s\")",
				   r->method, ct ? ct : "none");
		return 0;
	}
	return 1;
}
