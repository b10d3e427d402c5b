/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * suggest.h - "did you mean": the nearest of a list of names to a word
 * that is not one of them, by edit distance. Header only (static inline,
 * libc), so that the CLI (unknown options, settings, presets) and the
 * API (unknown query parameters and members) suggest alike.
 */
#ifndef CONVSIM_SUGGEST_H
#define CONVSIM_SUGGEST_H

#include <stddef.h>
#include <string.h>

/* Edit distance (Levenshtein) of two names shorter than 64 bytes (64 for
 * longer ones). */
static inline size_t sim_edit_distance(const char *a, const char *b)
{
	size_t n = strlen(b), row[64];
	if (n >= 64 || strlen(a) >= 64)
		return 64;
	for (size_t j = 0; j <= n; j++)
		row[j] = j;
	for (size_t i = 1; a[i - 1]; i++) {
		size_t diag = row[0];
		row[0] = i;
		for (size_t j = 1; j <= n; j++) {
			size_t up = row[j];
			size_t best = diag + (a[i - 1] != b[j - 1]);
			if (row[j] + 1 < best)
				best = row[j] + 1;
			if (row[j - 1] + 1 < best)
				best = row[j - 1] + 1;
			row[j] = best;
			diag = up;
		}
	}
	return row[n];
}

/* The name nearest to word among n names, each a `const char *` at the
 * start of an element `stride` bytes after the previous one (an array of
 * names, or of structs whose first member is the name); NULL when none is
 * near: at most 1 edit for words under 4 letters, 2 under 9, else 3, or
 * word a prefix of the name. */
static inline const char *sim_suggest(const char *word, const void *names, size_t n,
				      size_t stride)
{
	const char *best = NULL;
	size_t best_d = (size_t)-1, len = strlen(word);
	for (size_t i = 0; i < n; i++) {
		const char *name = *(const char *const *)(const void *)((const char *)names + i * stride);
		if (!name)
			continue;
		size_t d = sim_edit_distance(word, name);
		if (len >= 2 && strncmp(name, word, len) == 0)
			d = 1;
		if (d < best_d) {
			best_d = d;
			best = name;
		}
	}
	size_t limit = len < 4 ? 1 : len < 9 ? 2 : 3;
	return best && best_d <= limit ? best : NULL;
}

#endif
