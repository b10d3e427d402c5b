// SPDX-License-Identifier: GPL-3.0-or-later
// scene.feed_model auto picking a LIGGGHTS bed in the daemon (docs/feed-
// models.md "feed_model=auto"), with the real bed process
// (build/convsim-bed): a one-layer bed of 92 grains where the column model
// is not checked; the 201 body says the pick and the bed's expected cost
// (dem_bed_spec_cost, the estimate --max-dem-cost bounds), the session runs
// the bed; a daemon whose --max-dem-cost is below it answers 422 on
// scene.model_tol with why, and nothing is created.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, SLOW } from '../http/lib.mjs';

const AUTO = { pace: 1, scene: { feed_model: 'auto', model_tol: 0.01, layers: 1 }, params: { k_c: 10000, m_n: 0.005 } };
const NOTE = 'not checked against DEM with this contact (m_n differs): nearest checked is 1 layers, czubak2016 against glass';

let d, tight;
before(async () => {
  d = await startDaemon(['--worker-nice', '15']);
  tight = await startDaemon(['--max-dem-cost', '2']);
});
after(async () => { await d.stop(); await tight.stop(); });

test('feed_model auto: not checked, a LIGGGHTS bed, its expected cost in the 201 body', { timeout: 60000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sessions', AUTO);
  assert.equal(r.status, 201, JSON.stringify(r.body));
  try {
    assert.equal(r.body.feed_model_pick.model, 'liggghts');
    assert.equal(r.body.feed_model_pick.why, `liggghts: the column model is not within model_tol 0.01 m/s here (${NOTE}); ` +
      'a LIGGGHTS bed is the DEM itself, expected to cost about 0.78 CPU s a simulated second');
    // 92 grains at k/m 2e6 1/s^2: 3.2e-7 CPU s a grain's step of 3.77e-5 s
    assert.ok(Math.abs(r.body.feed_model_pick.expected_cpu_s_per_s - 0.77995555916634) < 1e-9,
      `${r.body.feed_model_pick.expected_cpu_s_per_s}`);
    assert.equal(r.body.bed.grains, 92);
    const s = (await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}`)).body;
    assert.equal(s.spec.scene.feed_model, 'liggghts');
    assert.deepEqual(s.feed_model_pick, r.body.feed_model_pick);
  } finally {
    await req(d.base, 'DELETE', `/api/v1/sessions/${r.body.id}`);
  }
});

test('feed_model auto: a bed over --max-dem-cost, 422 on scene.model_tol, nothing created', { timeout: 20000 * SLOW }, async () => {
  // k_c ten times stiffer: steps sqrt(10) shorter, 0.78 * sqrt(10) CPU s
  const r = await req(tight.base, 'POST', '/api/v1/sessions', { ...AUTO, params: { k_c: 100000, m_n: 0.005 } });
  assert.equal(r.status, 422);
  assert.equal(r.body.field, 'scene.model_tol');
  assert.equal(r.body.min, 0);
  assert.equal(r.body.max, 1);
  assert.equal(r.body.detail, `no feed model within model_tol 0.01 m/s here: the column model: ${NOTE}; ` +
    'a LIGGGHTS bed would cost about 2.47 CPU s a simulated second, over --max-dem-cost 2');
  assert.equal((await req(tight.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0);
});
