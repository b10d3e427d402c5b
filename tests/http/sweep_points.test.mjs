// SPDX-License-Identifier: GPL-3.0-or-later
// A sweep runs what it was asked and says so when it cannot
// (docs/api-jobs.md "Studies over any setting"): a seed without lhs
// shuffles nothing and is refused naming seed; a value listed twice (in
// beta or a vary list) would run the same point twice and is refused
// naming the repeat; lhs and seed not whole numbers give their range.
// Nothing is started by any of them.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, CHEAP } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const problem = (r) => {
  const { type, field, detail, min, max } = r.body;
  return { status: r.status, type, field, detail, ...(min !== undefined ? { min, max } : {}) };
};
const INVALID = '/api/v1/problems/invalid-value';
const RANGE = '/api/v1/problems/out-of-range';
const vary = { mu: { from: 0, to: 1, step: 0.5 } };

test('seed without lhs, a repeated value, lhs or seed not whole: 422 naming it, nothing started', async () => {
  const before = (await req(d.base, 'GET', '/api/v1/sweeps')).text;
  for (const [body, want] of [
    [{ vary, seed: 3 }, { status: 422, type: INVALID, field: 'seed',
      detail: 'seed shuffles a Latin-hypercube sample: it applies only with lhs' }],
    [{ beta: [10, 10] }, { status: 422, type: INVALID, field: 'beta[1]',
      detail: 'beta[1] repeats beta[0] (10): each point runs once; list each value once' }],
    [{ beta: [10, 20], vary: { mu: [0.3, 0.5, 0.3] } }, { status: 422, type: INVALID, field: 'vary.mu[2]',
      detail: 'vary.mu[2] repeats vary.mu[0] (0.3): each point runs once; list each value once' }],
    [{ vary, lhs: 2.5 }, { status: 422, type: RANGE, field: 'lhs', min: 1, max: 2000,
      detail: 'lhs must be a whole number of points in [1, 2000]' }],
    [{ vary, lhs: 2, seed: 1.5 }, { status: 422, type: RANGE, field: 'seed', min: 0, max: 4294967295,
      detail: 'seed must be a whole number in [0, 4294967295]' }],
  ]) {
    const r = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, t_end: 0.5, ...body });
    assert.deepEqual(problem(r), want, JSON.stringify(body));
  }
  assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).text, before, 'nothing started');
});
