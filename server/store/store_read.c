/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store_read.c - the framed files of the data directory (store.h): a
 * payload framed with its magic, format version, kind, length and
 * checksum, read back and checked; the restore's counts of damaged and
 * upgraded files by kind; the listings of stored ids; whether a record
 * could be removed now (a DELETE's check).
 */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "metrics.h"
#include "sim.h"
#include "store.h"
#include "util.h"

typedef struct frame_header {
	char magic[4];
	uint32_t version, kind, pad;
	uint64_t len, checksum;
} frame_header;

/* the restore's counts, by kind (written before the daemon serves) */
static struct {
	size_t damaged[8], upgraded[8];
} restore_counts;

void *srv_store_frame(uint32_t kind, const void *payload, size_t plen,
		      size_t *len)
{
	frame_header h = {{'C', 'V', 'S', 'F'}, SRV_STORE_VERSION, kind, 0,
			  plen, sim_checksum(payload, plen)};
	char *buf = malloc(sizeof h + plen);
	if (!buf)
		return NULL;
	memcpy(buf, &h, sizeof h);
	memcpy(buf + sizeof h, payload, plen);
	*len = sizeof h + plen;
	return buf;
}

char *srv_store_read_text(const char *rel, size_t *len)
{
	char path[4096];
	srv_store_path(path, sizeof path, rel);
	FILE *f = fopen(path, "rb");
	if (!f)
		return NULL;
	char *buf = NULL;
	size_t n = 0, cap = 0;
	for (;;) {
		if (n + 4096 + 1 > cap) {
			cap = cap ? 2 * cap : 8192;
			char *nb = realloc(buf, cap);
			if (!nb) {
				free(buf);
				fclose(f);
				return NULL;
			}
			buf = nb;
		}
		size_t r = fread(buf + n, 1, 4096, f);
		n += r;
		if (r < 4096)
			break;
	}
	fclose(f);
	buf[n] = '\0';
	*len = n;
	return buf;
}

void *srv_store_unframe(char *buf, size_t n, uint32_t kind, size_t *len, int *older,
			const char **bad)
{
	frame_header h;
	*bad = NULL;
	*older = 0;
	if (n < sizeof h)
		*bad = "cut off (shorter than its header)";
	if (!*bad) {
		memcpy(&h, buf, sizeof h);
		if (memcmp(h.magic, "CVSF", 4) != 0)
			*bad = "not a convsim file (bad magic)";
		else if (h.version > SRV_STORE_VERSION)
			*bad = "of a newer format version than this build reads";
		else if (h.version < SRV_STORE_OLDEST)
			*bad = "of an unknown format version";
		else if (h.kind != kind)
			*bad = "a file of another kind";
		else if (h.len > n - sizeof h)
			*bad = "cut off";
		else if (h.len < n - sizeof h)
			*bad = "longer than its header says";
		else if (sim_checksum(buf + sizeof h, h.len) != h.checksum)
			*bad = "checksum mismatch";
	}
	if (*bad) {
		free(buf);
		return NULL;
	}
	memmove(buf, buf + sizeof h, h.len);
	*len = h.len;
	if (h.version == SRV_STORE_VERSION)
		return buf;
	*older = 1;
	void *p = buf;
	if (h.version < 2)
		p = srv_store_upgrade_v1(kind, p, len, bad);
	return p ? srv_store_upgrade_v2(kind, p, len, bad) : NULL;
}

void *srv_store_read(const char *rel, uint32_t kind, size_t *len, int *older,
		     char *why, size_t whylen)
{
	size_t n = 0;
	char *buf = srv_store_read_text(rel, &n);
	const char *bad = "missing or unreadable";
	*older = 0;
	void *payload = buf ? srv_store_unframe(buf, n, kind, len, older, &bad) : NULL;
	if (!payload)
		snprintf(why, whylen, "%s: %s", rel, bad);
	return payload;
}

void srv_store_count_damaged(uint32_t kind)
{
	if (kind < sizeof restore_counts.damaged / sizeof *restore_counts.damaged)
		restore_counts.damaged[kind]++;
}

void srv_store_count_upgraded(uint32_t kind)
{
	if (kind < sizeof restore_counts.upgraded / sizeof *restore_counts.upgraded)
		restore_counts.upgraded[kind]++;
}

size_t srv_store_damaged(uint32_t kind)
{
	return kind < sizeof restore_counts.damaged / sizeof *restore_counts.damaged ? restore_counts.damaged[kind] : 0;
}

size_t srv_store_upgraded(uint32_t kind)
{
	return kind < sizeof restore_counts.upgraded / sizeof *restore_counts.upgraded ? restore_counts.upgraded[kind] : 0;
}

/* Is the entry name of rel one of the kind srv_store_list_ids lists? 1
 * yes, 0 the store's own leftovers (.tmp, .prev: skipped silently), -1
 * junk (the reason in *why). */
static int stored_entry(const char *rel, const char *name, int dirs,
			const char **why)
{
	size_t n = strlen(name);
	if (n > 4 && (strcmp(name + n - 4, ".tmp") == 0 ||
		      strcmp(name + n - 5, ".prev") == 0))
		return 0;
	char path[4096], sub[1024];
	struct stat sb;
	snprintf(sub, sizeof sub, "%s/%s", rel, name);
	srv_store_path(path, sizeof path, sub);
	size_t idlen = dirs ? n : n > 4 && strcmp(name + n - 4, ".bin") == 0 ? n - 4 : 0;
	if (lstat(path, &sb) != 0)
		*why = strerror(errno);
	else if (dirs ? !S_ISDIR(sb.st_mode) : !S_ISREG(sb.st_mode))
		*why = dirs ? "not a directory" : "not a regular file";
	else if (!srv_id_valid(name, idlen))
		*why = dirs ? "not named by an id" : "not named ID.bin";
	else
		return 1;
	return -1;
}

size_t srv_store_list_ids(const char *rel, int dirs, char ***names)
{
	size_t n = srv_store_list(rel, names), kept = 0;
	for (size_t i = 0; i < n; i++) {
		const char *why = NULL;
		int ok = stored_entry(rel, (*names)[i], dirs, &why);
		if (ok < 0)
			srv_log(SRV_LOG_WARN, "data dir: ignored %s/%.100s: %s",
				rel, (*names)[i], why);
		if (ok > 0)
			(*names)[kept++] = (*names)[i];
		else
			free((*names)[i]);
	}
	return kept;
}

int srv_store_dir_unwritten(const char *rel)
{
	char **names = NULL;
	size_t n = srv_store_list(rel, &names), files = 0;
	for (size_t i = 0; i < n; i++) {
		size_t l = strlen(names[i]);
		files += !(l > 4 && strcmp(names[i] + l - 4, ".tmp") == 0);
		free(names[i]);
	}
	free(names);
	return files == 0;
}

size_t srv_store_list(const char *rel, char ***names)
{
	char path[4096];
	srv_store_path(path, sizeof path, rel);
	*names = NULL;
	DIR *d = opendir(path);
	if (!d)
		return 0;
	size_t n = 0, cap = 0;
	struct dirent *de;
	while ((de = readdir(d))) {
		if (de->d_name[0] == '.')
			continue;
		if (n == cap) {
			cap = cap ? 2 * cap : 64;
			char **nn = realloc(*names, cap * sizeof *nn);
			if (!nn)
				break;
			*names = nn;
		}
		(*names)[n] = strdup(de->d_name);
		if ((*names)[n])
			n++;
	}
	closedir(d);
	return n;
}

api_err srv_store_check_removable(const char *rel, api_problem *pb)
{
	if (!srv_store_enabled())
		return API_OK;
	char path[4096];
	struct stat sb;
	srv_store_path(path, sizeof path, rel);
	int is_dir = stat(path, &sb) == 0 && S_ISDIR(sb.st_mode);
	/* its directory (the entry goes), and the entry's own when it is
	 * one (its files go) */
	char *slash = strrchr(path, '/');
	int err = 0;
	if (slash) {
		*slash = '\0';
		err = access(path, W_OK) != 0 && errno != ENOENT ? errno : 0;
		*slash = '/';
	}
	if (!err && is_dir && access(path, W_OK) != 0 && errno != ENOENT)
		err = errno;
	if (!err)
		return API_OK;
	api_fail(pb, API_UNAVAILABLE, NULL,
		 "the data directory cannot be changed (%s): %s cannot be "
		 "removed; nothing was deleted, retry once it is writable",
		 strerror(err), rel);
	pb->retry_after = 30;
	return API_UNAVAILABLE;
}
