/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * main.c - convsimd: start-up and graceful shutdown.
 *
 * The daemon serves with libmicrohttpd (one thread per connection, so a
 * stream may wait for its session's records) on a socket acceptor.c
 * listens on and accepts from, prints the bound address
 * as "listening on http://HOST:PORT" (tests start it with --port 0 and
 * read the line), then waits for SIGTERM or SIGINT in sigwait(). Shutdown
 * stops accepting, ends every stream with an "end" record, joins the
 * connection threads, the sweep pool and every session worker, frees
 * everything and exits 0. The options (config.c) are parsed into one
 * srv_config here and handed to each module's init.
 */
#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/resource.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "acceptor.h"
#include "budget.h"
#include "tether.h"
#include "catalog.h"
#include "config.h"
#include "conns.h"
#include "experiment_http.h"
#include "gate.h"
#include "metrics.h"
#include "peers.h"
#include "pool.h"
#include "routes.h"
#include "session.h"
#include "static.h"
#include "store.h"
#include "stream.h"
#include "fitjob.h"
#include "job.h"
#include "util.h"

/* The MHD flags --listen needs. */
typedef struct listen_addr {
	unsigned flags;
} listen_addr;

/* --listen as an IPv4 or IPv6 address; -1 with a message if neither. */
static int resolve_listen(const srv_config *cfg, listen_addr *la)
{
	struct in6_addr a;
	/* poll(), not select(): descriptors beyond FD_SETSIZE (1024) work;
	 * the listening socket is acceptor.c's */
	la->flags = MHD_USE_THREAD_PER_CONNECTION |
		    MHD_USE_POLL_INTERNAL_THREAD | MHD_USE_ITC |
		    MHD_USE_ERROR_LOG | MHD_USE_NO_LISTEN_SOCKET;
	if (inet_pton(AF_INET, cfg->listen, &a) == 1)
		return 0;
	if (inet_pton(AF_INET6, cfg->listen, &a) == 1) {
		la->flags |= MHD_USE_IPv6;
		return 0;
	}
	fprintf(stderr, "convsimd: --listen %s is not an IPv4 or IPv6 "
			"address\n", cfg->listen);
	return -1;
}

/* Raise the soft limit of open files to what the connection budget needs
 * (each connection a socket, plus the data directory's files, the
 * listening socket and libmicrohttpd's pipe); the hard limit caps it. */
static void raise_nofile(const srv_config *cfg)
{
	struct rlimit rl;
	rlim_t need = (rlim_t)cfg->max_connections + SRV_CONN_HEADROOM +
		      SRV_CLIENT_GRACE + 256;
	if (getrlimit(RLIMIT_NOFILE, &rl) != 0 || rl.rlim_cur >= need)
		return;
	rlim_t was = rl.rlim_cur;
	rl.rlim_cur = rl.rlim_max == RLIM_INFINITY || rl.rlim_max >= need
			      ? need : rl.rlim_max;
	if (setrlimit(RLIMIT_NOFILE, &rl) != 0 || rl.rlim_cur < need)
		srv_log(SRV_LOG_WARN, "open files limited to %llu (hard "
				      "limit); --max-connections %d needs %llu",
			(unsigned long long)rl.rlim_cur, cfg->max_connections,
			(unsigned long long)need);
	else
		srv_log(SRV_LOG_INFO, "open files: soft limit raised from "
				      "%llu to %llu", (unsigned long long)was,
			(unsigned long long)need);
}

/* Start libmicrohttpd with the connection budgets; it listens on no
 * socket of its own: acceptor.c hands it the connections. */
static struct MHD_Daemon *start_http(const srv_config *cfg,
				     const listen_addr *la)
{
	return MHD_start_daemon(
		la->flags, 0, NULL, NULL, srv_dispatch, NULL,
		MHD_OPTION_EXTERNAL_LOGGER, srv_budget_mhd_log, NULL,
		MHD_OPTION_NOTIFY_COMPLETED, srv_request_done, NULL,
		MHD_OPTION_URI_LOG_CALLBACK, srv_uri_seen, NULL,
		MHD_OPTION_NOTIFY_CONNECTION, srv_acceptor_notify, NULL,
		MHD_OPTION_CONNECTION_LIMIT,
		(unsigned)(cfg->max_connections + SRV_CONN_HEADROOM),
		/* a backstop only: conns.c holds the per-address cap by
		 * closing that address's idle or slow connections, which
		 * libmicrohttpd still counts until their threads close them */
		MHD_OPTION_PER_IP_CONNECTION_LIMIT,
		(unsigned)(cfg->max_client_connections + SRV_CLIENT_GRACE + SRV_CONN_HEADROOM),
		MHD_OPTION_CONNECTION_TIMEOUT,
		(unsigned)(cfg->connection_timeout + 0.5), MHD_OPTION_END);
}

/* Stop accepting, let streams end, join every thread, free everything. */
static void shut_down(struct MHD_Daemon *d)
{
	srv_store_watch(); /* the final checkpoints and records from here */
	srv_stop();
	srv_acceptor_stop(); /* no new connection from here */
	/* streams notice within half a second, send "end" and close */
	for (int i = 0; i < 500 && atomic_load(&srv_stats.stream_clients) > 0;
	     i++)
		usleep(10000);
	MHD_stop_daemon(d);
	srv_acceptor_free();
	srv_fits_shutdown(); /* their evaluations need the pool */
	srv_pool_stop();
	srv_job_close(&srv_sweep_job);
	srv_sessions_shutdown();
	srv_job_close(&srv_experiment_job);
	srv_catalog_shutdown();
	srv_store_close(); /* every queued write is on disk */
	srv_gate_shutdown();
	srv_conns_shutdown();
}

/* Of n restored, those not damaged (a damaged one may also have found no
 * room, so it is not always among the n). */
static size_t whole(size_t n, size_t damaged)
{
	return n > damaged ? n - damaged : 0;
}

/* Rebuild what the data directory holds: experiments first (the sessions
 * resume theirs), then sessions, then sweeps and fits (on the pool). */
static void restore_state(void)
{
	if (!srv_store_enabled())
		return;
	double t0 = srv_now();
	size_t ne = srv_job_restore(&srv_experiment_job);
	const srv_exp_finder ef = {srv_experiment_get, srv_experiment_put,
				   srv_experiments_readopt};
	size_t ns = srv_sessions_restore(&ef);
	size_t ni = srv_experiments_interrupt_orphans();
	size_t nw = srv_job_restore(&srv_sweep_job);
	size_t nf = srv_job_restore(&srv_fit_job);
	if (!(ne + ns + nw + nf))
		return;
	/* the damaged ones are listed (state "damaged") but not whole: said
	 * apart, and the line is a warning then */
	size_t ds = srv_store_damaged(SRV_STORE_SESSION),
	       de = srv_store_damaged(SRV_STORE_EXPERIMENT),
	       dw = srv_store_damaged(SRV_STORE_SWEEP), df = srv_store_damaged(SRV_STORE_FIT);
	size_t up = srv_store_upgraded(SRV_STORE_SESSION) +
		    srv_store_upgraded(SRV_STORE_EXPERIMENT) +
		    srv_store_upgraded(SRV_STORE_SWEEP) + srv_store_upgraded(SRV_STORE_FIT);
	srv_log(ds + de + dw + df ? SRV_LOG_WARN : SRV_LOG_INFO,
		"restored %zu sessions, %zu experiments (%zu interrupted), %zu "
		"sweeps, %zu fits in %.3f s; damaged: %zu sessions, %zu "
		"experiments, %zu sweeps, %zu fits; %zu read from an earlier "
		"format and written again in format %d",
		whole(ns, ds), whole(ne, de), ni, whole(nw, dw), whole(nf, df), srv_now() - t0, ds,
		de, dw, df, up, SRV_STORE_VERSION);
}

/* The floors' services, each given the options (before the store opens). */
static void open_services(srv_config *config)
{
	raise_nofile(config);
	srv_budget_init(config);
	srv_budget_settling_init(config);
	srv_conns_init(config);
	srv_catalog_init(config);
	srv_sessions_init(config);
	srv_experiments_init(config);
	srv_job_open(&srv_sweep_job, (size_t)config->max_sweeps);
	srv_job_open(&srv_fit_job, (size_t)config->max_fits);
	srv_streams_init(config);
	srv_static_init(config);
}

/* The address it listens on (stdout, for scripts) and its budgets (log). */
static void announce(const srv_config *config, int port)
{
	if (strchr(config->listen, ':'))
		printf("listening on http://[%s]:%d\n", config->listen, port);
	else
		printf("listening on http://%s:%d\n", config->listen, port);
	fflush(stdout);
	srv_log(SRV_LOG_INFO, "serving %s at /; %d sessions, %d streams max; "
			      "budgets: %.1f GiB memory, %g CPU s per session, "
			      "%g core%s for paced sessions, %d pace-max at once, "
			      "%d settling at once, %d connections per client (%d in "
			      "all), %d queued sweep points",
		config->web_root, config->max_sessions, config->max_streams,
		(double)config->max_memory / (1 << 30), config->max_cpu_seconds,
		config->max_paced_cores, config->max_paced_cores == 1 ? "" : "s", config->max_busy, config->max_settling,
		config->max_client_connections,
		config->max_connections,
		config->max_queued_points);
}

int main(int argc, char **argv)
{
	sim_tether_from_env(); /* the test suite's: end with the test */
	srv_config cfg;
	int parsed = srv_config_parse(&cfg, argc, argv);
	if (parsed)
		return parsed > 0 ? 0 : 2;
	srv_log_init(cfg.log_level);
	srv_background_nice_init(cfg.worker_nice);
	srv_ids_init(cfg.node_id);

	sigset_t sigs;
	sigemptyset(&sigs);
	sigaddset(&sigs, SIGTERM);
	sigaddset(&sigs, SIGINT);
	pthread_sigmask(SIG_BLOCK, &sigs, NULL); /* every thread inherits */
	signal(SIGPIPE, SIG_IGN);

	listen_addr la;
	if (resolve_listen(&cfg, &la) || srv_gate_init(&cfg) ||
	    srv_peers_init(&cfg))
		return 2;

	open_services(&cfg);
	if (srv_routes_init(&cfg))
		return 1;
	if (srv_store_open(&cfg))
		return 1;
	if (srv_pool_start(cfg.pool_threads)) {
		fprintf(stderr, "convsimd: cannot start the worker pool\n");
		return 1;
	}
	restore_state();
	int port = cfg.port;
	struct MHD_Daemon *d = NULL;
	if (srv_acceptor_open(&cfg, &port) || !(d = start_http(&cfg, &la)) ||
	    srv_acceptor_start(d, &cfg)) {
		fprintf(stderr, "convsimd: cannot listen on %s port %d\n",
			cfg.listen, cfg.port);
		srv_acceptor_stop();
		if (d)
			MHD_stop_daemon(d);
		srv_acceptor_free();
		srv_pool_stop();
		return 1;
	}
	srv_gate_set_port(port);
	announce(&cfg, port);

	/* once a second: remove the sessions whose experiment ended and
	 * those idle beyond --idle-timeout, close the connections past
	 * their deadline */
	int sig = 0;
	struct timespec tick = {1, 0};
	while ((sig = sigtimedwait(&sigs, NULL, &tick)) < 0) {
		srv_sessions_reap(cfg.idle_timeout);
		srv_conns_reap();
	}
	srv_log(SRV_LOG_INFO, "%s: shutting down",
		sig == SIGINT ? "SIGINT" : "SIGTERM");
	shut_down(d);
	/* a final checkpoint or record that is not on disk is not a clean
	 * stop: the next start would not find what was acknowledged */
	char failed[1024];
	size_t nfailed = srv_store_failed(failed, sizeof failed);
	if (nfailed) {
		srv_log(SRV_LOG_ERROR, "stopped, but %zu final write%s failed, their "
				       "state is not on disk: %s", nfailed,
			nfailed == 1 ? "" : "s", failed);
		return 1;
	}
	srv_log(SRV_LOG_INFO, "stopped cleanly");
	return 0;
}
