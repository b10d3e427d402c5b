/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * static.c - the dashboard's files: GET / serves web/index.html, other
 * paths the file of that name under --web-root, with a Content-Type by
 * extension. Paths with "..", "//", backslashes or hidden segments are
 * refused, and the resolved path (links followed) must stay inside the
 * web root, so no request reaches a file outside it. Only regular files
 * are served: a FIFO, a device, a socket or a directory is "not found",
 * and opening one never blocks (O_NONBLOCK, then fstat).
 */
#include <fcntl.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "static.h"

static const srv_config *cfg;

void srv_static_init(const srv_config *config)
{
	cfg = config;
}

static const struct {
	const char *ext, *type;
} types[] = {
	{".html", "text/html; charset=utf-8"},
	{".js", "text/javascript; charset=utf-8"},
	{".mjs", "text/javascript; charset=utf-8"},
	{".css", "text/css; charset=utf-8"},
	{".json", "application/json"},
	{".map", "application/json"},
	{".svg", "image/svg+xml"},
	{".png", "image/png"},
	{".ico", "image/x-icon"},
	{".txt", "text/plain; charset=utf-8"},
	{".md", "text/markdown; charset=utf-8"},
	{".woff2", "font/woff2"},
	{".csv", "text/csv"},
};

static const char *content_type(const char *path)
{
	const char *dot = strrchr(path, '.');
	for (size_t i = 0; dot && i < sizeof types / sizeof *types; i++)
		if (strcmp(dot, types[i].ext) == 0)
			return types[i].type;
	return "application/octet-stream";
}

/* Only plain relative segments: no "..", ".x", "//" or backslashes. */
static int safe_path(const char *p)
{
	if (*p != '/' || strchr(p, '\\') || strstr(p, "//"))
		return 0;
	for (const char *s = p; s; s = strchr(s + 1, '/'))
		if (s[1] == '.')
			return 0;
	return 1;
}

static enum MHD_Result missing(srv_req *r)
{
	return srv_fail(r, API_NOTFOUND, NULL, "no such file: %.200s", r->url);
}

enum MHD_Result srv_h_static(srv_req *r)
{
	const char *url = strcmp(r->url, "/") == 0 ? "/index.html" : r->url;
	char path[PATH_MAX], root[PATH_MAX], real[PATH_MAX];
	if (!safe_path(url))
		return missing(r);
	if (!realpath(cfg->web_root, root))
		return missing(r);
	int n = snprintf(path, sizeof path, "%s%s", root, url);
	if (n < 0 || (size_t)n >= sizeof path || !realpath(path, real))
		return missing(r);
	size_t rl = strlen(root);
	if (strncmp(real, root, rl) != 0 || real[rl] != '/')
		return missing(r);
	/* the resolved path is opened without following a link put there
	 * since, and without waiting for a FIFO's writer: only a regular
	 * file is served */
	int fd = open(real, O_RDONLY | O_CLOEXEC | O_NOFOLLOW | O_NONBLOCK);
	struct stat sb;
	if (fd < 0)
		return missing(r);
	if (fstat(fd, &sb) != 0 || !S_ISREG(sb.st_mode)) {
		close(fd);
		return missing(r);
	}
	struct MHD_Response *resp =
		MHD_create_response_from_fd((uint64_t)sb.st_size, fd);
	if (!resp) {
		close(fd);
		return MHD_NO;
	}
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CONTENT_TYPE,
				content_type(real));
	MHD_add_response_header(resp, MHD_HTTP_HEADER_CACHE_CONTROL,
				"no-cache");
	MHD_add_response_header(resp, "X-Content-Type-Options", "nosniff");
	return srv_queue(r, 200, resp);
}
