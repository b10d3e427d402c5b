/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * control_log.c - a session's control log on disk, sessions/ID/
 * controls.ndjson: a 200 on a control means its line is there, written
 * and fdatasync'd, before the answer leaves.
 *
 * The worker applies a control and appends its line to the session's log
 * in memory (s->controls, session lock held); it never touches the disk.
 * The handler that waits for the control then makes the log durable up to
 * its line (srv_control_log_sync) by group commit: the first thread that
 * finds lines not yet on disk becomes the leader, copies every line
 * appended so far, writes them with one pwrite at the end of what is on
 * disk and syncs once; the threads whose lines that covered wait for it
 * and return, the others lead the next round. So concurrent controls of
 * one session share one fdatasync, and controls of different sessions
 * sync in parallel (each handler its own file: the file system commits
 * them together). Lines nobody waits for (an experiment's segments, a
 * pace-down) are flushed the same way from the store's writer thread
 * (a closed loop's per-period beta is not: the experiment sends it again
 * after a restore, so its line goes with the next sync that comes),
 * and a checkpoint is written only once the log lines it accounts for
 * are on disk (session_store.c), so that a checkpoint never holds more
 * of the log than the file does.
 *
 * The file is opened at its first sync, in the session's directory made
 * when the session was created (never made here: a session deleted
 * meanwhile is not brought back), and cut to what was last known durable:
 * a line a crash cut short was never acknowledged.
 */
#include <errno.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "metrics.h"
#include "session_int.h"
#include "store.h"
#include "util.h"

/* Write len bytes of buf at offset off of s's log (opened on first use),
 * then fdatasync: 0 or an errno. Worker lock not held. */
static int write_durable(srv_session *s, int *fd, const char *buf, size_t len, size_t off)
{
	if (*fd < 0) {
		char path[128];
		snprintf(path, sizeof path, "sessions/%s/controls.ndjson", s->entry.id);
		*fd = srv_store_open_log(path, off);
		if (*fd < 0)
			return errno ? errno : EIO;
	}
	for (size_t done = 0; done < len;) {
		ssize_t w = pwrite(*fd, buf + done, len - done, (off_t)(off + done));
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			return w < 0 ? errno : EIO;
		done += (size_t)w;
	}
	return fdatasync(*fd) == 0 ? 0 : errno;
}

int srv_control_log_sync(srv_session *s, size_t end, double timeout_s)
{
	int rc = 0;
	struct timespec until = srv_deadline(timeout_s);
	pthread_mutex_lock(&s->lock);
	while (s->log.synced < end) {
		if (s->log.syncing) { /* a leader is at it: its round may hold ours */
			if (pthread_cond_timedwait(&s->log.cond, &s->lock, &until) == ETIMEDOUT) {
				rc = ETIMEDOUT;
				break;
			}
			continue;
		}
		/* lead a round: everything appended so far */
		size_t from = s->log.synced, to = s->controls_len;
		char *copy = malloc(to - from);
		if (!copy) {
			rc = ENOMEM;
			break;
		}
		memcpy(copy, s->controls + from, to - from);
		s->log.syncing = 1;
		int fd = s->log.fd;
		pthread_mutex_unlock(&s->lock);
		int err = write_durable(s, &fd, copy, to - from, from);
		free(copy);
		pthread_mutex_lock(&s->lock);
		s->log.fd = fd;
		s->log.syncing = 0;
		if (!err) {
			s->log.synced = to;
			atomic_fetch_add(&srv_stats.log_syncs, 1);
		} else {
			snprintf(s->persist.store_error, sizeof s->persist.store_error,
				 "cannot write sessions/%s/controls.ndjson: %s", s->entry.id,
				 strerror(err));
			atomic_fetch_add(&srv_stats.store_errors, 1);
		}
		pthread_cond_broadcast(&s->log.cond);
		if (err) {
			rc = err;
			break;
		}
	}
	pthread_mutex_unlock(&s->lock);
	return rc;
}

/* The store's writer: make the lines nobody waits for durable. */
static void flush(void *arg)
{
	char *id = arg;
	srv_entry *en = srv_registry_get(&srv_sessions_registry, id);
	free(id);
	if (!en)
		return;
	srv_session *s = SRV_CONTAINER(en, srv_session, entry);
	pthread_mutex_lock(&s->lock);
	s->log.flush_queued = 0;
	size_t end = s->controls_len;
	pthread_mutex_unlock(&s->lock);
	int err = srv_control_log_sync(s, end, 30.0);
	if (err)
		srv_log(SRV_LOG_ERROR, "session %s: the control log: %s", s->entry.id,
			strerror(err));
	srv_registry_put(&srv_sessions_registry, en);
}

size_t srv_control_log_append(srv_session *s, const char *json, int durable)
{
	if (!srv_store_enabled())
		return 0;
	size_t add = strlen(json) + 1;
	if (s->controls_len + add + 1 > s->controls_cap) {
		size_t cap = s->controls_cap ? 2 * s->controls_cap : 4096;
		while (cap < s->controls_len + add + 1)
			cap *= 2;
		char *nc = realloc(s->controls, cap);
		if (!nc)
			return 0;
		s->controls = nc;
		s->controls_cap = cap;
	}
	memcpy(s->controls + s->controls_len, json, add - 1);
	s->controls_len += add;
	s->controls[s->controls_len - 1] = '\n';
	if (durable == SRV_LINE_FLUSH && !s->log.flush_queued) {
		char *id = strdup(s->entry.id);
		if (id) {
			s->log.flush_queued = 1;
			srv_store_call(flush, id);
		}
	}
	return s->controls_len;
}

void srv_control_log_close(srv_session *s)
{
	if (s->log.fd >= 0)
		close(s->log.fd);
	s->log.fd = -1;
}
