/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * peers.h - the peers harness's parts (peers.c): the gate's points with
 * their reference and the error convention (peers_points.c), and the
 * harness's own sanity check (peers_check.c).
 */
#ifndef CONVSIM_PEERS_H
#define CONVSIM_PEERS_H

#include <stdint.h>

/* One point of the gate: beta (deg), sense, v_ref (m/s). */
typedef struct pt {
	double beta;
	char rot[4];
	double vref;
} pt;

/* The points a run covers, and the peak |v_ref| over all 74. */
typedef struct pset {
	int n;
	pt p[74];
	double peak;
} pset;

/* What one run yields. */
typedef struct prow {
	double v;
	uint64_t steps, rejected, rhs;
	char status[200];
} prow;

/* Reads the reference (beta_deg rotation v_ref ... per line, a header
 * first) from path and keeps the points of list: NULL or "all" (every
 * point), "cw" or "ccw" (one sense), or "BETA:ROT,BETA:ROT,..." Returns 0,
 * or -1 with a message on stderr. */
int pset_load(pset *ps, const char *path, const char *list);

/* |v - v_ref| by the convention of docs/accuracy.md "Accuracy and speed": relative
 * to |v_ref| where |v_ref| >= 0.3 peak, else to the peak. */
double pset_error(const pset *ps, const pt *p, double v);

/* Every peer at a tight tolerance against the core's rk4 at a small step
 * on the machine-alone orbit (the trough's x, y over 0.5 s after the
 * steady start, the settling included); prints one line each and returns
 * 0 when all agree to 1e-6 of the orbit's amplitude, else 1. */
int peers_check(void);

/* Reads DIR/peers.tsv and writes DIR/peers.md (headed by CMD, over the
 * npts points described by `points`) and DIR/peers_summary.tsv (one row a
 * setting: kind name setting points worst cpu_per_point complete).
 * peers_report.c. Returns 0, or 1 with a message when a file fails. */
int peers_report(const char *dir, const char *cmd, int npts, const char *points);

#endif
