// SPDX-License-Identifier: GPL-3.0-or-later
// A creation the cores for paced sessions cannot take is refused before
// its instance is built and settled (docs/budgets.md "What a refusal
// costs"): from an estimate of what the instance would integrate. That
// early answer must be the one the whole path gives: the same status and
// body, the same need in it (a scene with the symmetric reduction and one
// without, whose estimates differ by what is integrated), and nothing
// refused that fits: with the budget full for a default session, a pace
// "max" session (governed by --max-busy), a light scene and a default
// session at a pace that fits are still created. Holds are the estimate
// (--cpu-probe 0) and the sessions run slowly enough (pace <= 0.5) that
// no worker's measure replaces its hold before the test ends.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, metric, SLOW, g3, cores, pacedBusy, pacedEstimates } from './lib.mjs';

const DEFAULT = {};
const LIGHT = { scene: { drive: 'ideal', feed: false }, sample_rate: 10 };
const HEAVY = { scene: { trough_rotation: true, columns: 7, layers: 6 } }; // no symmetric reduction
const create = (d, body, pace) => req(d.base, 'POST', '/api/v1/sessions', { ...body, pace, until: 600 });
const held = async (d) => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_paced_cpu_cores');
const created = async (d) => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_sessions_created_total');

const busy = pacedBusy;

test('with the paced cores full, the early refusal answers as the whole path and refuses nothing that fits', { timeout: 90000 * SLOW }, async () => {
  const c = await pacedEstimates({ DEFAULT, LIGHT, HEAVY });
  // the scenes' estimates differ as the test needs them to: the light one
  // at pace 1/2 and a default at 1/4 fit the half left (LIGHT < DEFAULT / 2,
  // with room for the limit's rounding), the heavy one needs more than it
  assert.ok(c.LIGHT < 0.4 * c.DEFAULT && c.HEAVY > 1.6 * c.DEFAULT, JSON.stringify(c));
  const limit = Number((1.5 * c.DEFAULT).toPrecision(3));
  const d = await startDaemon(['--cpu-probe', '0', '--max-paced-cores', String(limit)]);
  try {
    // eight default sessions at pace 1/8 hold one default session's cores
    let sum = 0;
    for (let i = 0; i < 8; i++) {
      const r = await create(d, DEFAULT, 0.125);
      assert.equal(r.status, 201, r.text);
      sum += c.DEFAULT * 0.125;
    }
    assert.equal(await held(d), sum);
    const n = await created(d);
    // a default session at pace 1 does not fit the half left
    let r = await create(d, DEFAULT, 1);
    assert.equal(r.status, 503, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.headers.get('retry-after'), '5');
    assert.deepEqual(r.body, busy(c.DEFAULT, c.DEFAULT, 1, sum, limit));
    // a heavy scene at pace 1 needs more than the whole budget: 422 with
    // the largest pace that fits
    r = await create(d, HEAVY, 1);
    assert.equal(r.status, 422, r.text);
    assert.deepEqual(r.body, {
      type: '/api/v1/problems/out-of-range',
      title: 'Value out of range',
      status: 422,
      detail: `this session needs ${cores(c.HEAVY)} (${g3(1e3 * c.HEAVY)} ms of CPU per simulated s at pace 1), ` +
        `more than the ${limit} cores for paced sessions (--max-paced-cores); nothing was created, lower the pace`,
      instance: '/api/v1/sessions',
      field: 'pace',
      min: 0.001,
      max: limit / c.HEAVY,
      budget: 'cpu',
      limit,
    });
    assert.equal(await created(d), n, 'nothing created');
    assert.equal(await held(d), sum, 'nothing held');
    // pace "max" is not charged here (--max-busy governs it)
    r = await create(d, { ...DEFAULT, until: 1 }, 'max');
    assert.equal(r.status, 201, r.text);
    assert.equal(await held(d), sum);
    // a light scene fits what is left, and so does a default at pace 1/4
    r = await create(d, LIGHT, 0.5);
    assert.equal(r.status, 201, r.text);
    sum += c.LIGHT * 0.5;
    assert.equal(await held(d), sum);
    r = await create(d, DEFAULT, 0.25);
    assert.equal(r.status, 201, r.text);
    sum += c.DEFAULT * 0.25;
    assert.equal(await held(d), sum);
    // now neither a default at pace 1 nor the heavy scene at pace 1/8 fits
    r = await create(d, DEFAULT, 1);
    assert.equal(r.status, 503, r.text);
    assert.deepEqual(r.body, busy(c.DEFAULT, c.DEFAULT, 1, sum, limit));
    r = await create(d, HEAVY, 0.125);
    assert.equal(r.status, 503, r.text);
    assert.deepEqual(r.body, busy(c.HEAVY * 0.125, c.HEAVY, 0.125, sum, limit));
    assert.equal(await created(d), n + 3, 'the three that fit, no more');
    assert.equal(await held(d), sum);
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 11);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
