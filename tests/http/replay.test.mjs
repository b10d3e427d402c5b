// No acknowledged control is lost to a crash: the controls logged after
// the checkpoint a session is restored from (all of them when it had none
// yet) are applied again as its integrator reaches each one's
// t_effective, and the control log goes on from where it was
// (docs/hardening.md).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, sleep, CHEAP, SLOW } from './lib.mjs';

const get = async (d, id) => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;

for (const [name, interval, wait] of [['without a checkpoint yet', 3600, 0], ['after its last checkpoint', 1.5, 2.5]]) {
  test(`controls acknowledged ${name} are taken again after kill -9`, { timeout: 90000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsimd-replay-'));
    const args = ['--data-dir', dir, '--checkpoint-interval', String(interval)];
    let d = await startDaemon(args);
    let run, held, tEff;
    try {
      run = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 })).body.id;
      held = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 })).body.id;
      await sleep(wait * 1000);
      if (wait) {
        const ck = join(dir, 'sessions', run, 'checkpoint.bin');
        await until(async () => { try { return readFileSync(ck).length > 0; } catch { return false; } }, 5000, 'a checkpoint');
      }
      const p = await req(d.base, 'PATCH', `/api/v1/sessions/${run}`, { beta: 60, rotation: 'ccw' });
      assert.equal(p.status, 200, p.text);
      tEff = p.body.t_effective;
      assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${held}`, { running: false })).status, 200);
      assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${held}`, { beta: 25 })).status, 200);
      await sleep(100); // the control log is written; the next checkpoint is not due
    } finally {
      await d.stop('SIGKILL');
    }
    d = await startDaemon(args);
    try {
      const g = await until(async () => {
        const b = await get(d, run);
        return b.status.t > tEff + 0.1 && b;
      }, 20000, 'the session past the control');
      assert.equal(g.status.beta_target, 60, 'beta taken again');
      assert.equal(g.status.rotation, 'ccw', 'rotation taken again');
      const h = await get(d, held);
      assert.equal(h.state, 'paused', 'the pause taken again');
      assert.equal(h.status.beta_target, 25);
      // the log goes on: one more control, and all of them are in it
      assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${run}`, { beta: 70 })).status, 200);
      await sleep(300);
      const log = readFileSync(join(dir, 'sessions', run, 'controls.ndjson'), 'utf8').trim().split('\n').map((l) => JSON.parse(l));
      assert.deepEqual(log.map((c) => c.beta), [60, 70], 'the log keeps what came before the restart, once');
    } finally {
      assert.equal((await d.stop()).code, 0, d.stderr());
      rmSync(dir, { recursive: true, force: true });
    }
  });
}
