/*
 * session_int.h - the inside of a session, shared by session.c (registry,
 * lifetime, readers) and worker.c (the thread that steps the core).
 */
#ifndef CONVSIM_SESSION_INT_H
#define CONVSIM_SESSION_INT_H

#include <math.h>
#include <pthread.h>

#include "registry.h"
#include "session.h"
#include "worker.h"

struct srv_session {
	srv_entry entry;          /* id and references: the registry */
	api_spec spec;            /* immutable */
	double created;
	int columns, layers;      /* feed size, 0 without feed */
	sim *sim;                 /* worker only */
	pthread_t worker;
	int worker_started;
	api_sample scratch;       /* worker only */

	pthread_mutex_t lock;
	pthread_cond_t wake;      /* worker: commands, stop */
	pthread_cond_t data;      /* streams and waiting handlers */
	/* guarded by lock */
	int stop;
	int state;
	char error[256];
	double pace, until;
	srv_cmd *cmd_head, *cmd_tail;
	sim_status st;
	double steps_per_s, rtf;
	api_sample *ring;
	double *ring_store;
	size_t ring_cap;
	uint64_t head;
	double *hist;
	size_t hist_cap, hist_n;
	double hist_stride, hist_next;
	int streams;
	srv_experiment *exp;
	srv_cmd *exp_cmd;         /* the experiment's command while queued */
	int exp_started;
};

#endif
