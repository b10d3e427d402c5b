// SPDX-License-Identifier: GPL-3.0-or-later
// No acknowledged control is lost to a crash: the controls logged after
// the checkpoint a session is restored from (all of them when it had none
// yet) are applied again as its integrator reaches each one's
// t_effective, and the control log goes on from where it was
// (docs/hardening.md).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, untilReplayed, sleep, reframe, STORE_FRAME, CHEAP, SLOW } from './lib.mjs';

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

// this build's checkpoint head (srv_ckpt_record, exp_len at 304); the
// core's version follows its 8-byte magic (core/checkpoint.c).
const FRAME = STORE_FRAME;
const CKPT_RECORD = 320;

test('a checkpoint of another core version: re-created from its spec, its controls replayed to where it was', { timeout: 90000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-rebuild-'));
  const args = ['--data-dir', dir, '--checkpoint-interval', '0.5'];
  let d = await startDaemon(args);
  let id, before;
  try {
    id = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 })).body.id;
    await sleep(400);
    assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 60 })).status, 200);
    await sleep(400);
    assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { rotation: 'ccw', beta_rate: 45 })).status, 200);
    await sleep(800);
    before = (await get(d, id)).status.t;
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  for (const f of ['checkpoint.bin', 'checkpoint.bin.prev']) {
    const path = join(dir, 'sessions', id, f);
    const b = readFileSync(path);
    const expLen = Number(b.readBigUInt64LE(FRAME + 304));
    const at = FRAME + CKPT_RECORD + expLen + 8;
    b.writeUInt32LE(b.readUInt32LE(at) + 1, at); // another build's core
    writeFileSync(path, reframe(b));
  }
  d = await startDaemon(args);
  try {
    const g = await untilReplayed(d.base, id);
    assert.equal(g.state, 'running', JSON.stringify(g));
    assert.equal(g.restored, 'replayed');
    assert.ok(g.replay_seconds >= 0 && g.replay_seconds < 10, `replay took ${g.replay_seconds} s`);
    assert.ok(g.status.t >= before, `at its time again: ${g.status.t} >= ${before}`);
    assert.ok(g.status.t < before + 2, `and then at its pace: ${g.status.t}`);
    assert.equal(g.status.beta_target, 60);
    assert.equal(g.status.rotation, 'ccw');
    assert.match(d.stderr(), new RegExp(`session ${id}: .*unknown version.*re-created from its spec, 2 controls replayed`));
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});

test('the spec is read from spec.json, the API\'s JSON: a spec.bin of another layout does not matter', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-specjson-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  let id;
  try {
    id = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1, params: { beta: 45, k_s1: 400000 }, sample_rate: 100 })).body.id;
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  const spec = JSON.parse(readFileSync(join(dir, 'sessions', id, 'spec.json'), 'utf8'));
  assert.equal(spec.session.params.beta, 45);
  assert.equal(spec.session.params.k_s1, 400000);
  assert.equal(spec.session.sample_rate, 100);
  writeFileSync(join(dir, 'sessions', id, 'spec.bin'), Buffer.alloc(700, 1)); // another build's record
  d = await startDaemon(args);
  try {
    const g = await get(d, id);
    assert.equal(g.state, 'running', JSON.stringify(g.error));
    const full = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;
    assert.equal(full.spec.params.k_s1, 400000);
    assert.equal(full.sample_rate, 100);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
