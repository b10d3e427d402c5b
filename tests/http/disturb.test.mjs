// SPDX-License-Identifier: GPL-3.0-or-later
// Disturbances on a running session (docs/api.md "Disturbances",
// docs/MODEL.md "Disturbances"): PATCH of the column feed's m_n and mu
// answers what it applied, shows in the status and in the stream's
// control event, refuses a value outside its range with a 422 naming the
// field and the range (nothing changed), refuses a session without a
// column feed, and survives a restart: from the checkpoint, and from the
// control log's replay after kill -9.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, streamUntil, until, sleep, CHEAP, NO_FEED, SLOW } from './lib.mjs';

const get = async (d, id) => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;

test('PATCH m_n and mu: applied, in the status and the stream; out of range a 422 that changes nothing', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(c.status, 201, c.text);
    const id = c.body.id;
    assert.equal(c.body.status.m_n, 0.5);
    assert.equal(c.body.status.mu, 0.4);

    const event = streamUntil(d.base, id, (r) => r.type === 'control' && 'm_n' in r && r);
    await sleep(300);
    const p = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { m_n: 0.75 });
    assert.equal(p.status, 200, p.text);
    assert.deepEqual(p.body.applied, { m_n: 0.75 });
    assert.equal(typeof p.body.t_effective, 'number');
    assert.equal(p.body.status.m_n, 0.75);
    assert.equal(p.body.status.mu, 0.4);
    const ev = await event;
    assert.equal(ev.m_n, 0.75);
    assert.equal(ev.t_effective, p.body.t_effective);
    assert.equal('mu' in ev, false, 'the event holds what was sent');
    // the stored energy's jump is input, booked apart as the disturbance's
    const e0 = p.body.status.energy;
    assert.ok(e0.disturbance > 0 && e0.disturbance < e0.input, JSON.stringify(e0));

    const q = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { mu: 0.6, beta: 40 });
    assert.equal(q.status, 200, q.text);
    assert.deepEqual(q.body.applied, { beta: 40, mu: 0.6 });
    let st = (await get(d, id)).status;
    assert.equal(st.m_n, 0.75);
    assert.equal(st.mu, 0.6);
    // the books close after both changes; mu brought no energy
    await sleep(500);
    const e = (await get(d, id)).status.energy;
    assert.equal(e.disturbance, e0.disturbance);
    assert.ok(Math.abs(e.kinetic + e.potential + e.dissipated - e.input - e.residual) <= 1e-9 * e.input);
    assert.ok(Math.abs(e.residual) <= 1e-3 * e.input, JSON.stringify(e));

    // out of the settings table's range: 422 out-of-range with the range
    const bad = [
      [{ m_n: 200 }, 'm_n', 1e-4, 100],
      [{ m_n: 0 }, 'm_n', 1e-4, 100],
      [{ mu: 2.5 }, 'mu', 0, 2],
      [{ mu: -0.1 }, 'mu', 0, 2],
      // within the table but past the mass the session's dem corrector
      // couples (0.2 of the machine's 166 kg over 1 x 2 elements)
      [{ m_n: 20 }, 'm_n', 1e-4, 0.2 * (120 + 10 + 18 + 18) / (1 * 2)],
      // all or nothing: a good beta with a bad mu changes neither
      [{ beta: 50, mu: 3 }, 'mu', 0, 2],
    ];
    for (const [body, field, min, max] of bad) {
      const r = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, body);
      assert.equal(r.status, 422, JSON.stringify(body));
      assert.match(r.headers.get('content-type'), /^application\/problem\+json/);
      assert.match(r.body.type, /\/out-of-range$/);
      assert.equal(r.body.field, field, JSON.stringify(r.body));
      assert.equal(r.body.min, min, JSON.stringify(r.body));
      assert.equal(r.body.max, max, JSON.stringify(r.body));
    }
    const t = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { m_n: 'heavy' });
    assert.equal(t.status, 400);
    assert.equal(t.body.field, 'm_n');
    st = (await get(d, id)).status;
    assert.equal(st.m_n, 0.75, 'nothing changed');
    assert.equal(st.mu, 0.6);
    assert.equal(st.beta_target, 40);

    // heavier elements than its contacts hold: on k_c = 5000 N/m a column
    // of 2 layers rests 3 m_n g / k_c deep, 5 cm at m_n = 0.05 x 5000 /
    // (3 x 9.81) = 8.49473 kg (below the corrector's 16.6): 10 kg is refused
    // with that as max, 8 kg applied
    const soft = await req(d.base, 'POST', '/api/v1/sessions',
      { ...CHEAP, pace: 1, params: { ...(CHEAP.params || {}), k_c: 5000 } });
    assert.equal(soft.status, 201, soft.text);
    const heavy = await req(d.base, 'PATCH', `/api/v1/sessions/${soft.body.id}`, { m_n: 10 });
    assert.equal(heavy.status, 422, heavy.text);
    assert.equal(heavy.body.field, 'm_n');
    assert.ok(Math.abs(heavy.body.max - 8.49473) < 1e-5, String(heavy.body.max));
    assert.match(heavy.body.detail, /^m_n must be below 8\.49473 kg in this session; got 10: its column of 2 layers would rest 5 cm or more into the deck on k_c = 5000/);
    assert.equal((await get(d, soft.body.id)).status.m_n, 0.5, 'nothing changed');
    const ok = await req(d.base, 'PATCH', `/api/v1/sessions/${soft.body.id}`, { m_n: 8 });
    assert.equal(ok.status, 200, ok.text);

    // a session without a feed has none to disturb
    const n = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1 });
    assert.equal(n.status, 201);
    for (const field of ['m_n', 'mu']) {
      const r = await req(d.base, 'PATCH', `/api/v1/sessions/${n.body.id}`, { [field]: 0.6 });
      assert.equal(r.status, 422);
      assert.match(r.body.type, /\/invalid-value$/);
      assert.equal(r.body.field, field);
      assert.match(r.body.detail, /has no feed/);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

for (const [name, stop, interval] of [['from its checkpoint after a stop', 'SIGTERM', 0.5],
  ['from the control log after kill -9 before a checkpoint', 'SIGKILL', 3600]]) {
  test(`m_n and mu survive a restart: ${name}`, { timeout: 90000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsimd-disturb-'));
    const args = ['--data-dir', dir, '--checkpoint-interval', String(interval)];
    let d = await startDaemon(args);
    let id, tEff;
    try {
      id = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 })).body.id;
      await sleep(300);
      const p = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { m_n: 0.3, mu: 0.7 });
      assert.equal(p.status, 200, p.text);
      tEff = p.body.t_effective;
      await sleep(interval < 1 ? 1200 : 100);
    } finally {
      await d.stop(stop);
    }
    const log = readFileSync(join(dir, 'sessions', id, 'controls.ndjson'), 'utf8').trim().split('\n').map((l) => JSON.parse(l));
    assert.deepEqual(log.map((c) => [c.m_n, c.mu, c.t_effective]), [[0.3, 0.7, tEff]]);
    d = await startDaemon(args);
    try {
      const g = await until(async () => {
        const b = await get(d, id);
        return b.status && b.status.t > tEff + 0.1 && b;
      }, 20000 * SLOW, 'the session past the control');
      assert.equal(g.status.m_n, 0.3);
      assert.equal(g.status.mu, 0.7);
      assert.equal(g.spec ? g.spec.params.m_n : 0.5, 0.5, 'the spec keeps the start\'s value');
    } finally {
      assert.equal((await d.stop()).code, 0, d.stderr());
      rmSync(dir, { recursive: true, force: true });
    }
  });
}
