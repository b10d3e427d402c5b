/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * feed_remote.c - a bed in a child process (feed.h's "remote"): the
 * program `convsim-bed --serve` spawned with two pipes, its stdin for the
 * requests and its stdout for the answers (bed_proto.h), one line each
 * way per coupling interval. Built without LIGGGHTS and MPI: the daemon
 * links this and never LIGGGHTS.
 *
 * The child ends with its bed: dem_feed_free kills it and its process
 * group (SIGKILL; the bed has nothing to save) and reaps it, so that no
 * process or zombie is left. Under mpirun, whose ranks lead groups of
 * their own and must be reaped by it, the end of the requests ends them
 * first (then SIGTERM to mpirun, then SIGKILL).
 * A child that ends on its own (LIGGGHTS refused a command, a signal)
 * shows as the end of its answers: the advance fails with how it ended.
 */
#define _GNU_SOURCE /* pipe2, posix_spawn_file_actions_addclosefrom_np (glibc 2.34) */
#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <poll.h>
#include <sys/socket.h>
#include <pthread.h>
#include <signal.h>
#include <spawn.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bed_proto.h"
#include "feed.h"

extern char **environ;

typedef struct remote {
	dem_feed base;
	pthread_mutex_t lock; /* pid, against a kill from another thread */
	pid_t pid;     /* 0 once reaped */
	int ranks;     /* > 1: pid is mpirun's */
	int to, from;  /* our ends: its stdin, its stdout */
	double timeout; /* s an answer may take; 0: no limit */
	int watch;     /* -1, or a socket whose peer's leaving cancels the
			  settling (the first answer) */
	char in[DEM_PROTO_LINE];
	size_t have;   /* bytes of in read but not yet taken */
} remote;

static void remote_free(dem_feed *f);

/* Reap the child (blocking: called when it has ended or was killed) and
 * say how it ended into msg. */
static void remote_reap(remote *r, char *msg, size_t msglen)
{
	int status = 0;
	pthread_mutex_lock(&r->lock);
	pid_t pid = r->pid;
	if (pid)
		while (waitpid(pid, &status, 0) < 0 && errno == EINTR)
			;
	r->pid = 0;
	pthread_mutex_unlock(&r->lock);
	if (!pid || !msg)
		return;
	if (WIFSIGNALED(status))
		snprintf(msg, msglen, "the bed process (pid %ld) was ended by signal %d (%s)",
			 (long)pid, WTERMSIG(status), strsignal(WTERMSIG(status)));
	else
		snprintf(msg, msglen, "the bed process (pid %ld) exited with status %d (LIGGGHTS "
				      "ends its process on a command it refuses; CONVSIM_DEM_LOG=FILE "
				      "in the daemon's environment keeps its output)",
			 (long)pid, WIFEXITED(status) ? WEXITSTATUS(status) : -1);
}

/* Write one whole line; 0 or -1 (the child is gone: SIGPIPE is the
 * caller's to ignore, as the daemon does). */
static int remote_send(remote *r, const char *line, size_t n)
{
	while (n > 0) {
		ssize_t w = write(r->to, line, n);
		if (w < 0 && errno == EINTR)
			continue;
		if (w <= 0)
			return -1;
		line += w;
		n -= (size_t)w;
	}
	return 0;
}

/* 1 when the watched socket's peer has gone (hung up, or the end of its
 * data); data from it ends the watch (it is still there). */
static int watch_gone(remote *r, short revents)
{
	if (revents & (POLLHUP | POLLERR | POLLNVAL))
		return 1;
	if (!(revents & POLLIN))
		return 0;
	char c;
	ssize_t n = recv(r->watch, &c, 1, MSG_PEEK | MSG_DONTWAIT);
	if (n == 0)
		return 1;
	if (n > 0)
		r->watch = -1; /* a pipelined request: the client is there */
	return 0;
}

/* Wait until the answer has bytes to read: 0, -1 when r->timeout s pass
 * without any (the deadline counts from the request), -2 when the
 * watched socket's peer leaves. */
static int remote_await(remote *r, const struct timespec *t0)
{
	if (!(r->timeout > 0) && r->watch < 0)
		return 0;
	for (;;) {
		struct timespec now;
		clock_gettime(CLOCK_MONOTONIC, &now);
		double left = r->timeout > 0 ? r->timeout - ((double)(now.tv_sec - t0->tv_sec) +
							     1e-9 * (double)(now.tv_nsec - t0->tv_nsec))
					     : 1e9;
		if (left <= 0)
			return -1;
		struct pollfd p[2] = {{.fd = r->from, .events = POLLIN},
				      {.fd = r->watch, .events = POLLIN}};
		int n = poll(p, r->watch >= 0 ? 2 : 1,
			     left > 1e6 ? 1000000000 : (int)ceil(left * 1e3));
		if (n > 0 && (p[0].revents & (POLLIN | POLLHUP | POLLERR)))
			return 0;
		if (n > 0 && r->watch >= 0 && watch_gone(r, p[1].revents))
			return -2;
		if (n < 0 && errno != EINTR)
			return 0; /* the read says what is wrong */
	}
}

/* Read one answer line into line (newline dropped): 0, -1 at the end of
 * the answers or a line too long, -2 when no answer came in time, -3 when
 * the watched socket's peer left. */
static int remote_receive(remote *r, char *line, size_t len)
{
	struct timespec t0;
	clock_gettime(CLOCK_MONOTONIC, &t0);
	for (;;) {
		char *nl = memchr(r->in, '\n', r->have);
		if (nl) {
			size_t n = (size_t)(nl - r->in);
			if (n >= len)
				return -1;
			memcpy(line, r->in, n);
			line[n] = '\0';
			r->have -= n + 1;
			memmove(r->in, nl + 1, r->have);
			return 0;
		}
		if (r->have == sizeof r->in)
			return -1;
		int w = remote_await(r, &t0);
		if (w)
			return w == -2 ? -3 : -2;
		ssize_t got = read(r->from, r->in + r->have, sizeof r->in - r->have);
		if (got < 0 && errno == EINTR)
			continue;
		if (got <= 0)
			return -1;
		r->have += (size_t)got;
	}
}

/* One request, one state answer into r->base: 0, or with msg -1, or -2
 * when the watched socket's peer left while it waited (the child ended
 * and reaped either way). */
static int remote_exchange(remote *r, const char *req, int n, char *msg, size_t msglen)
{
	char line[DEM_PROTO_LINE];
	if (!r->pid) {
		snprintf(msg, msglen, "the bed process has ended");
		return -1;
	}
	int rc = n < 0 || remote_send(r, req, (size_t)n) ? -1 : remote_receive(r, line, sizeof line);
	if (rc) {
		long pid = (long)r->pid;
		dem_feed_kill(&r->base); /* gone, hung or talking nonsense: make sure */
		remote_reap(r, msg, msglen);
		if (rc == -2)
			snprintf(msg, msglen, "the bed process (pid %ld) gave no answer within %g s "
					      "(--dem-timeout) and was ended", pid, r->timeout);
		if (rc == -3)
			snprintf(msg, msglen, "the client went away while the bed settled: the bed "
					      "process (pid %ld) was ended", pid);
		return rc == -3 ? -2 : -1;
	}
	if (!strncmp(line, "error ", 6)) {
		snprintf(msg, msglen, "bed process: %s", line + 6);
		return -1;
	}
	if (strncmp(line, "state ", 6) ||
	    dem_proto_state_parse(line + 6, &r->base.state, &r->base.cpu, &r->base.grains)) {
		snprintf(msg, msglen, "the bed process answered something else than a state: "
				      "%.60s", line);
		return -1;
	}
	return 0;
}

static int remote_advance(dem_feed *f, double ax, double ay, double interval, char *msg,
			  size_t msglen)
{
	remote *r = (remote *)f;
	char req[DEM_PROTO_LINE];
	return remote_exchange(r, req, dem_proto_advance_line(req, sizeof req, ax, ay, interval),
			       msg, msglen);
}

static const struct dem_feed_ops remote_ops = {"remote", remote_advance, remote_free};

/* Wait up to seconds for the child to end; 1 once it is reaped. */
static int remote_wait(remote *r, double seconds)
{
	for (int i = 0; i <= (int)(seconds / 0.02); i++) {
		pthread_mutex_lock(&r->lock);
		pid_t got = r->pid ? waitpid(r->pid, NULL, WNOHANG) : r->pid;
		if (got == r->pid || got < 0)
			r->pid = 0;
		int gone = r->pid == 0;
		pthread_mutex_unlock(&r->lock);
		if (gone)
			return 1;
		nanosleep(&(struct timespec){0, 20000000}, NULL);
	}
	return 0;
}

static void remote_free(dem_feed *f)
{
	remote *r = (remote *)f;
	if (r->to >= 0)
		close(r->to);
	/* under mpirun, whose ranks lead process groups of their own: the
	 * end of the requests ends every rank and then mpirun, which reaps
	 * them; one that does not is told to (mpirun ends its ranks on
	 * SIGTERM) before the group is killed */
	if (r->ranks > 1 && !remote_wait(r, 3.0)) {
		dem_feed_kill(f);
		remote_wait(r, 5.0);
	}
	if (r->pid) {
		pthread_mutex_lock(&r->lock);
		if (r->pid)
			kill(-r->pid, SIGKILL);
		pthread_mutex_unlock(&r->lock);
	}
	if (r->from >= 0)
		close(r->from);
	remote_reap(r, NULL, 0);
	pthread_mutex_destroy(&r->lock);
	free(r);
}

long dem_feed_pid(const dem_feed *f)
{
	if (!f || f->ops != &remote_ops)
		return 0;
	remote *r = (remote *)(void *)(uintptr_t)f; /* the lock is not the bed's state */
	pthread_mutex_lock(&r->lock);
	long pid = (long)r->pid;
	pthread_mutex_unlock(&r->lock);
	return pid;
}

void dem_feed_kill(const dem_feed *f)
{
	if (!f || f->ops != &remote_ops)
		return;
	remote *r = (remote *)(void *)(uintptr_t)f;
	pthread_mutex_lock(&r->lock);
	/* not reaped yet: the id is still the child's (and its group's);
	 * mpirun is asked, so that it ends and reaps its ranks */
	if (r->pid)
		kill(r->ranks > 1 ? r->pid : -r->pid, r->ranks > 1 ? SIGTERM : SIGKILL);
	pthread_mutex_unlock(&r->lock);
}

/* Start `path --serve --nice N` (under `mpirun -n ranks` when ranks > 1)
 * with its stdin and stdout on two new pipes (ours close on exec; the
 * child keeps no other descriptor), leading a process group of its own.
 * 0 or -1 with msg. */
static int remote_spawn(remote *r, const char *path, int nice_value, int ranks, char *msg,
			size_t msglen)
{
	int req[2] = {-1, -1}, ans[2] = {-1, -1};
	char nice_arg[16], ranks_arg[16];
	snprintf(nice_arg, sizeof nice_arg, "%d", nice_value);
	snprintf(ranks_arg, sizeof ranks_arg, "%d", ranks);
	char *serial[] = {(char *)path, "--serve", "--nice", nice_arg, NULL};
	char *parallel[] = {"mpirun", "-n", ranks_arg, (char *)path, "--serve", "--nice", nice_arg,
			    NULL};
	char **argv = ranks > 1 ? parallel : serial;
	posix_spawn_file_actions_t fa;
	posix_spawnattr_t at;
	if (pipe2(req, O_CLOEXEC) || pipe2(ans, O_CLOEXEC)) {
		snprintf(msg, msglen, "bed process: no pipe: %s", strerror(errno));
		goto fail;
	}
	posix_spawn_file_actions_init(&fa);
	posix_spawn_file_actions_adddup2(&fa, req[0], 0);
	posix_spawn_file_actions_adddup2(&fa, ans[1], 1);
	posix_spawn_file_actions_addclosefrom_np(&fa, 3);
	posix_spawnattr_init(&at);
	posix_spawnattr_setflags(&at, POSIX_SPAWN_SETPGROUP);
	posix_spawnattr_setpgroup(&at, 0);
	int rc = posix_spawnp(&r->pid, argv[0], &fa, &at, argv, environ);
	posix_spawn_file_actions_destroy(&fa);
	posix_spawnattr_destroy(&at);
	if (rc) {
		r->pid = 0;
		snprintf(msg, msglen, "bed process: cannot start %s: %s", argv[0], strerror(rc));
		goto fail;
	}
	close(req[0]);
	close(ans[1]);
	r->to = req[1];
	r->from = ans[0];
	return 0;
fail:
	for (int i = 0; i < 2; i++) {
		if (req[i] >= 0)
			close(req[i]);
		if (ans[i] >= 0)
			close(ans[i]);
	}
	return -1;
}

dem_feed *dem_feed_remote(const char *bed_path, const dem_bed_spec *spec, int nice_value,
			  int ranks, double timeout, int watch_fd, int *left, char *msg,
			  size_t msglen)
{
	char req[DEM_PROTO_LINE];
	if (spec->wiggle_period > 0) {
		snprintf(msg, msglen, "bed process: the frame check's moving floor runs in "
				      "convsim-dem only");
		return NULL;
	}
	remote *r = calloc(1, sizeof *r);
	if (!r) {
		snprintf(msg, msglen, "bed process: out of memory");
		return NULL;
	}
	r->base.ops = &remote_ops;
	r->to = r->from = -1;
	r->ranks = ranks;
	r->timeout = timeout > 0 && isfinite(timeout) ? timeout : 0;
	r->watch = watch_fd;
	pthread_mutex_init(&r->lock, NULL);
	int rc = remote_spawn(r, bed_path, nice_value, ranks, msg, msglen);
	if (!rc)
		rc = remote_exchange(r, req, dem_proto_bed_line(req, sizeof req, spec), msg, msglen);
	if (rc) {
		if (left)
			*left = rc == -2;
		remote_free(&r->base);
		return NULL;
	}
	r->watch = -1; /* settled: the session lives on without its creator */
	return &r->base;
}
