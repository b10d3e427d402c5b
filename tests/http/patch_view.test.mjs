// SPDX-License-Identifier: GPL-3.0-or-later
// A PATCH's answer and every later GET show the accepted targets: on a
// running session at once (not the target before the change), on a
// paused or finished one without waiting for a resume, and in the unit
// and value sent (60 deg is 60, not 59.99999999999999).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, CHEAP, SLOW } from './lib.mjs';

test('PATCH answers and later GETs show the accepted beta and rotation, running, paused and finished', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(c.status, 201, c.text);
    const path = `/api/v1/sessions/${c.body.id}`;
    const get = async () => (await req(d.base, 'GET', path)).body.status;
    // running at pace 1: every answer shows its own new target, exactly
    for (const beta of [60, 128, 37.5, 45.1, 12.3456789, 60]) {
      const p = await req(d.base, 'PATCH', path, { beta });
      assert.equal(p.status, 200, p.text);
      assert.equal(p.body.status.beta_target, beta, `running: answer to beta ${beta}`);
      assert.equal((await get()).beta_target, beta, `running: GET after beta ${beta}`);
    }
    // paused: the answer and every GET, before any resume
    const pause = await req(d.base, 'PATCH', path, { running: false });
    assert.equal(pause.body.state, 'paused', pause.text);
    const p = await req(d.base, 'PATCH', path, { beta: 25, rotation: 'ccw' });
    assert.equal(p.status, 200, p.text);
    assert.equal(p.body.status.beta_target, 25);
    assert.equal(p.body.status.rotation, 'ccw');
    for (let i = 0; i < 3; i++) {
      const g = await get();
      assert.equal(g.beta_target, 25, 'paused: GET');
      assert.equal(g.rotation, 'ccw', 'paused: GET');
    }
    // finished: the same
    const f = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 0.2 });
    const fpath = `/api/v1/sessions/${f.body.id}`;
    await until(async () => (await req(d.base, 'GET', fpath)).body.state === 'finished', 20000, 'finish');
    const fp = await req(d.base, 'PATCH', fpath, { beta: 60, rotation: 'ccw' });
    assert.equal(fp.status, 200, fp.text);
    assert.equal(fp.body.status.beta_target, 60);
    assert.equal(fp.body.status.rotation, 'ccw');
    const fg = (await req(d.base, 'GET', fpath)).body;
    assert.equal(fg.state, 'finished');
    assert.equal(fg.status.beta_target, 60);
    assert.equal(fg.status.rotation, 'ccw');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
