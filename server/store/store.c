/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * store.c - the writer thread and the framed files of the data directory
 * (store.h).
 *
 * The writer takes jobs from one FIFO queue: writes (superseding a
 * pending write to the same path in place) and removals. A write is
 * open(path.tmp) -> write all -> fsync -> close (each checked) -> [path.prev
 * made a second name of path] -> rename(path.tmp, path) -> fsync of the
 * directory;
 * on any failure the temporary file is removed and the file it would have
 * replaced stays as it was. So a reader finds the old file or the new
 * one, whole, never a mixture, whatever moment the daemon dies. The
 * framed files read back and the listings are store_read.c's.
 */
#define _GNU_SOURCE /* pthread_setname_np: the writer shows as "store" */
#include <dirent.h>
#include <errno.h>
#include <fcntl.h>
#include <pthread.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "metrics.h"
#include "sim.h"
#include "store.h"
#include "util.h"

typedef struct store_job {
	char path[256];
	int notify;           /* only call done (a superseded write) */
	void *buf;            /* NULL: remove path */
	size_t len;
	int keep_prev;
	srv_store_done done;
	void (*before)(void *arg); /* called just before the write */
	void (*call)(void *arg);   /* a call in order (srv_store_call) */
	void *arg;
	struct store_job *next;
} store_job;

static struct {
	const char *dir;
	double interval;
	pthread_mutex_t lock;
	pthread_cond_t wake;
	store_job *head, *tail;
	int stop, started;
	pthread_t thread;
	/* srv_store_watch on: the writes that failed since (lock held) */
	int watching;
	size_t failed;
	char failed_what[1024];
} st = {.lock = PTHREAD_MUTEX_INITIALIZER, .wake = PTHREAD_COND_INITIALIZER};

void srv_store_path(char *out, size_t len, const char *rel)
{
	snprintf(out, len, "%s/%s", st.dir, rel);
}

/* mkdir -p of the parent of abs path p. */
static int make_parents(const char *p)
{
	char tmp[4096];
	snprintf(tmp, sizeof tmp, "%s", p);
	for (char *c = tmp + 1; *c; c++)
		if (*c == '/') {
			*c = '\0';
			if (mkdir(tmp, 0755) != 0 && errno != EEXIST)
				return -1;
			*c = '/';
		}
	return 0;
}

static int fsync_parent(const char *p)
{
	char dir[4096];
	snprintf(dir, sizeof dir, "%s", p);
	char *slash = strrchr(dir, '/');
	if (slash)
		*slash = '\0';
	int fd = open(dir, O_RDONLY | O_DIRECTORY | O_CLOEXEC);
	if (fd < 0)
		return -1;
	int rc = fsync(fd);
	int e = errno;
	close(fd);
	errno = e;
	return rc;
}

/* The atomic write of one job through path + tmp_ext: 0, or an errno
 * with what in msg. */
static int write_atomic(const store_job *j, const char *tmp_ext, char *msg, size_t msglen)
{
	char path[4096], tmp[4200], prev[4200];
	srv_store_path(path, sizeof path, j->path);
	snprintf(tmp, sizeof tmp, "%s%s", path, tmp_ext);
	snprintf(prev, sizeof prev, "%s.prev", path);
	const char *step = "create the directory of";
	int fd = -1, err = 0;
	if (make_parents(path) != 0)
		goto fail;
	step = "create";
	fd = open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
	if (fd < 0)
		goto fail;
	step = "write";
	for (size_t off = 0; off < j->len;) {
		ssize_t w = write(fd, (const char *)j->buf + off, j->len - off);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0) {
			if (w == 0)
				errno = EIO;
			goto fail;
		}
		off += (size_t)w;
	}
	step = "fsync";
	if (fsync(fd) != 0)
		goto fail;
	step = "close";
	int c = close(fd);
	fd = -1;
	if (c != 0)
		goto fail;
	/* the previous version as a second name of the current file, so that
	 * path names a whole file at every moment (a rename of path to
	 * path.prev left none between the two renames: a kill there lost the
	 * latest checkpoint's name) */
	step = "keep the previous version of";
	if (j->keep_prev && ((unlink(prev) != 0 && errno != ENOENT) ||
			     (link(path, prev) != 0 && errno != ENOENT)))
		goto fail;
	step = "rename into place";
	if (rename(tmp, path) != 0)
		goto fail;
	step = "fsync the directory of";
	if (fsync_parent(path) != 0)
		goto fail;
	return 0;
fail:
	err = errno ? errno : EIO;
	if (fd >= 0)
		close(fd);
	unlink(tmp);
	snprintf(msg, msglen, "cannot %s %s: %s", step, j->path, strerror(err));
	return err;
}

/* Remove a file or a directory tree (one level of files is all the
 * store makes under a directory). */
static void remove_path(const char *rel)
{
	char path[4096];
	srv_store_path(path, sizeof path, rel);
	DIR *d = opendir(path);
	if (d) {
		struct dirent *de;
		while ((de = readdir(d)))
			if (strcmp(de->d_name, ".") && strcmp(de->d_name, "..")) {
				char f[4400];
				snprintf(f, sizeof f, "%s/%s", path, de->d_name);
				unlink(f);
			}
		closedir(d);
		rmdir(path);
	} else {
		unlink(path);
	}
	fsync_parent(path);
}

/* A failed write while srv_store_watch is on (writer thread). */
static void note_failure(const char *path, const char *msg)
{
	pthread_mutex_lock(&st.lock);
	size_t n = strlen(st.failed_what);
	if (st.watching && st.failed++ == 0)
		snprintf(st.failed_what, sizeof st.failed_what, "%.900s", msg);
	else if (st.watching && n + strlen(path) + 3 < sizeof st.failed_what)
		snprintf(st.failed_what + n, sizeof st.failed_what - n, "; %s", path);
	pthread_mutex_unlock(&st.lock);
}

/* A write's outcome counted and logged (err 0: written). */
static void note_write(const char *path, int err, const char *msg)
{
	if (err) {
		atomic_fetch_add(&srv_stats.store_errors, 1);
		srv_log(SRV_LOG_ERROR, "store: %s", msg);
		note_failure(path, msg);
	} else {
		atomic_fetch_add(&srv_stats.store_writes, 1);
	}
}

int srv_store_write_now(const char *path, const void *buf, size_t len, char *msg,
			size_t msglen)
{
	if (!st.started)
		return 0;
	store_job j = {.buf = (void *)buf, .len = len};
	snprintf(j.path, sizeof j.path, "%s", path);
	/* a temporary file of its own: the writer may be at the same path
	 * (an experiment that ended at once), and the later rename wins */
	int err = write_atomic(&j, ".now.tmp", msg, msglen);
	note_write(path, err, msg);
	return err;
}

static void run_job(store_job *j)
{
	char msg[4400] = "";
	int err = 0;
	if (j->call) {
		j->call(j->arg);
		free(j);
		return;
	}
	if (j->notify) {
		/* superseded: nothing to write, done says so */
	} else if (j->buf) {
		if (j->before)
			j->before(j->arg);
		err = write_atomic(j, ".tmp", msg, sizeof msg);
		note_write(j->path, err, msg);
	} else {
		remove_path(j->path);
	}
	if (j->done)
		j->done(j->arg, err, msg);
	free(j->buf);
	free(j);
}

static void *writer_main(void *arg)
{
	(void)arg;
	pthread_setname_np(pthread_self(), "store");
	pthread_mutex_lock(&st.lock);
	for (;;) {
		while (!st.head && !st.stop)
			pthread_cond_wait(&st.wake, &st.lock);
		store_job *j = st.head;
		if (!j)
			break;
		st.head = j->next;
		if (!st.head)
			st.tail = NULL;
		pthread_mutex_unlock(&st.lock);
		run_job(j);
		pthread_mutex_lock(&st.lock);
	}
	pthread_mutex_unlock(&st.lock);
	return NULL;
}

/* DIR/node-id names the replica whose ids the directory holds: a start
 * with another --node-id (or none) would serve ids a proxy routes
 * elsewhere, so it is refused. Written (here, before the writer starts)
 * at the first start with a node id. */
static int check_node_id(const char *node_id)
{
	char p[4096], held[64] = "";
	srv_store_path(p, sizeof p, "node-id");
	FILE *f = fopen(p, "r");
	if (f) {
		if (!fgets(held, sizeof held, f))
			held[0] = '\0';
		fclose(f);
		held[strcspn(held, "\n")] = '\0';
		if (strcmp(held, node_id ? node_id : "") == 0)
			return 0;
		fprintf(stderr, "convsimd: --data-dir %s belongs to --node-id "
				"%s (its file node-id); start it with that "
				"node id\n", st.dir, held[0] ? held : "(none)");
		return -1;
	}
	if (!node_id)
		return 0;
	f = fopen(p, "w");
	int bad = !f || fprintf(f, "%s\n", node_id) < 0;
	if (f && fclose(f) != 0)
		bad = 1;
	if (bad)
		fprintf(stderr, "convsimd: cannot write %s\n", p);
	return bad ? -1 : 0;
}

int srv_store_open(const srv_config *cfg)
{
	st.dir = cfg->data_dir;
	st.interval = cfg->checkpoint_interval;
	if (!st.dir)
		return 0;
	static const char *const subdirs[] = {"sessions", "experiments", "sweeps", "fits"};
	for (size_t i = 0; i < sizeof subdirs / sizeof *subdirs; i++) {
		char p[4096];
		srv_store_path(p, sizeof p, subdirs[i]);
		if (mkdir(p, 0755) != 0 && errno != EEXIST) {
			fprintf(stderr, "convsimd: cannot create %s: %s\n", p,
				strerror(errno));
			return -1;
		}
	}
	if (check_node_id(cfg->node_id))
		return -1;
	if (pthread_create(&st.thread, NULL, writer_main, NULL) != 0) {
		fprintf(stderr, "convsimd: cannot start the store's writer\n");
		return -1;
	}
	st.started = 1;
	return 0;
}

void srv_store_close(void)
{
	if (!st.started)
		return;
	pthread_mutex_lock(&st.lock);
	st.stop = 1;
	pthread_cond_broadcast(&st.wake);
	pthread_mutex_unlock(&st.lock);
	pthread_join(st.thread, NULL);
	st.started = 0;
}

void srv_store_watch(void)
{
	pthread_mutex_lock(&st.lock);
	st.watching = 1;
	pthread_mutex_unlock(&st.lock);
}

size_t srv_store_failed(char *what, size_t len)
{
	pthread_mutex_lock(&st.lock);
	size_t n = st.failed;
	snprintf(what, len, "%s", st.failed_what);
	pthread_mutex_unlock(&st.lock);
	return n;
}

int srv_store_enabled(void)
{
	return st.dir != NULL;
}

double srv_store_interval(void)
{
	return st.interval;
}

static void enqueue(store_job *j)
{
	pthread_mutex_lock(&st.lock);
	j->next = NULL;
	if (st.tail)
		st.tail->next = j;
	else
		st.head = j;
	st.tail = j;
	pthread_cond_broadcast(&st.wake);
	pthread_mutex_unlock(&st.lock);
}

void srv_store_write(const char *path, void *buf, size_t len, int keep_prev,
		     srv_store_done done, void *arg)
{
	srv_store_write_after(path, buf, len, keep_prev, NULL, done, arg);
}

void srv_store_write_after(const char *path, void *buf, size_t len, int keep_prev,
			   void (*before)(void *arg), srv_store_done done, void *arg)
{
	store_job *j = st.started ? calloc(1, sizeof *j) : NULL;
	if (!j) { /* off (callers check first) or out of memory */
		free(buf);
		return;
	}
	snprintf(j->path, sizeof j->path, "%s", path);
	j->buf = buf;
	j->len = len;
	j->keep_prev = keep_prev;
	j->done = done;
	j->before = before;
	j->arg = arg;
	/* supersede a pending write to the same path in place */
	store_job *old = NULL;
	pthread_mutex_lock(&st.lock);
	for (store_job *q = st.head; q; q = q->next)
		if (q->buf && strcmp(q->path, j->path) == 0) {
			old = malloc(sizeof *old);
			if (!old)
				break;
			*old = *q;
			q->buf = j->buf;
			q->len = j->len;
			q->keep_prev = j->keep_prev;
			q->done = j->done;
			q->before = j->before;
			q->arg = j->arg;
			break;
		}
	pthread_mutex_unlock(&st.lock);
	if (old) {
		/* the caller may hold a lock the callback takes: the writer
		 * calls it */
		free(j);
		free(old->buf);
		old->buf = NULL;
		old->before = NULL;
		old->notify = 1;
		enqueue(old);
		return;
	}
	enqueue(j);
}

void srv_store_call(void (*fn)(void *arg), void *arg)
{
	store_job *j = st.started ? calloc(1, sizeof *j) : NULL;
	if (!j)
		return;
	j->call = fn;
	j->arg = arg;
	enqueue(j);
}

int srv_store_make_dir(const char *rel)
{
	if (!st.started)
		return 0;
	char path[4096];
	srv_store_path(path, sizeof path, rel);
	if (mkdir(path, 0755) != 0)
		return errno == EEXIST ? 0 : -1;
	return fsync_parent(path);
}

int srv_store_open_log(const char *rel, uint64_t len)
{
	char path[4096];
	srv_store_path(path, sizeof path, rel);
	int fd = open(path, O_WRONLY | O_CREAT | O_CLOEXEC, 0644);
	if (fd < 0)
		return -1;
	/* what lies past len was never acknowledged (a line cut short by a
	 * crash): cut it, and make the file's name durable */
	if (ftruncate(fd, (off_t)len) != 0 || fsync(fd) != 0 || fsync_parent(path) != 0) {
		int e = errno;
		close(fd);
		errno = e;
		return -1;
	}
	return fd;
}

void srv_store_remove(const char *path)
{
	if (!st.started)
		return;
	store_job *j = calloc(1, sizeof *j);
	if (!j)
		return;
	snprintf(j->path, sizeof j->path, "%s", path);
	enqueue(j);
}
