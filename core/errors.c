/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * errors.c - text of the core's return codes, generated from SIM_ERRNO_MAP
 * so that the enum and the messages share one list.
 */
#include "sim.h"

const char *sim_strerror(int err)
{
	switch (err) {
#define SIM_ERR_TEXT(name, msg)         \
	case SIM_##name:                \
		return msg;
		SIM_ERRNO_MAP(SIM_ERR_TEXT)
#undef SIM_ERR_TEXT
	default:
		return "unknown error";
	}
}
