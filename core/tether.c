/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * tether.c - a process that ends with the one that started it. The test
 * suite sets CONVSIM_TETHER to the id of the node process that runs a
 * test; every convsim program (the daemon, the CLI and its MPI ranks, the
 * DEM programs) started under it, directly or through make, a shell,
 * mpirun or the daemon, ends with a SIGKILL when that process ends,
 * whatever ended it (a SIGKILL too), so that no daemon outlives its test.
 *
 * A direct child asks the kernel (prctl PR_SET_PDEATHSIG) and then checks
 * that its parent is still the one named, since the parent may have ended
 * before the request; any other descendant watches the named process
 * through a pidfd on a thread of its own. Without the variable nothing
 * happens. Linux only; elsewhere a no-op.
 */
#define _GNU_SOURCE /* syscall */
#include "tether.h"

#include <stdlib.h>

#ifdef __linux__
#include <errno.h>
#include <poll.h>
#include <pthread.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <sys/prctl.h>
#include <sys/syscall.h>
#include <unistd.h>

#ifndef SYS_pidfd_open
#define SYS_pidfd_open 434
#endif

static void *watch(void *arg)
{
	struct pollfd p = {.fd = (int)(intptr_t)arg, .events = POLLIN};
	while (poll(&p, 1, -1) < 0 && errno == EINTR)
		;
	kill(getpid(), SIGKILL);
	return NULL;
}

int sim_tether_from_env(void)
{
	const char *v = getenv("CONVSIM_TETHER");
	if (!v || !*v)
		return 0;
	char *end;
	errno = 0;
	long pid = strtol(v, &end, 10);
	if (*end || errno || pid <= 1) {
		fprintf(stderr, "CONVSIM_TETHER=%.20s is no process id; ignored\n", v);
		return -1;
	}
	if (getppid() == (pid_t)pid) {
		if (prctl(PR_SET_PDEATHSIG, SIGKILL) != 0)
			return -1;
		if (getppid() != (pid_t)pid) /* it ended before the request */
			kill(getpid(), SIGKILL);
		return 1;
	}
	int fd = (int)syscall(SYS_pidfd_open, (pid_t)pid, 0);
	if (fd < 0) {
		if (errno == ESRCH) /* it ended already */
			kill(getpid(), SIGKILL);
		return -1;
	}
	pthread_t t;
	pthread_attr_t at;
	pthread_attr_init(&at);
	pthread_attr_setdetachstate(&at, PTHREAD_CREATE_DETACHED);
	pthread_attr_setstacksize(&at, 64 * 1024);
	int rc = pthread_create(&t, &at, watch, (void *)(intptr_t)fd);
	pthread_attr_destroy(&at);
	if (rc != 0) {
		close(fd);
		return -1;
	}
	return 1;
}
#else
int sim_tether_from_env(void)
{
	return 0;
}
#endif
