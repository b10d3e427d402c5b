// SPDX-License-Identifier: GPL-3.0-or-later
// Refused numbers of POST /api/v1/sessions, exact status and body: a
// setting without a unit that is no number reads "must be a number"
// (it read "must be a number ()"), one with a unit keeps it; sample_rate
// 0, -5, 1e9 and "x" each name the member sample_rate. Nothing is created.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const post = (body) => req(d.base, 'POST', '/api/v1/sessions', body);
const WRONG_TYPE = { type: '/api/v1/problems/wrong-type', title: 'Wrong type', status: 400, instance: '/api/v1/sessions' };
const OUT_OF_RANGE = { type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422,
  instance: '/api/v1/sessions' };

test('a number member that is none: its unit in brackets, none without a unit', async () => {
  for (const columns of [null, '']) {
    const r = await post({ scene: { columns } });
    assert.equal(r.status, 400, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.deepEqual(r.body, { ...WRONG_TYPE, detail: 'scene.columns must be a number', field: 'scene.columns',
      min: 1, max: 64 });
  }
  const r = await post({ params: { k_s1: 'stiff' } });
  assert.equal(r.status, 400, r.text);
  assert.equal(r.body.detail, 'params.k_s1 must be a number (N/m)');
  assert.equal(r.body.field, 'params.k_s1');
});

test('sample_rate 0, -5, 1e9 and "x": each problem names sample_rate', async () => {
  for (const rate of [0, -5, 1e9]) {
    const r = await post({ sample_rate: rate });
    assert.equal(r.status, 422, r.text);
    assert.deepEqual(r.body, { ...OUT_OF_RANGE, detail: 'sample_rate must lie in [1, 10000]', field: 'sample_rate',
      min: 1, max: 10000 });
  }
  const r = await post({ sample_rate: 'x' });
  assert.equal(r.status, 400, r.text);
  assert.deepEqual(r.body, { ...WRONG_TYPE, detail: 'sample_rate must be a number', field: 'sample_rate' });
  assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
});
