/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * experiment_http.h - the experiment resources and their registry.
 */
#ifndef CONVSIM_EXPERIMENT_HTTP_H
#define CONVSIM_EXPERIMENT_HTTP_H

#include "config.h"
#include "reply.h"

/* Start with an empty registry of cfg->max_experiments (cfg borrowed for
 * the daemon's life). */
void srv_experiments_init(const srv_config *cfg);
/* Free every experiment (after the sessions are shut down). */
void srv_experiments_shutdown(void);

typedef struct srv_experiment srv_experiment;

/* Load every experiment of the data directory (before the sessions are
 * restored, which resume the running ones). Returns how many. */
size_t srv_experiments_restore(void);
/* After the sessions are restored: mark the running experiments no
 * session resumed "interrupted". Returns how many. */
size_t srv_experiments_interrupt_orphans(void);
/* The experiment with this id as a new reference, or NULL; put it back
 * (NULL accepted). */
srv_experiment *srv_experiment_get(const char *id);
void srv_experiment_put(srv_experiment *e);

/* POST /api/v1/experiments, GET /api/v1/experiments[/{id}]. */
enum MHD_Result srv_h_experiments_create(srv_req *r);
enum MHD_Result srv_h_experiments_list(srv_req *r);
enum MHD_Result srv_h_experiment_get(srv_req *r);

#endif
