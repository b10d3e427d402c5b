// SPDX-License-Identifier: GPL-3.0-or-later
// A refused job start changes nothing (docs/jobs.md "Kept jobs"): with the
// registry full (--max-experiments), a new job's place is reserved before
// its start, which may still refuse it (an experiment's session: a
// running one that does not exist, 404; a fresh one whose settling is
// beyond --max-cpu-seconds, 422). The oldest finished job that makes room
// was removed at the reservation, so a refused POST took it with it. Now
// it is only claimed there and removed once the start is certain: every
// finished experiment is still listed and fetchable after the refusals,
// and a start that succeeds evicts exactly the oldest one. Sweeps and fits
// take the same path (job.c); their starts do not refuse once reserved
// (a fit's only when its thread cannot start), and the sweeps' eviction is
// checked to come with a start as before.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, CHEAP, SLOW } from './lib.mjs';

const CAP = 2;
const SHORT = { session: { ...CHEAP, pace: 'max' }, schedule: [{ beta: 38, until: 0.05 }] };
const listed = async (d, kind) => (await req(d.base, 'GET', `/api/v1/${kind}`)).body[kind].map((x) => x.id).sort();
const finished = async (d, kind, body, state) => {
  const r = await req(d.base, 'POST', `/api/v1/${kind}`, body);
  assert.ok(r.status === 201 || r.status === 202, r.text);
  await until(async () => (await req(d.base, 'GET', `/api/v1/${kind}/${r.body.id}`)).body.state === state,
    30000, `${kind} ${r.body.id} ${state}`);
  return r.body.id;
};

test('with --max-experiments full of finished ones, refused starts evict none; a start evicts the oldest', { timeout: 120000 * SLOW }, async () => {
  const d = await startDaemon(['--max-experiments', String(CAP), '--max-cpu-seconds', '0.5']);
  try {
    const kept = [];
    for (let i = 0; i < CAP; i++) kept.push(await finished(d, 'experiments', SHORT, 'done'));
    const before = await Promise.all(kept.map(async (id) => (await req(d.base, 'GET', `/api/v1/experiments/${id}`)).text));
    // refused after the reservation: a running session that does not exist
    const missing = await req(d.base, 'POST', '/api/v1/experiments', { ...SHORT, session: 'ffffffffffffffff' });
    assert.equal(missing.status, 404, missing.text);
    assert.deepEqual(missing.body, {
      type: '/api/v1/problems/not-found', title: 'Not found', status: 404,
      detail: 'no session with id "ffffffffffffffff"', instance: '/api/v1/experiments', field: 'session',
    });
    // and a fresh 64 x 64 session whose settling is beyond --max-cpu-seconds
    const large = await req(d.base, 'POST', '/api/v1/experiments',
      { ...SHORT, session: { scene: { columns: 64, layers: 64 }, pace: 'max' } });
    assert.equal(large.status, 422, large.text);
    assert.equal(large.body.field, 'session.scene.settle', large.text);
    // every finished experiment is still there, as it was
    assert.deepEqual(await listed(d, 'experiments'), [...kept].sort());
    for (const [i, id] of kept.entries()) {
      const g = await req(d.base, 'GET', `/api/v1/experiments/${id}`);
      assert.equal(g.status, 200, `${id}: ${g.text}`);
      assert.equal(g.text, before[i]);
    }
    // a start that succeeds evicts exactly the oldest finished one
    const next = await req(d.base, 'POST', '/api/v1/experiments', SHORT);
    assert.equal(next.status, 201, next.text);
    assert.deepEqual(await listed(d, 'experiments'), [kept[1], next.body.id].sort());
    assert.equal((await req(d.base, 'GET', `/api/v1/experiments/${kept[0]}`)).status, 404);
    // two starts at once, each claiming a different finished one (a
    // claimed one is not claimed twice): both go and the cap holds
    await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${next.body.id}`)).body.state === 'done',
      30000, 'the third experiment done');
    const burst = await Promise.all([SHORT, SHORT].map((body) => req(d.base, 'POST', '/api/v1/experiments', body)));
    assert.deepEqual(burst.map((r) => r.status), [201, 201], burst.map((r) => r.text).join('\n'));
    assert.deepEqual(await listed(d, 'experiments'), burst.map((r) => r.body.id).sort());
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('--max-sweeps full of finished ones: the next sweep evicts exactly the oldest, once started', { timeout: 120000 * SLOW }, async () => {
  const d = await startDaemon(['--max-sweeps', String(CAP)]);
  const sweep = { ...CHEAP, beta: [30], rotations: ['cw'], t_end: 0.3 };
  try {
    const kept = [];
    for (let i = 0; i < CAP; i++) kept.push(await finished(d, 'sweeps', sweep, 'done'));
    const next = await req(d.base, 'POST', '/api/v1/sweeps', sweep);
    assert.equal(next.status, 202, next.text);
    assert.deepEqual(await listed(d, 'sweeps'), [kept[1], next.body.id].sort());
    assert.equal((await req(d.base, 'GET', `/api/v1/sweeps/${kept[0]}`)).status, 404);
    // a sweep refused before its reservation (a bad body) evicts nothing
    const bad = await req(d.base, 'POST', '/api/v1/sweeps', { rotations: ['up'] });
    assert.equal(bad.status, 422, bad.text);
    assert.deepEqual(await listed(d, 'sweeps'), [kept[1], next.body.id].sort());
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
