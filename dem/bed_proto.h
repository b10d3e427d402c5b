/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * bed_proto.h - the bed server's protocol (docs/dem.md "The bed
 * process"): lines of text over two pipes, the daemon's requests on the
 * child's stdin, one answer each on a descriptor the child was given.
 * Every number is C99 hexadecimal floating point (printf %a), exact both
 * ways, so a bed in a child gives the coupling the very bits a bed in the
 * process would.
 *
 *   -> bed G DMIN DMAX RHO CX CY K/M E MU MUROLL FREEZE SEED G SETTLE
 *   <- state T MASS X Z PX PZ KIN KROT CPU GRAINS     (settled: t = 0)
 *   -> advance AX AY H                                 (per interval)
 *   <- state ...                                       (at its end)
 *   <- error SENTENCE                                  (to any request)
 *   -> quit, or the end of its stdin: the child exits 0
 *
 * The child answers `error` for a request it cannot read or a bed it
 * cannot build and goes on reading; LIGGGHTS itself may end the child,
 * which the parent sees as the end of the answers.
 */
#ifndef CONVSIM_DEM_BED_PROTO_H
#define CONVSIM_DEM_BED_PROTO_H

#include <stddef.h>

#include "dem.h"

/* Longest line either side writes or reads, with its newline. */
#define DEM_PROTO_LINE 1024

/* The request that builds a bed, into buf; its length, or -1 if it does
 * not fit. */
int dem_proto_bed_line(char *buf, size_t len, const dem_bed_spec *s);
/* Read a `bed` request's numbers (after the word) into *s: 0, or -1. */
int dem_proto_bed_parse(const char *args, dem_bed_spec *s);
/* An advance request, into buf; its length, or -1. */
int dem_proto_advance_line(char *buf, size_t len, double ax, double ay, double interval);
/* Read an advance request's numbers (after the word): 0, or -1. */
int dem_proto_advance_parse(const char *args, double *ax, double *ay, double *interval);
/* A state answer, into buf; its length, or -1. */
int dem_proto_state_line(char *buf, size_t len, const dem_bed_state *st, double cpu,
			 int grains);
/* Read a state answer's numbers (after the word): 0, or -1. */
int dem_proto_state_parse(const char *args, dem_bed_state *st, double *cpu, int *grains);

#endif
