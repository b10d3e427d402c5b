/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * config.h - the daemon's options: their defaults and the command line.
 *
 * main.c owns the one srv_config and hands it (borrowed, read-only while
 * the daemon runs) to each module's init, which keeps what it needs: no
 * module reads another's globals for its settings.
 */
#ifndef CONVSIM_CONFIG_H
#define CONVSIM_CONFIG_H

#include <stddef.h>

/* A repeatable option's values (argv's strings, borrowed). */
#define SRV_LIST_MAX 16
typedef struct srv_list {
	const char *v[SRV_LIST_MAX];
	int n;
} srv_list;

typedef struct srv_config {
	const char *listen;    /* address to bind, "127.0.0.1" */
	int port;              /* 0: ephemeral */
	int max_sessions;
	int max_streams;       /* open stream clients, all sessions */
	size_t max_body;       /* bytes */
	const char *data_dir;  /* NULL: results are not saved */
	const char *web_root;  /* static files served at / */
	int log_level;         /* SRV_LOG_* */
	int ring;              /* stream records kept per session */
	int history;           /* trajectory rows kept per session */
	int pool_threads;      /* sweep workers */
	int worker_nice;       /* nice value of session workers and the pool */
	double heartbeat;      /* s between stream heartbeats */
	int max_experiments, max_sweeps;
	int max_fits;          /* fits kept (running or over) */
	double checkpoint_interval; /* s of wall time between checkpoints */
	double idle_timeout;   /* s without client or request; 0: never */
	const char *token_file; /* NULL: no token asked (loopback only) */
	int insecure;          /* serve beyond loopback without a token */
	srv_list allow_origins; /* --allow-origin: more origins than ours */
	srv_list server_names; /* --server-name: more Host names */
	const char *node_id;   /* --node-id: ids start "NODE-"; NULL: none */
	const char *peers;     /* --peers: comma list of http://HOST:PORT */
	/* budgets (budget.c) */
	size_t max_memory;     /* bytes: sessions' and streams' estimated need */
	double max_cpu_seconds; /* CPU s a session may use per grant */
	int max_busy;          /* pace "max" sessions stepping at once */
	double max_paced_cores; /* cores the running paced sessions may need,
				   all together (their CPU s per simulated s
				   times their pace) */
	int max_settling;      /* requests that settle simulations in their
				  own thread at once (budget_settling.c) */
	int max_client_connections; /* open connections per client address */
	int max_connections;   /* open connections, all clients */
	double connection_timeout; /* s a connection may stay silent */
	double request_timeout; /* s from a request line to its last header,
				   and a body's start (conns.c) */
	size_t min_body_rate;  /* bytes/s a body must keep up after that */
	int max_queued_points; /* sweep points queued or running, all sweeps */
	double cpu_probe;      /* CPU s a new session's cost is probed for
				  (cpu_probe.c); 0: the estimate alone */
	/* LIGGGHTS sessions (session_dem.c) */
	const char *dem_bed;   /* --dem-bed: the bed program; NULL: convsim-bed
				  next to the daemon's own executable */
	int max_dem_sessions;  /* LIGGGHTS sessions at once */
	int dem_ranks;         /* --dem-ranks: a bed process's MPI ranks (under
				  mpirun when > 1), the cores it holds */
	double dem_timeout;    /* --dem-timeout: s a bed process may take to
				  answer before its session fails */
	double max_dem_cost;   /* --max-dem-cost: CPU s a bed may be expected
				  to take per simulated second (its DEM step
				  and grains), beyond which it is refused */
} srv_config;

/* Longest --node-id: "NODE-" and 12 hex digits fit in an id (SRV_ID_LEN). */
#define SRV_NODE_ID_MAX 10

/* Fill *cfg from the defaults and the command line (argv is borrowed: the
 * strings stay argv's). Returns 0; 1 after --help (usage printed); -1 on a
 * bad option (message on stderr). */
int srv_config_parse(srv_config *cfg, int argc, char **argv);

#endif
