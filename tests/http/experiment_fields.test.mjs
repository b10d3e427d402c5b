// SPDX-License-Identifier: GPL-3.0-or-later
// An experiment's fresh session (`"session": {...}`) is refused as the same
// body at POST /api/v1/sessions is, with the field named by its path in the
// experiment's body: session.scene.layers for the memory budget,
// session.pace for the cores of paced sessions, session.scene.settle for a
// settling estimated beyond --max-cpu-seconds, session.integrator.method
// for an adaptive settling stopped there, and the spec's own checks
// (docs/api-errors.md). The rest of each
// refusal (status, detail, range, choices, budget) is the session's, byte
// for byte, and nothing is created.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, SLOW } from './lib.mjs';

const SCHEDULE = [{ beta: 30, until: 1 }];
const listed = async (d) => Promise.all(['experiments', 'sessions']
  .map(async (k) => (await req(d.base, 'GET', `/api/v1/${k}`)).text));

// spec refused at /sessions naming field; at /experiments the same problem
// with session.field
async function sameRefusal(d, spec, field, status = 422) {
  const was = await listed(d);
  const alone = await req(d.base, 'POST', '/api/v1/sessions', spec);
  assert.equal(alone.status, status, alone.text);
  assert.equal(alone.body.field, field, alone.text);
  const r = await req(d.base, 'POST', '/api/v1/experiments', { session: spec, schedule: SCHEDULE });
  assert.equal(r.status, status, r.text);
  assert.equal(r.headers.get('content-type'), 'application/problem+json');
  assert.deepEqual(r.body, { ...alone.body, instance: '/api/v1/experiments', field: `session.${field}` });
  assert.deepEqual(await listed(d), was, 'nothing created');
  return r.body;
}

async function withDaemon(args, fn) {
  const d = await startDaemon(args);
  try {
    await fn(d);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
}

test('the memory budget names session.scene.layers with its range', { timeout: 60000 * SLOW }, () =>
  withDaemon(['--max-memory', '64M'], async (d) => {
    const b = await sameRefusal(d, { scene: { columns: 64, layers: 64 }, pace: 1 }, 'scene.layers');
    assert.equal(b.budget, 'memory');
    assert.equal(b.min, 1);
    assert.ok(b.max >= 1 && b.max < 64, JSON.stringify(b));
  }));

test('the cores for paced sessions name session.pace with its one choice', { timeout: 60000 * SLOW }, () =>
  withDaemon(['--max-paced-cores', '1'], async (d) => {
    const slow = { scene: { drive: 'ideal', columns: 1, layers: 2, start: 'rest' }, integrator: { dt: 2e-10 },
      sample_rate: 10000, pace: 0.001 };
    const b = await sameRefusal(d, slow, 'pace');
    assert.deepEqual(b.choices, ['max']);
    assert.equal(b.budget, 'cpu');
  }));

test('a settling beyond --max-cpu-seconds names session.scene.settle, an adaptive one session.integrator.method',
  { timeout: 60000 * SLOW }, () =>
    withDaemon(['--max-cpu-seconds', '0.2'], async (d) => {
      const large = await sameRefusal(d, { scene: { columns: 64, layers: 64 }, pace: 0.01, sample_rate: 1 },
        'scene.settle');
      assert.equal(large.min, 0);
      assert.ok(large.max > 0 && large.max < 0.6, JSON.stringify(large));
      // stopped at the bound: the detail's CPU figures differ run to run
      const r = await req(d.base, 'POST', '/api/v1/experiments',
        { session: { integrator: { method: 'dopri5' } }, schedule: SCHEDULE });
      assert.equal(r.status, 422, r.text);
      const { detail, ...rest } = r.body;
      assert.deepEqual(rest, {
        type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422,
        instance: '/api/v1/experiments', field: 'session.integrator.method', budget: 'cpu', limit: 0.2,
        choices: ['rk4', 'euler', 'dem'],
      });
      assert.match(detail, /^the steady start's settling stopped at /);
    }));

// parsed and validated: named so before (a guard on the one rewrite)
test('a spec out of its range names its session. path', { timeout: 30000 * SLOW }, () =>
  withDaemon([], async (d) => {
    const b = await sameRefusal(d, { scene: { layers: 0 } }, 'scene.layers');
    assert.equal(b.min, 1);
    const m = await sameRefusal(d, { integrator: { method: 'nope' } }, 'integrator.method', 422);
    assert.ok(m.choices.includes('rk4'), JSON.stringify(m));
  }));
