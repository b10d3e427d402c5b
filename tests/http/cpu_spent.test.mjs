// SPDX-License-Identifier: GPL-3.0-or-later
// The CPU a session spent against its grant survives a restart
// (docs/budgets.md "CPU"): after a SIGTERM or a kill -9 its count goes on
// from its last checkpoint, not from 0, its cpu_limit is the one it had,
// and its budget pauses it once the rest of the grant is spent, not a
// whole new grant later. A session paused by its client checkpoints its
// count exactly; one running when the daemon stops loses nothing to a
// SIGTERM and to a kill -9 what it spent since the checkpoint on disk
// (read from the file after the kill, so that a writer behind on a busy
// disk does not decide the test). The daemon's own CPU after the restart
// (/proc) tells apart a build that restores the figures but spends a
// whole grant again.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, getReady, near, sleep, processCpu, CHEAP, SLOW } from './lib.mjs';

const MAX = 300;  // --max-cpu-seconds
const SPEND = 1;  // CPU s each session spends before its grant
const GRANT = 4;  // CPU s of the grant (cpu_budget)
const INTO = 2;   // CPU s of the grant spent before the restart


// What the checkpoint on disk of session id kept of its CPU budget: its
// frame's format (null: no file) and, in format 3, the trailer
// (server/store/records.h srv_ckpt_trailer, its last 40 bytes: the log's
// length, t, the count, the limit, paused); NaN in another format.
const kept = (dir, id) => {
  let b;
  try {
    b = readFileSync(join(dir, 'sessions', id, 'checkpoint.bin'));
  } catch {
    return { format: null, cpu: NaN, limit: NaN, paused: NaN };
  }
  const format = b.readUInt32LE(4);
  if (format !== 3 || b.length < 72)
    return { format, cpu: NaN, limit: NaN, paused: NaN };
  const at = b.length - 40;
  return { format, cpu: b.readDoubleLE(at + 16), limit: b.readDoubleLE(at + 24), paused: b.readInt32LE(at + 32) };
};
// Wait (up to 10 s, then go on) for the checkpoint on disk to say ok; a
// build that writes another format: its first checkpoint.
const onDisk = (dir, id, ok) => until(async () => {
  const k = kept(dir, id);
  return k.format !== null && (k.format !== 3 || ok(k));
}, 10000, 'a checkpoint').catch(() => {});

const at = (id) => `/api/v1/sessions/${id}`;
const get = async (d, id) => (await getReady(d.base, at(id))).body;

for (const [signal, interval] of [['SIGTERM', '3600'], ['SIGKILL', '0.2']]) {
  test(`${signal}: the CPU spent against the grant is still spent after the restart`, { timeout: 120000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsimd-spent-'));
    const args = ['--data-dir', dir, '--max-cpu-seconds', String(MAX), '--checkpoint-interval', interval];
    let d = await startDaemon(args);
    try {
      // paused: paused by its client after INTO of its grant; running:
      // running when the daemon stops
      const ids = {};
      for (const name of ['paused', 'running']) {
        const r = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 1e6 });
        assert.equal(r.status, 201, r.text);
        ids[name] = r.body.id;
      }
      const limit = {};
      for (const [name, id] of Object.entries(ids)) {
        await until(async () => (await get(d, id)).cpu_seconds >= SPEND, 30000, `${name} to spend ${SPEND} CPU s`);
        const r = await req(d.base, 'PATCH', at(id), { cpu_budget: GRANT });
        assert.equal(r.status, 200, r.text);
        limit[name] = r.body.cpu_limit;
        assert.ok(limit[name] >= SPEND + GRANT, `${name}: cpu_limit ${limit[name]}, the grant from what it spent`);
      }
      for (const [name, id] of Object.entries(ids))
        await until(async () => (await get(d, id)).cpu_seconds >= limit[name] - GRANT + INTO, 30000, `${name} to spend ${INTO} CPU s of its grant`);
      let r = await req(d.base, 'PATCH', at(ids.paused), { running: false });
      assert.equal(r.status, 200, r.text);
      await sleep(300); // its worker reads its CPU where it stops
      const spentPaused = (await get(d, ids.paused)).cpu_seconds;
      await onDisk(dir, ids.paused, (k) => k.cpu >= spentPaused);
      await sleep(500); // checkpoints of the running one (SIGKILL's interval is 0.2 s)
      const spentRunning = (await get(d, ids.running)).cpu_seconds;
      assert.ok(spentPaused < limit.paused, 'paused: its grant not spent before the restart');
      await d.stop(signal);
      const kp = kept(dir, ids.paused), kr = kept(dir, ids.running);

      d = await startDaemon(args);
      const cpuAtStart = processCpu(d.proc.pid);
      const p = await get(d, ids.paused);
      assert.equal(p.state, 'paused');
      assert.equal(p.pause_reason, 'client');
      assert.ok(p.cpu_seconds >= spentPaused, `paused: cpu_seconds ${p.cpu_seconds}, it had spent ${spentPaused}`);
      near(p.cpu_seconds, spentPaused, 0.1, 'paused: cpu_seconds after the restart');
      near(p.cpu_limit, limit.paused, 1e-6, 'paused: cpu_limit after the restart');
      // on disk: the paused one's count where it stopped; the running
      // one's at its last checkpoint, all of it after a SIGTERM
      near(kp.cpu, spentPaused, 0.05, 'paused: the count its checkpoint kept');
      near(kp.limit, limit.paused, 1e-6, 'paused: the limit its checkpoint kept');
      assert.ok(kr.cpu >= (signal === 'SIGTERM' ? spentRunning : limit.running - GRANT),
        `running: its checkpoint kept a count of ${kr.cpu} (it had spent ${spentRunning} before the ${signal})`);
      const g = await get(d, ids.running);
      assert.ok(g.cpu_seconds >= kr.cpu, `running: cpu_seconds ${g.cpu_seconds}, its checkpoint's count ${kr.cpu}`);
      near(g.cpu_limit, limit.running, 1e-6, 'running: cpu_limit after the restart');

      // the rest of the grant, not a new one: each pauses at its old limit
      r = await req(d.base, 'PATCH', at(ids.paused), { running: true });
      assert.equal(r.status, 200, r.text);
      near(r.body.cpu_limit, limit.paused, 1e-6, 'paused: cpu_limit resumed by its client (no grant)');
      for (const [name, id] of Object.entries(ids))
        await until(async () => (await get(d, id)).pause_reason === 'cpu-budget', 60000, `${name}'s budget to pause it`);
      const left = (limit.paused - kp.cpu) + (limit.running - kr.cpu);
      const spentAfter = processCpu(d.proc.pid) - cpuAtStart;
      assert.ok(spentAfter < left + 1, `the daemon spent ${spentAfter} CPU s after the restart; what was left of the grants: ${left} s (a new grant each: ${2 * GRANT} s)`);
      for (const [name, id] of Object.entries(ids)) {
        const s = await get(d, id);
        near(s.cpu_limit, limit[name], 1e-6, `${name}: cpu_limit where its budget paused it`);
        assert.ok(s.cpu_seconds >= s.cpu_limit && s.cpu_seconds < s.cpu_limit + 0.5,
          `${name}: paused at cpu_seconds ${s.cpu_seconds}, its limit ${s.cpu_limit}`);
      }
    } finally {
      assert.equal((await d.stop()).code, 0, d.stderr());
    }
  });
}

// A running: true acknowledged after the checkpoint of a session its budget
// paused is replayed with its grant: --max-cpu-seconds from the count it
// had, not the spent grant again (with no checkpoint in between: the
// interval is an hour, the last one written where the budget paused it).
test('SIGKILL: a running: true logged after the checkpoint grants again when replayed', { timeout: 90000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-spent-'));
  const args = ['--data-dir', dir, '--max-cpu-seconds', String(MAX), '--checkpoint-interval', '3600'];
  let d = await startDaemon(args);
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 1e6 });
    assert.equal(c.status, 201, c.text);
    const id = c.body.id;
    await until(async () => (await get(d, id)).cpu_seconds >= SPEND, 30000, `spending ${SPEND} CPU s`);
    let r = await req(d.base, 'PATCH', at(id), { cpu_budget: 0.05 });
    assert.equal(r.status, 200, r.text);
    await until(async () => (await get(d, id)).pause_reason === 'cpu-budget', 30000, 'the budget to pause it');
    await sleep(300); // its worker reads its CPU where it stops
    const spent = (await get(d, id)).cpu_seconds;
    assert.ok(spent >= SPEND, `cpu_seconds ${spent}`);
    await onDisk(dir, id, (k) => k.paused === 1); // its checkpoint where it stopped
    r = await req(d.base, 'PATCH', at(id), { running: true });
    assert.equal(r.status, 200, r.text);
    near(r.body.cpu_limit, spent + MAX, 0.1, 'cpu_limit resumed');
    await d.stop('SIGKILL');
    const k = kept(dir, id);

    d = await startDaemon(args);
    const s = await get(d, id);
    assert.equal(s.state, 'running', JSON.stringify(s));
    assert.equal(s.pause_reason, null);
    assert.ok(s.cpu_seconds >= spent, `cpu_seconds ${s.cpu_seconds}, it had spent ${spent}`);
    near(s.cpu_limit, spent + MAX, 0.1, 'cpu_limit after the replayed running: true');
    near(k.cpu, spent, 0.05, 'the count its checkpoint kept');
    assert.equal(k.paused, 1, 'its checkpoint: paused by its budget');
    await sleep(500);
    assert.equal((await get(d, id)).state, 'running', 'still running on its new grant');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
