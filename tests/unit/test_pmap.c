/* SPDX-License-Identifier: GPL-3.0-or-later */
/*
 * test_pmap.c - the library's parallel map (core/pmap.h): every index runs
 * exactly once whatever the thread count, progress is called once per job
 * with the count done rising by one, and never two calls at a time.
 */
#include <setjmp.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>
#include <cmocka.h>

#include <pthread.h>
#include <string.h>

#include "pmap.h"

#define N 500

typedef struct counts {
	int runs[N];            /* atomically incremented by the jobs */
	size_t calls, last_done;
	int seen[N], in_progress, overlapped, out_of_order;
} counts;

static void job(void *arg, size_t i)
{
	counts *c = arg;
	__atomic_fetch_add(&c->runs[i], 1, __ATOMIC_SEQ_CST);
}

static void progress(void *arg, size_t i, size_t done)
{
	counts *c = arg;
	if (__atomic_fetch_add(&c->in_progress, 1, __ATOMIC_SEQ_CST) != 0)
		c->overlapped = 1;
	c->calls++;
	if (done != c->last_done + 1)
		c->out_of_order = 1;
	c->last_done = done;
	c->seen[i]++;
	__atomic_fetch_sub(&c->in_progress, 1, __ATOMIC_SEQ_CST);
}

static void check_threads(int threads, size_t n)
{
	static counts c;
	memset(&c, 0, sizeof c);
	pmap_run(threads, n, job, &c, progress);
	for (size_t i = 0; i < N; i++) {
		assert_int_equal(c.runs[i], i < n ? 1 : 0);
		assert_int_equal(c.seen[i], i < n ? 1 : 0);
	}
	assert_int_equal(c.calls, n);
	assert_int_equal(c.last_done, n);
	assert_false(c.overlapped);
	assert_false(c.out_of_order);
}

static void every_index_once(void **state)
{
	(void)state;
	check_threads(1, N);
	check_threads(2, N);
	check_threads(7, N);
	check_threads(64, 3);
	check_threads(0, 10);   /* fewer than one: one */
	check_threads(200, N);  /* more than 64: 64 */
	check_threads(4, 0);
}

static void no_progress_hook(void **state)
{
	(void)state;
	static counts c;
	memset(&c, 0, sizeof c);
	pmap_run(3, N, job, &c, NULL);
	for (size_t i = 0; i < N; i++)
		assert_int_equal(c.runs[i], 1);
}

int main(void)
{
	const struct CMUnitTest tests[] = {
		cmocka_unit_test(every_index_once),
		cmocka_unit_test(no_progress_hook),
	};
	return cmocka_run_group_tests(tests, NULL, NULL);
}
