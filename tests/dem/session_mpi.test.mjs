// SPDX-License-Identifier: GPL-3.0-or-later
// A LIGGGHTS session whose bed runs under `mpirun -n 2` (the daemon's
// --dem-ranks 2, docs/dem.md "The bed process"): the bed split over two
// ranks in the bed process's group, the session's v that of `mpirun -n 2
// convsim run` on the same scene, and DELETE ends the whole group (mpirun
// and its ranks, no zombie). One-layer bed, 0.2 s.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { startDaemon, req, until, children, procState, SLOW } from '../http/lib.mjs';

const BUILD = process.env.BUILD || 'build';
const ROOT = new URL('../..', import.meta.url).pathname;
const CONVSIM = process.env.CONVSIM || `${ROOT}${BUILD}/convsim`;
// mpirun as root, more ranks than free cores (as tests/dem/mpi.test.mjs);
// leak detection off under ASan (the MPI stack's own leaks at exit)
Object.assign(process.env, { OMPI_ALLOW_RUN_AS_ROOT: '1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM: '1', OMPI_MCA_rmaps_base_oversubscribe: '1',
  ASAN_OPTIONS: [process.env.ASAN_OPTIONS, 'detect_leaks=0'].filter(Boolean).join(':') });


let d;
before(async () => { d = await startDaemon(['--worker-nice', '15', '--dem-ranks', '2']); });
after(async () => { await d.stop(); });

test('--dem-ranks 2: the bed on two ranks gives mpirun\'s v; DELETE ends mpirun and its ranks', { timeout: 300000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sessions', { scene: { feed_model: 'liggghts', layers: 1 }, pace: 'max', until: 0.2 });
  assert.equal(r.status, 201, JSON.stringify(r.body));
  const id = r.body.id, pid = r.body.bed.pid;
  assert.equal(r.body.bed.grains, 92);
  const ranks = children(pid);
  assert.equal(ranks.length, 2, `mpirun's ranks: ${ranks}`);
  const end = await until(async () => { const g = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body; return g.state !== 'running' && g; }, 240000 * SLOW, 'finished');
  assert.equal(end.state, 'finished', end.error);
  assert.equal(end.status.t, 0.2);
  const cli = JSON.parse(execFileSync('nice', ['-n', '15', 'mpirun', '-n', '2', CONVSIM, 'run', '--set', 'feed_model=liggghts',
    '--set', 'layers=1', '-d', '0.2', '-q'], { encoding: 'utf8', timeout: 240000 }));
  assert.equal(cli.mpi_ranks, 2);
  assert.equal(end.status.transport_velocity, cli.transport_velocity);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${id}`)).status, 204);
  for (const p of [pid, ...ranks]) assert.equal(procState(p), null, `process ${p} gone, no zombie`);
});
