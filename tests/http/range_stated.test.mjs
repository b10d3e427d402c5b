// SPDX-License-Identifier: GPL-3.0-or-later
// A range's ends in a problem are the values its detail states: the m_n a
// dem session takes is at most 0.2 x 166 kg / 40 elements, which binary
// arithmetic makes 0.8300000000000001; the 422 says 0.83 in the detail and
// in max, and 0.83 itself is taken; a heavier feed's bound, just above
// it, is stated rounded up (docs/api.md "Disturbances").
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, SLOW } from './lib.mjs';

test("a dem session's m_n bound: max is the 0.83 the detail states, and 0.83 is taken", { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { integrator: { method: 'dem' }, pace: 0.1 });
    assert.equal(c.status, 201, c.text);
    const path = `/api/v1/sessions/${c.body.id}`;
    const r = await req(d.base, 'PATCH', path, { m_n: 5 });
    assert.equal(r.status, 422, r.text);
    assert.deepEqual({ type: r.body.type, field: r.body.field, min: r.body.min, max: r.body.max }, {
      type: '/api/v1/problems/out-of-range', field: 'm_n', min: 0.0001, max: 0.83,
    });
    assert.match(r.body.detail, /^m_n must lie in \[0\.0001, 0\.83\] kg in this session; got 5: /);
    const ok = await req(d.base, 'PATCH', path, { m_n: r.body.max });
    assert.equal(ok.status, 200, ok.text);
    assert.deepEqual(ok.body.applied, { m_n: 0.83 });
    assert.equal(ok.body.status.m_n, 0.83);
    // a heavy feed stays heavier than the bound: its min rounded up, and taken
    const h = await req(d.base, 'POST', '/api/v1/sessions', { integrator: { method: 'dem', substeps: 4 }, params: { m_n: 1 }, pace: 0.1 });
    assert.equal(h.status, 201, h.text);
    const hp = `/api/v1/sessions/${h.body.id}`;
    const lo = await req(d.base, 'PATCH', hp, { m_n: 0.5 });
    assert.equal(lo.status, 422, lo.text);
    assert.deepEqual([lo.body.field, lo.body.min, lo.body.max], ['m_n', 0.830001, 100]);
    assert.match(lo.body.detail, /^m_n must lie in \[0\.830001, 100\] kg in this session; got 0\.5: /);
    assert.equal((await req(d.base, 'PATCH', hp, { m_n: lo.body.min })).status, 200);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
