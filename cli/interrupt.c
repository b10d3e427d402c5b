/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * interrupt.c - Ctrl-C (SIGINT) and SIGTERM during a long job: noted in a
 * flag the job reads between its units of work (a sweep's points), so
 * that it stops starting new ones and writes what it measured, marked,
 * instead of dying with nothing written. The first signal resets the
 * handler: a second one ends the program at once, as without it.
 */
#include <signal.h>

#include "cli.h"

static volatile sig_atomic_t interrupted;

static void on_interrupt(int signo)
{
	interrupted = signo;
}

void cli_catch_interrupts(void)
{
	struct sigaction sa = {.sa_handler = on_interrupt, .sa_flags = SA_RESETHAND};
	sigemptyset(&sa.sa_mask);
	sigaction(SIGINT, &sa, NULL);
	sigaction(SIGTERM, &sa, NULL);
}

int cli_interrupted(void)
{
	return interrupted;
}
