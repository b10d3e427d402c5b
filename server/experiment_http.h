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

/* POST /api/v1/experiments, GET /api/v1/experiments[/{id}]. */
enum MHD_Result srv_h_experiments_create(srv_req *r);
enum MHD_Result srv_h_experiments_list(srv_req *r);
enum MHD_Result srv_h_experiment_get(srv_req *r);

#endif
