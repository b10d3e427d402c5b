/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * decimal.c - a plain decimal number from text (decimal.h): the syntax
 * checked by hand, then the value from strtod, which rounds it correctly.
 */
#include "decimal.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The count of decimal digits at text[i, n). */
static size_t digits(const char *text, size_t i, size_t n)
{
	size_t k = 0;
	while (i + k < n && text[i + k] >= '0' && text[i + k] <= '9')
		k++;
	return k;
}

size_t sim_decimal_len(const char *text, size_t n)
{
	size_t i = 0;
	if (i < n && (text[i] == '-' || text[i] == '+'))
		i++;
	size_t whole = digits(text, i, n);
	i += whole;
	size_t fraction = 0;
	if (i < n && text[i] == '.') {
		fraction = digits(text, i + 1, n);
		i += 1 + fraction;
	}
	if (whole + fraction == 0)
		return 0;
	if (i < n && (text[i] == 'e' || text[i] == 'E')) {
		size_t j = i + 1;
		if (j < n && (text[j] == '-' || text[j] == '+'))
			j++;
		size_t exp = digits(text, j, n);
		if (exp)
			i = j + exp; /* else the 'e' is not part of the number */
	}
	return i;
}

int sim_decimal_n(const char *text, size_t n, double *out)
{
	if (!text || n == 0 || sim_decimal_len(text, n) != n)
		return 0;
	/* strtod stops where the syntax above does, unless the text goes on
	 * past n with more of a number: then the span was not the number */
	char *end;
	double v = strtod(text, &end);
	if (end != text + n || !isfinite(v))
		return 0;
	*out = v;
	return 1;
}

int sim_decimal(const char *text, double *out)
{
	return text && sim_decimal_n(text, strlen(text), out);
}
