/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_int.h - an experiment as experiment.c and
 * experiment_segment.c see it (the rest of the daemon has experiment.h).
 */
#ifndef CONVSIM_EXPERIMENT_INT_H
#define CONVSIM_EXPERIMENT_INT_H

#include <pthread.h>

#include "experiment.h"

/* Feed-velocity records an experiment keeps at most. */
#define EXP_RECORDS 50000

enum {
	EXP_WAITING,
	EXP_RUNNING,
	EXP_DONE,
	EXP_ABORTED,
	EXP_INTERRUPTED, /* running when the daemon died, not resumed */
	EXP_ERROR,       /* its result could not be written */
	EXP_DAMAGED,     /* its record could not be read back */
	EXP_NSTATES
};

struct srv_experiment {
	srv_entry entry;         /* id and references: experiment_http.c */
	const char *data_dir;    /* borrowed; NULL: results are not saved */
	pthread_mutex_t lock;
	/* guarded by lock */
	char session_id[SRV_ID_LEN];
	api_experiment_req req;  /* schedule and per-segment results */
	int state;
	int attached;            /* a session worker still refers to it */
	char error[256];
	double t0, t_now;        /* s: start and latest simulated time */
	int cur;                 /* running segment */
	double *rec_t, *rec_v;   /* feed velocity record */
	size_t rec_n, rec_cap, seg_first;
	double rec_spacing;      /* s between records, at least */
	srv_cmd cmd;             /* the running segment's command */
	int writes;              /* queued store writes (they refer to e) */
	int freed;               /* srv_exp_free came while writes > 0 */
};

/* Start segment i at status st (lock held): its command for the worker. */
srv_cmd *srv_exp_start_segment(srv_experiment *e, int i, const sim_status *st);
/* The running segment ends at status st (lock held): its mean and steady
 * velocity and its reversal time from the feed-velocity record. */
void srv_exp_finish_segment(srv_experiment *e, const sim_status *st);

#endif
