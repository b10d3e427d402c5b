/*
 * main.c - convsimd: flags, start-up and graceful shutdown.
 *
 * The daemon binds with libmicrohttpd (one thread per connection, so a
 * stream may wait for its session's records), prints the bound address
 * as "listening on http://HOST:PORT" (tests start it with --port 0 and
 * read the line), then waits for SIGTERM or SIGINT in sigwait(). Shutdown
 * stops accepting, ends every stream with an "end" record, joins the
 * connection threads, the sweep pool and every session worker, frees
 * everything and exits 0.
 */
#include <arpa/inet.h>
#include <getopt.h>
#include <netinet/in.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "srv.h"

srv_config srv_cfg = {
	.listen = "127.0.0.1",
	.port = 8080,
	.max_sessions = 64,
	.max_streams = 256,
	.max_body = 1 << 20,
	.data_dir = NULL,
	.web_root = NULL,
	.log_level = SRV_LOG_INFO,
	.ring = 4096,
	.history = 20000,
	.pool_threads = 2,
	.heartbeat = 15.0,
	.max_experiments = 256,
	.max_sweeps = 64,
};
atomic_int srv_stopping;

static void usage(FILE *f)
{
	fprintf(f,
		"usage: convsimd [options]\n"
		"  --listen ADDR        address to bind (default 127.0.0.1)\n"
		"  --port N             TCP port, 0 = ephemeral (default 8080)\n"
		"  --max-sessions N     live sessions (default 64)\n"
		"  --max-streams N      open stream clients (default 256)\n"
		"  --max-body BYTES     request body limit (default 1048576)\n"
		"  --data-dir DIR       save experiment and sweep results here\n"
		"  --web-root DIR       static files served at / (default web)\n"
		"  --log-level L        error|warn|info|debug (default info)\n"
		"  --ring N             stream records kept per session "
		"(default 4096)\n"
		"  --history N          trajectory rows kept per session "
		"(default 20000)\n"
		"  --pool-threads N     sweep worker threads (default 2)\n"
		"  --heartbeat S        seconds between stream heartbeats "
		"(default 15)\n");
}

static int parse_int(const char *arg, const char *name, long lo, long hi,
		     long *out)
{
	char *end;
	long v = strtol(arg, &end, 10);
	if (*end || end == arg || v < lo || v > hi) {
		fprintf(stderr, "convsimd: %s must be an integer in [%ld, %ld]\n",
			name, lo, hi);
		return -1;
	}
	*out = v;
	return 0;
}

static int parse_flags(int argc, char **argv)
{
	static const struct option opts[] = {
		{"listen", required_argument, 0, 'l'},
		{"port", required_argument, 0, 'p'},
		{"max-sessions", required_argument, 0, 's'},
		{"max-streams", required_argument, 0, 'S'},
		{"max-body", required_argument, 0, 'b'},
		{"data-dir", required_argument, 0, 'd'},
		{"web-root", required_argument, 0, 'w'},
		{"log-level", required_argument, 0, 'L'},
		{"ring", required_argument, 0, 'r'},
		{"history", required_argument, 0, 'H'},
		{"pool-threads", required_argument, 0, 't'},
		{"heartbeat", required_argument, 0, 'B'},
		{"help", no_argument, 0, 'h'},
		{0, 0, 0, 0},
	};
	static const char *const levels[] = {"error", "warn", "info", "debug"};
	int c;
	long v;
	while ((c = getopt_long(argc, argv, "h", opts, NULL)) != -1) {
		switch (c) {
		case 'l': srv_cfg.listen = optarg; break;
		case 'p':
			if (parse_int(optarg, "--port", 0, 65535, &v))
				return -1;
			srv_cfg.port = (int)v;
			break;
		case 's':
			if (parse_int(optarg, "--max-sessions", 1, 100000, &v))
				return -1;
			srv_cfg.max_sessions = (int)v;
			break;
		case 'S':
			if (parse_int(optarg, "--max-streams", 1, 100000, &v))
				return -1;
			srv_cfg.max_streams = (int)v;
			break;
		case 'b':
			if (parse_int(optarg, "--max-body", 64, 1L << 30, &v))
				return -1;
			srv_cfg.max_body = (size_t)v;
			break;
		case 'd': srv_cfg.data_dir = optarg; break;
		case 'w': srv_cfg.web_root = optarg; break;
		case 'L': {
			int found = -1;
			for (int i = 0; i < 4; i++)
				if (strcmp(optarg, levels[i]) == 0)
					found = i;
			if (found < 0) {
				fprintf(stderr, "convsimd: --log-level must be "
						"error, warn, info or debug\n");
				return -1;
			}
			srv_cfg.log_level = found;
			break;
		}
		case 'r':
			if (parse_int(optarg, "--ring", 16, 1 << 22, &v))
				return -1;
			srv_cfg.ring = (int)v;
			break;
		case 'H':
			if (parse_int(optarg, "--history", 16, 1 << 24, &v))
				return -1;
			srv_cfg.history = (int)v;
			break;
		case 't':
			if (parse_int(optarg, "--pool-threads", 1, 256, &v))
				return -1;
			srv_cfg.pool_threads = (int)v;
			break;
		case 'B': {
			char *end;
			double s = strtod(optarg, &end);
			if (*end || !(s >= 0.05 && s <= 3600)) {
				fprintf(stderr, "convsimd: --heartbeat must be "
						"seconds in [0.05, 3600]\n");
				return -1;
			}
			srv_cfg.heartbeat = s;
			break;
		}
		case 'h': usage(stdout); exit(0);
		default: usage(stderr); return -1;
		}
	}
	if (optind < argc) {
		fprintf(stderr, "convsimd: unexpected argument %s\n",
			argv[optind]);
		return -1;
	}
	return 0;
}

/* web/ next to the working directory, else next to the binary's parent. */
static char web_guess[4096];
static void pick_web_root(const char *argv0)
{
	struct stat sb;
	if (srv_cfg.web_root)
		return;
	srv_cfg.web_root = "web";
	if (stat("web", &sb) == 0 && S_ISDIR(sb.st_mode))
		return;
	const char *slash = strrchr(argv0, '/');
	if (!slash)
		return;
	snprintf(web_guess, sizeof web_guess, "%.*s/../web",
		 (int)(slash - argv0), argv0);
	if (stat(web_guess, &sb) == 0 && S_ISDIR(sb.st_mode))
		srv_cfg.web_root = web_guess;
}

int main(int argc, char **argv)
{
	if (parse_flags(argc, argv))
		return 2;
	pick_web_root(argv[0]);
	struct stat dd;
	if (srv_cfg.data_dir && (stat(srv_cfg.data_dir, &dd) != 0 ||
				 !S_ISDIR(dd.st_mode) ||
				 access(srv_cfg.data_dir, W_OK) != 0)) {
		fprintf(stderr, "convsimd: --data-dir %s is not a writable "
				"directory\n", srv_cfg.data_dir);
		return 2;
	}

	sigset_t sigs;
	sigemptyset(&sigs);
	sigaddset(&sigs, SIGTERM);
	sigaddset(&sigs, SIGINT);
	pthread_sigmask(SIG_BLOCK, &sigs, NULL); /* every thread inherits */
	signal(SIGPIPE, SIG_IGN);

	struct sockaddr_in a4;
	struct sockaddr_in6 a6;
	struct sockaddr *addr;
	unsigned flags = MHD_USE_THREAD_PER_CONNECTION |
			 MHD_USE_INTERNAL_POLLING_THREAD | MHD_USE_ITC |
			 MHD_USE_ERROR_LOG;
	memset(&a4, 0, sizeof a4);
	memset(&a6, 0, sizeof a6);
	if (inet_pton(AF_INET, srv_cfg.listen, &a4.sin_addr) == 1) {
		a4.sin_family = AF_INET;
		a4.sin_port = htons((uint16_t)srv_cfg.port);
		addr = (struct sockaddr *)&a4;
	} else if (inet_pton(AF_INET6, srv_cfg.listen, &a6.sin6_addr) == 1) {
		a6.sin6_family = AF_INET6;
		a6.sin6_port = htons((uint16_t)srv_cfg.port);
		addr = (struct sockaddr *)&a6;
		flags |= MHD_USE_IPv6;
	} else {
		fprintf(stderr, "convsimd: --listen %s is not an IPv4 or IPv6 "
				"address\n", srv_cfg.listen);
		return 2;
	}

	srv_catalog_init();
	srv_sessions_init();
	srv_experiments_init();
	srv_sweeps_init();
	if (srv_pool_start(srv_cfg.pool_threads)) {
		fprintf(stderr, "convsimd: cannot start the worker pool\n");
		return 1;
	}
	struct MHD_Daemon *d = MHD_start_daemon(
		flags, (uint16_t)srv_cfg.port, NULL, NULL, srv_dispatch, NULL,
		MHD_OPTION_NOTIFY_COMPLETED, srv_request_done, NULL,
		MHD_OPTION_SOCK_ADDR, addr, MHD_OPTION_CONNECTION_LIMIT,
		(unsigned)(srv_cfg.max_streams + 256),
		MHD_OPTION_CONNECTION_TIMEOUT, (unsigned)120, MHD_OPTION_END);
	if (!d) {
		fprintf(stderr, "convsimd: cannot listen on %s port %d\n",
			srv_cfg.listen, srv_cfg.port);
		srv_pool_stop();
		return 1;
	}
	const union MHD_DaemonInfo *info =
		MHD_get_daemon_info(d, MHD_DAEMON_INFO_BIND_PORT);
	int port = info ? info->port : srv_cfg.port;
	if (strchr(srv_cfg.listen, ':'))
		printf("listening on http://[%s]:%d\n", srv_cfg.listen, port);
	else
		printf("listening on http://%s:%d\n", srv_cfg.listen, port);
	fflush(stdout);
	srv_log(SRV_LOG_INFO, "serving %s at /; %d sessions, %d streams max",
		srv_cfg.web_root, srv_cfg.max_sessions, srv_cfg.max_streams);

	int sig = 0;
	sigwait(&sigs, &sig);
	srv_log(SRV_LOG_INFO, "%s: shutting down",
		sig == SIGINT ? "SIGINT" : "SIGTERM");
	atomic_store(&srv_stopping, 1);
	MHD_socket ls = MHD_quiesce_daemon(d);
	if (ls != MHD_INVALID_SOCKET)
		close(ls);
	/* streams notice within half a second, send "end" and close */
	for (int i = 0; i < 500 && atomic_load(&srv_stats.stream_clients) > 0;
	     i++)
		usleep(10000);
	MHD_stop_daemon(d);
	srv_pool_stop();
	srv_sweeps_shutdown();
	srv_sessions_shutdown();
	srv_experiments_shutdown();
	srv_catalog_shutdown();
	srv_log(SRV_LOG_INFO, "stopped cleanly");
	return 0;
}
