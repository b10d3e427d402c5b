/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * records_v1.h - internal to store_v1.c: the records of format version 1
 * as c793934 laid them out (x86-64 and aarch64 Linux), written out rather
 * than through today's types, with the sizes that build wrote held by
 * static_asserts.
 */
#ifndef CONVSIM_RECORDS_V1_H
#define CONVSIM_RECORDS_V1_H

#include <assert.h>
#include <stdint.h>

#include "records.h"

/* ---- c793934's layouts ------------------------------------------------------ */

typedef struct v1_method {
	char name[24];
	double dt, rtol, atol;
	int32_t substeps, feed_events;
} v1_method;

/* sim_params and sim_scene as c793934 laid them out: each member in its
 * order, with its type; the same lists copy them into today's structs by
 * name */
#define V1_PARAMS(X)                                                                      \
	X(double, l1) X(double, l2) X(double, h) X(double, k_x) X(double, k_y)            \
	X(double, b_x) X(double, b_y) X(double, M_r) X(double, J_r) X(double, m)          \
	X(double, e) X(double, J_w) X(double, w_x) X(double, w_y) X(double, b_phi)        \
	X(double, M_load) X(double, M_ut) X(double, omega_ss) X(double, slip_ut)          \
	X(int32_t, rotation) X(double, m1) X(double, m2) X(double, k_s1) X(double, k_s2)  \
	X(double, b_s1) X(double, b_s2) X(double, p1_x) X(double, p1_y) X(double, p2_x)   \
	X(double, p2_y) X(double, c) X(double, beta) X(double, beta_rate)                 \
	X(double, beta_accel) X(double, m_n) X(double, k_c) X(double, p) X(double, R)     \
	X(double, mu) X(double, h_d) X(double, column_span) X(double, g)                  \
	X(double, drive_accel)
#define V1_SCENE(X)                                                                       \
	X(int32_t, feed) X(int32_t, columns) X(int32_t, layers) X(int32_t, drive)         \
	X(int32_t, trough_rotation) X(int32_t, mirror) X(int32_t, feed_coupling)          \
	X(int32_t, friction) X(double, friction_eps) X(int32_t, motor_on)                 \
	X(double, transient) X(int32_t, start) X(double, settle)
#define V1_MEMBER(type, name) type name;
#define V1_COPY(type, name) to->name = from->name;

typedef struct v1_params {
	V1_PARAMS(V1_MEMBER)
} v1_params;

typedef struct v1_scene {
	V1_SCENE(V1_MEMBER)
} v1_scene;

typedef struct v1_spec {
	char preset[32];
	v1_params params;
	v1_scene scene;
	v1_method method;
	double pace, until, sample_rate;
} v1_spec;

typedef struct v1_spec_record {
	char id[24];
	v1_spec spec;
	double created;
	int32_t owned, pad;
} v1_spec_record;

typedef struct v1_value {
	double si, user;
} v1_value;

typedef struct v1_segment {
	v1_value beta;
	double until;
	int32_t state, pad;
	double t_command, t_end, steady_velocity, mean_velocity, uncertainty;
	int32_t steady, pad2;
	double reversal_time, start_velocity;
} v1_segment;

typedef struct v1_exp_req {
	int32_t fresh;
	v1_spec spec;
	char session_id[24];
	v1_value beta_rate;
	int32_t keep_session, nseg;
	v1_segment seg[32];
} v1_exp_req;

typedef struct v1_exp_record {
	char id[24], session_id[24];
	v1_exp_req req;
	int32_t state, cur;
	char error[256];
	double t0, t_now;
	uint64_t seg_first, rec_n;
	double rec_spacing;
} v1_exp_record;

typedef struct v1_sweep_req {
	v1_spec spec;
	int32_t nbeta;
	uint64_t betas; /* a pointer, NULL in the file */
	int32_t nrot, rotations[2];
	double t_end;
} v1_sweep_req;

typedef struct v1_sweep_record {
	char id[24];
	v1_sweep_req req;
	uint64_t total, done;
	int32_t cancelled, pad;
} v1_sweep_record;

typedef struct v1_sweep_point {
	v1_value beta;
	int32_t rotation, state;
	double velocity, uncertainty;
	int32_t steady, mirrored;
	char error[160];
} v1_sweep_point;

typedef struct v1_ckpt_record {
	int32_t state, exp_started;
	double pace, until;
	char error[256];
	char exp_id[24];
	uint64_t exp_len, sim_len;
} v1_ckpt_record;

typedef struct v1_ckpt_trailer {
	uint64_t logged;
	double t;
} v1_ckpt_trailer;

/* the core's checkpoint header as c793934 wrote it (core/checkpoint.c):
 * its state vectors y, y_obs, y_prev (n doubles each) follow, then
 * t_int and t_obs */
typedef struct v1_core_header {
	char magic[8];
	uint32_t version, n, columns, ctl_size, est_size, ws_size;
	uint64_t payload, checksum;
} v1_core_header;

#if defined(__x86_64__) || defined(__aarch64__)
static_assert(sizeof(v1_params) == 344 && sizeof(v1_scene) == 72, "c793934's settings");
static_assert(sizeof(v1_spec_record) == 568, "c793934's spec.bin");
static_assert(sizeof(v1_exp_record) == 4008, "c793934's experiment record");
static_assert(sizeof(v1_sweep_record) == 616, "c793934's sweep record");
static_assert(sizeof(v1_sweep_point) == 208, "c793934's sweep point");
static_assert(sizeof(v1_ckpt_record) == 320, "c793934's checkpoint head");
static_assert(sizeof(v1_core_header) == 48, "c793934's core checkpoint header");
#endif

#endif
