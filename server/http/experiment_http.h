/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_http.h - the experiments' registry: the kind of job
 * srv_experiment_job (job.h), and what the sessions' restore needs of it.
 * Shut down with srv_job_close after the sessions.
 */
#ifndef CONVSIM_EXPERIMENT_HTTP_H
#define CONVSIM_EXPERIMENT_HTTP_H

#include "config.h"
#include "reply.h"

/* Start with an empty registry of cfg->max_experiments (cfg borrowed for
 * the daemon's life). */
void srv_experiments_init(const srv_config *cfg);
typedef struct srv_experiment srv_experiment;

/* At the restore, before the sessions' workers start: the experiment
 * whose record says it ran on session_id, still running or waiting and
 * not resumed by a checkpoint, attached again from its first segment
 * (srv_exp_readopt; the registry keeps it), or NULL. */
srv_experiment *srv_experiments_readopt(const char *session_id);
/* After the sessions are restored: mark the running experiments no
 * session resumed "interrupted". Returns how many. */
size_t srv_experiments_interrupt_orphans(void);
/* The experiment with this id as a new reference, or NULL; put it back
 * (NULL accepted). */
srv_experiment *srv_experiment_get(const char *id);
void srv_experiment_put(srv_experiment *e);

#endif
