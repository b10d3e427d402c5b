// SPDX-License-Identifier: GPL-3.0-or-later
// A steady start's settling runs in the creating request's thread, so a
// creation whose settling is estimated beyond --max-cpu-seconds is refused
// before it settles (docs/hardening.md "The cores for paced sessions"); one
// admitted is stopped at the bound (settle_stop.test.mjs), so the estimate
// has to be near what the
// settling costs for every scene size (docs/load.md "What settling
// costs"). A 64 x 64 scene settles for about a CPU second; the estimate
// that counted a light column's work said 0.024 CPU s, so --max-cpu-seconds
// 0.2 admitted it and it settled for five times the bound.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, metric, postRefusedCpu, SLOW } from './lib.mjs';

const LARGE = { scene: { columns: 64, layers: 64 }, pace: 0.01, sample_rate: 1 };
const BOUND = 0.2;
// the estimate for the 64 x 64 scene (server/admit/budget_cost.c): CPU s of
// its settling, per simulated s of it, and the longest scene.settle that
// fits the bound
const SETTLE_CPU = 0.579, PER_S = 0.966, MAX = 0.20714239765039225;

const refusal = {
  type: '/api/v1/problems/out-of-range',
  title: 'Value out of range',
  status: 422,
  detail: `the steady start would settle for about ${SETTLE_CPU} CPU s (${PER_S} CPU s per simulated s ` +
    `over scene.settle = 0.6 s), more than --max-cpu-seconds (${BOUND}); nothing was created: a larger ` +
    'integrator.dt, a smaller scene, a shorter scene.settle or scene.start "rest"',
  instance: '/api/v1/sessions',
  field: 'scene.settle',
  budget: 'cpu',
  limit: BOUND,
  min: 0,
  max: MAX,
};

test('a 64 x 64 scene is refused under --max-cpu-seconds 0.2 before it settles; scenes that fit are created', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-settle-bound-'));
  const d = await startDaemon(['--max-cpu-seconds', String(BOUND), '--data-dir', dir]);
  const metrics = async () => (await req(d.base, 'GET', '/metrics')).text;
  try {
    const { r, cpu } = await postRefusedCpu(d, '/api/v1/sessions', LARGE);
    assert.deepEqual(r.body, refusal);
    assert.ok(Math.abs(MAX * SETTLE_CPU / 0.6 - BOUND) < 1e-3 * BOUND, 'max is the settle that fits');
    // refused before anything settled (a settling of it takes about a CPU second)
    assert.ok(cpu < 0.2 * SLOW, `the daemon spent ${cpu} CPU s over the request`);
    // nothing was created or held: not listed, no directory, no memory, no settling slot taken
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
    assert.deepEqual(readdirSync(join(dir, 'sessions')), []);
    const m = await metrics();
    assert.equal(metric(m, 'convsim_sessions_created_total'), 0);
    assert.equal(metric(m, 'convsim_memory_reserved_bytes'), 0);
    assert.equal(metric(m, 'convsim_settling_max'), 0);
    // the longest settling it names is not refused before it settles: it
    // is created, or stopped at the bound where it costs more than its
    // estimate (this one settles for about 1.7 times it here), naming a
    // shorter scene.settle; a little longer is refused at once
    const at = async (settle) => req(d.base, 'POST', '/api/v1/sessions',
      { ...LARGE, scene: { ...LARGE.scene, settle } });
    const fits = await at(Math.floor(MAX * 1000) / 1000);
    if (fits.status === 201) {
      assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${fits.body.id}`)).status, 204);
    } else {
      assert.equal(fits.status, 422, fits.text);
      assert.match(fits.body.detail, /^the steady start's settling stopped at /, fits.text);
      assert.ok(fits.body.field === 'scene.settle' && fits.body.max < MAX, fits.text);
    }
    const t1 = performance.now();
    const over = await at(Math.ceil(MAX * 1000) / 1000);
    assert.equal(over.status, 422, over.text);
    assert.equal(over.body.field, 'scene.settle', over.text);
    assert.match(over.body.detail, /^the steady start would settle for about /, over.text);
    assert.ok(performance.now() - t1 < 300 * SLOW, 'refused before it settled');
    // scenes whose settling fits the bound are created: the default, 8 x 8
    // and 8 x 64 (about 0.03 CPU s; its feed is heavier than the machine).
    // The estimate is the release build's: a sanitized build (SLOW > 1),
    // several times dearer, may be stopped at the bound instead, never
    // refused before it settles
    let created = fits.status === 201 ? 1 : 0;
    for (const scene of [{}, { columns: 8, layers: 8 }, { columns: 8, layers: 64 }]) {
      const ok = await req(d.base, 'POST', '/api/v1/sessions', { scene, pace: 0.01, sample_rate: 1 });
      if (ok.status === 201) {
        created++;
        continue;
      }
      assert.ok(SLOW > 1, `${JSON.stringify(scene)}: ${ok.text}`);
      assert.equal(ok.status, 422, ok.text);
      assert.match(ok.body.detail, /^the steady start's settling stopped at /, ok.text);
    }
    assert.ok(created >= (SLOW > 1 ? 0 : 3), `created ${created}`);
    assert.equal(metric(await metrics(), 'convsim_sessions_created_total'), created);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
