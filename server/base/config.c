/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * config.c - the daemon's options: defaults, the command line and the
 * checks of what it names (web root guess, writable data directory).
 *
 * Options are a table {flag, kind, range, field, help}: one loop parses
 * them all, each kind checks its range with one message, and --help is
 * printed from the same rows with the defaults' values.
 */
#include <ctype.h>
#include <getopt.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "config.h"
#include "decimal.h"
#include "util.h"

static const srv_config defaults = {
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
	.worker_nice = 5,
	.heartbeat = 15.0,
	.max_experiments = 256,
	.max_sweeps = 64,
	.max_fits = 16,
	.checkpoint_interval = 10.0,
	.idle_timeout = 0.0,
	.max_memory = 0,       /* set from the machine: machine_defaults() */
	.max_cpu_seconds = 1800.0,
	.max_busy = 0,         /* set from the machine */
	.max_paced_cores = 0,  /* set from the machine */
	.max_settling = 0,     /* set from the machine */
	.max_client_connections = 64,
	.max_connections = 1024,
	.connection_timeout = 30.0,
	.request_timeout = 10.0,
	.min_body_rate = 1024,
	.max_queued_points = 4096,
	.cpu_probe = 0.03,
	.dem_bed = NULL,
	.max_dem_sessions = 1,
	.dem_ranks = 1,
	.dem_timeout = 300.0,
	.max_dem_cost = 1000.0,
};

enum { OPT_STRING, OPT_INT, OPT_SIZE, OPT_MEMORY, OPT_SECONDS, OPT_CORES, OPT_LEVEL,
       OPT_FLAG, OPT_LIST };

/* One option: its flag, kind, range, field, and its line of --help: the
 * argument's name, the text ("%D" is the default, from the field; "\n"
 * starts a continuation line) and a heading printed above it. */
typedef struct opt {
	const char *name;
	int kind;
	long lo, hi;
	size_t field; /* offsetof(srv_config, ...) */
	const char *arg, *doc, *heading;
} opt;

#define F(member) offsetof(srv_config, member)
static const opt opts[] = {
	{"listen", OPT_STRING, 0, 0, F(listen), "ADDR", "address to bind (default %D)", NULL},
	{"port", OPT_INT, 0, 65535, F(port), "N", "TCP port, 0 = ephemeral (default %D)", NULL},
	{"max-sessions", OPT_INT, 1, 100000, F(max_sessions), "N", "live sessions (default %D)",
	 NULL},
	{"max-streams", OPT_INT, 1, 100000, F(max_streams), "N",
	 "open stream clients (default %D)", NULL},
	{"max-experiments", OPT_INT, 1, 100000, F(max_experiments), "N",
	 "experiments kept; beyond, the oldest finished one goes (default %D)", NULL},
	{"max-sweeps", OPT_INT, 1, 100000, F(max_sweeps), "N",
	 "sweeps kept; beyond, the oldest finished one goes (default %D)", NULL},
	{"max-fits", OPT_INT, 1, 100000, F(max_fits), "N",
	 "fits kept; beyond, the oldest finished one goes (default %D)", NULL},
	{"max-body", OPT_SIZE, 64, 1L << 30, F(max_body), "BYTES",
	 "request body limit (default %D)", NULL},
	{"data-dir", OPT_STRING, 0, 0, F(data_dir), "DIR",
	 "save sessions, experiments, sweeps and fits here", NULL},
	{"web-root", OPT_STRING, 0, 0, F(web_root), "DIR",
	 "static files served at / (default web)", NULL},
	{"log-level", OPT_LEVEL, 0, 0, F(log_level), "L", "error|warn|info|debug (default %D)",
	 NULL},
	{"ring", OPT_INT, 16, 1 << 22, F(ring), "N", "stream records kept per session (default %D)",
	 NULL},
	{"history", OPT_INT, 16, 1 << 24, F(history), "N",
	 "trajectory rows kept per session (default %D)", NULL},
	{"pool-threads", OPT_INT, 1, 256, F(pool_threads), "N",
	 "sweep worker threads (default %D)", NULL},
	{"worker-nice", OPT_INT, 0, 19, F(worker_nice), "N",
	 "nice value (0-19) of session workers and sweep threads, below\n"
	 "the request and stream threads' 0 (default %D)", NULL},
	{"heartbeat", OPT_SECONDS, 50, 3600000, F(heartbeat), "S",
	 "seconds between stream heartbeats (default %D)", NULL},
	{"checkpoint-interval", OPT_SECONDS, 50, 3600000, F(checkpoint_interval), "S",
	 "wall seconds between session checkpoints (default %D)", NULL},
	{"idle-timeout", OPT_SECONDS, 0, 864000000, F(idle_timeout), "S",
	 "remove sessions with no client and no request for S seconds (default %D: never)",
	 NULL},
	{"token-file", OPT_STRING, 0, 0, F(token_file), "FILE",
	 "require Authorization: Bearer with the token in FILE\n"
	 "(mode 0600 or stricter) on every route but / files and /health", NULL},
	{"insecure", OPT_FLAG, 0, 0, F(insecure), "",
	 "allow a non-loopback --listen without --token-file", NULL},
	{"allow-origin", OPT_LIST, 0, 0, F(allow_origins), "ORIG",
	 "one more browser origin allowed to call (repeatable, max 16)", NULL},
	{"server-name", OPT_LIST, 0, 0, F(server_names), "NAME",
	 "one more Host name the daemon answers to (repeatable, max 16)", NULL},
	{"node-id", OPT_STRING, 0, 0, F(node_id), "NAME",
	 "this replica's name (1-10 of a-z 0-9 -): every id it makes starts NAME-", NULL},
	{"peers", OPT_STRING, 0, 0, F(peers), "URL,...",
	 "other replicas (http://HOST:PORT); lists gather theirs", NULL},
	{"max-memory", OPT_MEMORY, 1L << 20, 1L << 50, F(max_memory), "BYTES",
	 "estimated memory of all sessions and streams; K, M, G suffixes\n"
	 "(default %D: 3/4 of this machine's memory)",
	 "budgets (429/503 with Retry-After when spent; see docs/budgets.md \"Budgets and "
	 "load\"):"},
	{"max-cpu-seconds", OPT_SECONDS, 100, 864000000, F(max_cpu_seconds), "S",
	 "CPU seconds a session may use before it pauses, per grant\n(default %D)", NULL},
	{"max-busy", OPT_INT, 1, 1024, F(max_busy), "N",
	 "pace \"max\" sessions stepping at once, in turns (default %D: the cores)", NULL},
	{"max-paced-cores", OPT_CORES, 10, 4096000000L, F(max_paced_cores), "C",
	 "cores the running paced sessions may need together: each its CPU s\n"
	 "per simulated s times its pace (default %D: half the cores)", NULL},
	{"max-settling", OPT_INT, 1, 1024, F(max_settling), "N",
	 "requests that settle simulations in their own thread at once (a\n"
	 "session's creation, an experiment's measurements); beyond, 503\n"
	 "(default %D: half the cores, rounded up)", NULL},
	{"max-client-connections", OPT_INT, 1, 100000, F(max_client_connections), "N",
	 "open connections per client address (default %D); beyond, each\n"
	 "closes the address's least progressing one", NULL},
	{"max-connections", OPT_INT, 16, 100000, F(max_connections), "N",
	 "open connections, all clients (default %D)", NULL},
	{"connection-timeout", OPT_SECONDS, 1000, 3600000, F(connection_timeout), "S",
	 "close a connection silent for S seconds; must exceed --heartbeat\n(default %D)", NULL},
	{"request-timeout", OPT_SECONDS, 100, 3600000, F(request_timeout), "S",
	 "a request's headers must all come within S seconds of its first\n"
	 "line; a body gets S, then must keep up with --min-body-rate (default %D)", NULL},
	{"min-body-rate", OPT_SIZE, 1, 1L << 30, F(min_body_rate), "BYTES",
	 "bytes per second a body must average after --request-timeout;\n"
	 "slower ones are closed (default %D)", NULL},
	{"max-queued-points", OPT_INT, 1, 10000000, F(max_queued_points), "N",
	 "sweep points queued or running, all sweeps (default %D)", NULL},
	{"cpu-probe", OPT_SECONDS, 0, 1000, F(cpu_probe), "S",
	 "CPU seconds a new session's cost is measured for before it is\n"
	 "admitted; 0: the estimate alone (default %D)", NULL},
	{"dem-bed", OPT_STRING, 0, 0, F(dem_bed), "PATH",
	 "the bed program (default: convsim-bed next to this executable)",
	 "LIGGGHTS sessions (scene.feed_model liggghts, docs/dem.md):"},
	{"max-dem-sessions", OPT_INT, 0, 1024, F(max_dem_sessions), "N",
	 "sessions with a LIGGGHTS bed at once, each a bed process\n"
	 "holding a whole core (default %D; 0: none)", NULL},
	{"dem-ranks", OPT_INT, 1, 256, F(dem_ranks), "N",
	 "run each bed under mpirun -n N, holding N cores (default %D)", NULL},
	{"dem-timeout", OPT_SECONDS, 100, 86400000, F(dem_timeout), "S",
	 "fail a session whose bed process gives no answer for S seconds\n"
	 "(a hung bed; default %D)", NULL},
	{"max-dem-cost", OPT_SECONDS, 1000, 1000000000, F(max_dem_cost), "S",
	 "refuse a bed expected to take more than S CPU seconds a\n"
	 "simulated second (its grains over its DEM step; default %D)", NULL},
};
#undef F
#define NOPTS (sizeof opts / sizeof *opts)

/* The budgets that depend on the machine: 3/4 of its memory, one pace
 * "max" session per core, half the cores for paced sessions (the other
 * half answers requests, feeds their streams, about 15 % more than the
 * sessions themselves, and takes what a measured cost exceeds its
 * estimate), and requests settling at once on that other half: one per
 * core of it, rounded up (a settling takes a whole core, at a priority
 * above the workers'; more at once would only share those cores, each
 * slower, and take the paced sessions' half). */
static void machine_defaults(srv_config *cfg)
{
	long pages = sysconf(_SC_PHYS_PAGES), page = sysconf(_SC_PAGESIZE);
	long cores = sysconf(_SC_NPROCESSORS_ONLN);
	cfg->max_memory = pages > 0 && page > 0
				  ? (size_t)pages / 4 * 3 * (size_t)page
				  : (size_t)4 << 30;
	cfg->max_busy = cores > 0 ? (int)cores : 1;
	cfg->max_paced_cores = 0.5 * (cores > 0 ? (double)cores : 1.0);
	cfg->max_settling = cores > 1 ? (int)((cores + 1) / 2) : 1;
}

static const char *const levels[] = {"error", "warn", "info", "debug"};

/* The value of option o in cfg as --help shows a default. */
static void print_default(FILE *f, const opt *o, const srv_config *cfg)
{
	const char *at = (const char *)cfg + o->field;
	switch (o->kind) {
	case OPT_STRING: fputs(*(const char *const *)(const void *)at, f); break;
	case OPT_INT: fprintf(f, "%d", *(const int *)(const void *)at); break;
	case OPT_SIZE: fprintf(f, "%zu", *(const size_t *)(const void *)at); break;
	case OPT_MEMORY:
		fprintf(f, "%.1f GiB",
			(double)*(const size_t *)(const void *)at / (double)(1 << 30));
		break;
	case OPT_SECONDS:
	case OPT_CORES: fprintf(f, "%g", *(const double *)(const void *)at); break;
	case OPT_LEVEL: fputs(levels[*(const int *)(const void *)at], f); break;
	default: break;
	}
}

/* The help, from the option table and the defaults in cfg: the flag and
 * its argument, then the text from column 23 (or two spaces past a
 * longer flag), its continuation lines indented as far. */
static void usage(FILE *f, const srv_config *cfg)
{
	enum { COLUMN = 23 };
	fputs("usage: convsimd [options]\n", f);
	for (size_t i = 0; i < NOPTS; i++) {
		const opt *o = &opts[i];
		if (o->heading)
			fprintf(f, "%s\n", o->heading);
		int w = fprintf(f, "  --%s%s%s", o->name, *o->arg ? " " : "", o->arg);
		fprintf(f, "%*s", w < COLUMN - 1 ? COLUMN - w : 2, "");
		for (const char *c = o->doc; *c; c++) {
			if (c[0] == '%' && c[1] == 'D') {
				print_default(f, o, cfg);
				c++;
			} else if (*c == '\n') {
				fprintf(f, "\n%*s", COLUMN, "");
			} else {
				fputc(*c, f);
			}
		}
		fputc('\n', f);
	}
}

/* An integer in [lo, hi]; sizes (binary) may end in K, M, G or T. */
static int parse_int(const char *arg, const char *name, long lo, long hi,
		     int suffix, long *out)
{
	char *end;
	long v = strtol(arg, &end, 10);
	const char *units = "KMGT", *u = *end ? strchr(units, *end) : NULL;
	if (suffix && u && end[1] == '\0' && v >= 0 &&
	    v <= (hi >> (10 * (u - units + 1)))) {
		v <<= 10 * (u - units + 1);
		end++;
	}
	/* strtol (base 10) takes a sign and digits, after skipping white
	 * space: " 8" is refused as a number is elsewhere (decimal.h) */
	if (*end || end == arg || isspace((unsigned char)*arg) || v < lo || v > hi) {
		fprintf(stderr, "convsimd: %s must be an integer in [%ld, %ld]\n",
			name, lo, hi);
		return -1;
	}
	*out = v;
	return 0;
}

/* Set one option of cfg from its argument; -1 with a message if bad. */
static int set_option(srv_config *cfg, const opt *o, const char *arg)
{
	char *at = (char *)cfg + o->field, flag[40];
	long v;
	snprintf(flag, sizeof flag, "--%s", o->name);
	switch (o->kind) {
	case OPT_STRING: *(const char **)(void *)at = arg; return 0;
	case OPT_FLAG: *(int *)(void *)at = 1; return 0;
	case OPT_LIST: {
		srv_list *l = (srv_list *)(void *)at;
		if (l->n >= SRV_LIST_MAX || !*arg) {
			fprintf(stderr, "convsimd: %s takes a non-empty value, at "
					"most %d times\n", flag, SRV_LIST_MAX);
			return -1;
		}
		l->v[l->n++] = arg;
		return 0;
	}
	case OPT_INT:
	case OPT_SIZE:
	case OPT_MEMORY:
		if (parse_int(arg, flag, o->lo, o->hi, o->kind != OPT_INT, &v))
			return -1;
		if (o->kind == OPT_INT)
			*(int *)(void *)at = (int)v;
		else
			*(size_t *)(void *)at = (size_t)v;
		return 0;
	case OPT_SECONDS:
	case OPT_CORES: {
		/* lo, hi: the range in milliseconds, millionths of a core */
		double unit = o->kind == OPT_CORES ? 1e-6 : 1e-3;
		double s = NAN; /* a plain decimal number (decimal.h): not 0x10 */
		if (!sim_decimal(arg, &s) || !(s >= unit * (double)o->lo &&
					       s <= unit * (double)o->hi)) {
			fprintf(stderr, "convsimd: %s must be %s in [%g, %g]\n",
				flag, o->kind == OPT_CORES ? "cores" : "seconds",
				unit * (double)o->lo, unit * (double)o->hi);
			return -1;
		}
		*(double *)(void *)at = s;
		return 0;
	}
	default:
		for (int i = 0; i < 4; i++)
			if (strcmp(arg, levels[i]) == 0) {
				*(int *)(void *)at = i;
				return 0;
			}
		fprintf(stderr, "convsimd: --log-level must be "
				"error, warn, info or debug\n");
		return -1;
	}
}

/* 1..SRV_NODE_ID_MAX of [a-z0-9-], not starting with '-'. */
static int valid_node_id(const char *id)
{
	size_t n = strlen(id);
	if (n < 1 || n > SRV_NODE_ID_MAX || id[0] == '-')
		return 0;
	for (size_t i = 0; i < n; i++)
		if (!((id[i] >= 'a' && id[i] <= 'z') ||
		      (id[i] >= '0' && id[i] <= '9') || id[i] == '-'))
			return 0;
	return 1;
}

/* web/ next to the working directory, else next to the binary's parent. */
static void pick_web_root(srv_config *cfg, const char *argv0)
{
	static char web_guess[4096];
	struct stat sb;
	if (cfg->web_root)
		return;
	cfg->web_root = "web";
	if (stat("web", &sb) == 0 && S_ISDIR(sb.st_mode))
		return;
	const char *slash = strrchr(argv0, '/');
	if (!slash)
		return;
	/* beside the build directory, or where `make install` puts it */
	static const char *const guesses[] = {"../web", "../share/convsim/web"};
	for (size_t i = 0; i < sizeof guesses / sizeof *guesses; i++) {
		snprintf(web_guess, sizeof web_guess, "%.*s/%s", (int)(slash - argv0), argv0,
			 guesses[i]);
		if (stat(web_guess, &sb) == 0 && S_ISDIR(sb.st_mode)) {
			cfg->web_root = web_guess;
			return;
		}
	}
}

int srv_config_parse(srv_config *cfg, int argc, char **argv)
{
	struct option longopts[NOPTS + 2];
	for (size_t i = 0; i < NOPTS; i++)
		longopts[i] = (struct option){
			opts[i].name,
			opts[i].kind == OPT_FLAG ? no_argument : required_argument,
			0, (int)i};
	longopts[NOPTS] = (struct option){"help", no_argument, 0, 'h'};
	longopts[NOPTS + 1] = (struct option){0, 0, 0, 0};
	*cfg = defaults;
	machine_defaults(cfg);
	int c;
	while ((c = getopt_long(argc, argv, "h", longopts, NULL)) != -1) {
		if (c == 'h') {
			usage(stdout, cfg);
			return 1;
		}
		if (c < 0 || (size_t)c >= NOPTS) {
			usage(stderr, cfg);
			return -1;
		}
		if (set_option(cfg, &opts[c], optarg))
			return -1;
	}
	if (optind < argc) {
		fprintf(stderr, "convsimd: unexpected argument %s\n",
			argv[optind]);
		return -1;
	}
	if (cfg->node_id && !valid_node_id(cfg->node_id)) {
		fprintf(stderr, "convsimd: --node-id must be 1 to %d characters "
				"of a-z, 0-9 and '-', starting with a letter "
				"or digit\n", SRV_NODE_ID_MAX);
		return -1;
	}
	if (cfg->connection_timeout <= cfg->heartbeat) {
		fprintf(stderr, "convsimd: --connection-timeout (%g s) must "
				"exceed --heartbeat (%g s), or idle streams "
				"would be cut\n", cfg->connection_timeout,
			cfg->heartbeat);
		return -1;
	}
	pick_web_root(cfg, argv[0]);
	struct stat dd;
	if (cfg->data_dir && (stat(cfg->data_dir, &dd) != 0 ||
			      !S_ISDIR(dd.st_mode) ||
			      access(cfg->data_dir, W_OK) != 0)) {
		fprintf(stderr, "convsimd: --data-dir %s is not a writable "
				"directory\n", cfg->data_dir);
		return -1;
	}
	return 0;
}
