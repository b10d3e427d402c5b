/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * decimal.h - the one rule for a number given as text (decimal.c): a
 * command-line value, a --set, a CSV cell, a query parameter. strtod
 * alone takes more than a user means (0x10 as 16, 0x1p4, "inf", "nan",
 * leading spaces), so every reader of a number checks its text here
 * first.
 *
 * A plain decimal number is an optional sign (- or +), digits with an
 * optional decimal point (at least one digit: 5, 5., .5, 2.5), and an
 * optional exponent (e or E, an optional sign, at least one digit):
 * -2.5, 1e-3, +4E2. Nothing else, not even a space; a reader that
 * allows spaces around a value (a CSV cell) strips them itself.
 */
#ifndef CONVSIM_DECIMAL_H
#define CONVSIM_DECIMAL_H

#include <stddef.h>

/* The length of the plain decimal number that text starts with, reading
 * at most n characters (and none past a '\0'); 0 if it starts with none. */
size_t sim_decimal_len(const char *text, size_t n);

/* text[0, n) as a number into *out: 1 if those n characters are exactly
 * a plain decimal number and its value is finite (1e999 is not), else 0
 * with *out unchanged. */
int sim_decimal_n(const char *text, size_t n, double *out);

/* sim_decimal_n of the whole string text (NULL: 0). */
int sim_decimal(const char *text, double *out);

#endif
