// SPDX-License-Identifier: GPL-3.0-or-later
// The coupled run under `mpirun -n 2` (LIGGGHTS's domain split in two,
// the machine on both ranks, rank 0 printing): the same bed and machine
// as one process, so the same weight carried and a v within the packing
// noise of the one-process run (the ranks sum the bed's totals in another
// order, and the bed's chaos makes that a different packing; 5 %, the
// spread of three packing seeds being 1-2 %: docs/dem.md).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import '../tether.mjs'; // nothing started here outlives the test

const BUILD = process.env.BUILD || 'build';
const ROOT = new URL('../..', import.meta.url).pathname;
const CONVSIM = process.env.CONVSIM || `${ROOT}${BUILD}/convsim`;
const SCENE = ['run', '--set', 'feed_model=liggghts', '--set', 'layers=2', '-d', '0.6', '--set', 'transient=0.2', '-q'];
// (leak detection off under ASan: the MPI stack's own leaks at exit, as in dem.test.mjs)
const env = { ...process.env, ASAN_OPTIONS: [process.env.ASAN_OPTIONS, 'detect_leaks=0'].filter(Boolean).join(':'), OMPI_ALLOW_RUN_AS_ROOT: '1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM: '1', OMPI_MCA_rmaps_base_oversubscribe: '1' };
const run = (cmd, args) => JSON.parse(execFileSync(cmd, args, { encoding: 'utf8', timeout: 600000, env }));

test('mpirun -n 2: one summary, two ranks, v within 5 % of one process, the weight carried', () => {
  const one = run('nice', ['-n', '15', CONVSIM, ...SCENE]);
  const two = run('nice', ['-n', '15', 'mpirun', '-n', '2', CONVSIM, ...SCENE]);
  assert.equal(one.mpi_ranks, 1);
  assert.equal(two.mpi_ranks, 2);
  assert.equal(two.grains, one.grains);
  assert.ok(Math.abs(two.balance.load_mean_y / two.balance.weight + 1) < 0.03, `load ${two.balance.load_mean_y}`);
  const rel = Math.abs(two.transport_velocity - one.transport_velocity) / Math.abs(one.transport_velocity);
  assert.ok(rel < 0.05, `1 rank ${one.transport_velocity}, 2 ranks ${two.transport_velocity}`);
});
