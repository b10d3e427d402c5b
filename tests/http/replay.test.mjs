// SPDX-License-Identifier: GPL-3.0-or-later
// No acknowledged control is lost to a crash: the controls logged after
// the checkpoint a session is restored from (all of them when it had none
// yet) are applied again as its integrator reaches each one's
// t_effective, and the control log goes on from where it was
// (docs/durability.md).
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

test('a session replayed from its spec answers 503 until it is back where it was: no GET shows the past', { timeout: 120000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-replay-visible-'));
  const args = ['--data-dir', dir, '--checkpoint-interval', '0.2'];
  let d = await startDaemon(args);
  let id, seen;
  try {
    id = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 20 })).body.id;
    await until(async () => (await get(d, id)).state === 'finished', 30000, 'finished at 20 s');
    assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 130, until: 80 })).status, 200);
    seen = await until(async () => { const b = await get(d, id); return b.state === 'finished' && b; }, 60000, 'finished at 80 s');
    assert.equal(seen.status.t, 80);
    assert.equal(seen.status.beta_target, 130);
    await sleep(500); // its last checkpoint written
  } finally {
    await d.stop('SIGKILL');
  }
  for (const f of ['checkpoint.bin', 'checkpoint.bin.prev']) { // another build's core
    const path = join(dir, 'sessions', id, f);
    const b = readFileSync(path);
    const at = FRAME + CKPT_RECORD + Number(b.readBigUInt64LE(FRAME + 304)) + 8;
    b.writeUInt32LE(b.readUInt32LE(at) + 1, at);
    writeFileSync(path, reframe(b));
  }
  d = await startDaemon(args);
  try {
    // from the first moment: every answer is the present or a 503
    let refused = 0, answered = 0;
    for (;;) {
      const r = await req(d.base, 'GET', `/api/v1/sessions/${id}`);
      if (r.status === 503) {
        refused++;
        assert.equal(r.body.type, '/api/v1/problems/unavailable');
        assert.match(r.body.detail, /replaying its control log/);
        assert.ok(Number(r.headers.get('retry-after')) >= 1, 'Retry-After');
        const l = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.find((s) => s.id === id);
        assert.ok(l.status === null || l.status.t >= 80, `the listing shows t ${l.status && l.status.t}`);
        continue;
      }
      assert.equal(r.status, 200, r.text);
      answered++;
      assert.equal(r.body.status.t, 80, 'where the client left it');
      assert.equal(r.body.status.beta_target, 130);
      assert.equal(r.body.state, 'finished');
      assert.equal(r.body.restored, 'replayed');
      if (answered >= 3) break;
    }
    console.log(`${refused} GETs answered 503 during the replay`);
    assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { until: 81 })).status, 200);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
