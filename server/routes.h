/*
 * routes.h - the route table and the callbacks given to libmicrohttpd.
 */
#ifndef CONVSIM_ROUTES_H
#define CONVSIM_ROUTES_H

#include "config.h"
#include "reply.h"

/* cfg (borrowed for the daemon's life) gives --max-body. */
void srv_routes_init(const srv_config *cfg);
/* The access handler and completion callback given to MHD. */
enum MHD_Result srv_dispatch(void *cls, struct MHD_Connection *conn,
			     const char *url, const char *method,
			     const char *version, const char *upload_data,
			     size_t *upload_data_size, void **con_cls);
void srv_request_done(void *cls, struct MHD_Connection *conn,
		      void **con_cls, enum MHD_RequestTerminationCode toe);

#endif
