// SPDX-License-Identifier: GPL-3.0-or-later
// State on disk (--data-dir, docs/operations.md "Persistence"): a daemon with 10
// sessions receiving controls, one experiment and one sweep is killed with
// SIGKILL at random moments and restarted on the same directory; nothing
// acknowledged more than one checkpoint interval before the kill may be
// lost, finished results are served byte for byte, a cut-off checkpoint
// falls back to the previous one, an unreadable spec lists its session as
// damaged, checkpoints of another version are replayed from the spec. A full file system (a tiny tmpfs in a private mount namespace)
// puts sessions, sweeps and experiments in state "error".
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync, truncateSync, writeFileSync, statSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, untilReplayed, getReady, sleep, CHEAP, NO_FEED, SLOW, BIN, WEB_ROOT } from './lib.mjs';

const INTERVAL = 0.5;            // --checkpoint-interval, s
const MARGIN = 0.8 * SLOW;       // s: scheduling slack on top of it (shared CI cores)
const ROUNDS = 5;

// seeded, so that a failure can be replayed (CONVSIM_CRASH_SEED)
let seed = Number(process.env.CONVSIM_CRASH_SEED || Date.now() % 100000);
const rand = () => ((seed = (seed * 16807) % 2147483647) / 2147483647);

test('SIGKILL at random moments loses nothing beyond one checkpoint interval', { timeout: 180000 * SLOW }, async () => {
  console.log(`# crash seed ${seed}`);
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-crash-'));
  const args = ['--data-dir', dir, '--checkpoint-interval', String(INTERVAL)];
  let d = await startDaemon(args);
  try {
    const ids = [];
    for (let i = 0; i < 10; i++) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', CHEAP);
      assert.equal(r.status, 201, r.text);
      ids.push(r.body.id);
    }
    const ex = await req(d.base, 'POST', '/api/v1/experiments', {
      session: { ...CHEAP, pace: 1 },
      schedule: [{ beta: 40, until: 3 }, { beta: 120, until: 600 }],
    });
    assert.equal(ex.status, 201, ex.text);
    const sw = await req(d.base, 'POST', '/api/v1/sweeps', {
      ...CHEAP, beta: { from: 0, to: 180, step: 5 }, rotations: ['cw', 'ccw'], t_end: 2,
    });
    assert.equal(sw.status, 202, sw.text);
    let finished = null; // a finished result, served again byte for byte
    let counter = 0;
    for (let round = 0; round < ROUNDS; round++) {
      const acked = []; // {id, beta, t, wall}
      const seen = [];  // {wall, exp t_now, sweep done}
      const cut = {};   // id -> the beta whose answer the kill cut off: in the log or not
      let stop = false;
      const controls = (async () => {
        while (!stop) {
          const id = ids[Math.floor(rand() * ids.length)];
          const beta = 10 + (counter++ % 1600) / 10;
          cut[id] = beta;
          const r = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta });
          delete cut[id];
          if (r.status === 200) acked.push({ id, beta, t: r.body.t_effective, wall: Date.now() / 1000 });
          await sleep(10);
        }
      })();
      const watch = (async () => {
        while (!stop) {
          const e = await req(d.base, 'GET', `/api/v1/experiments/${ex.body.id}`);
          const s = await req(d.base, 'GET', `/api/v1/sweeps/${sw.body.id}`);
          seen.push({ wall: Date.now() / 1000, t: e.body.t, done: s.body.done });
          await sleep(50);
        }
      })();
      await sleep((0.8 + 1.2 * rand()) * 1000 * SLOW);
      const kill = Date.now() / 1000;
      d.proc.kill('SIGKILL');
      stop = true;
      await Promise.allSettled([controls, watch, d.exited]);
      if (round === 2) {
        // a checkpoint cut off mid-write: the previous one serves
        const f = join(dir, 'sessions', ids[0], 'checkpoint.bin');
        truncateSync(f, Math.floor(statSync(f).size / 2));
      }
      d = await startDaemon(args);
      const limit = kill - INTERVAL - MARGIN - (round === 2 ? INTERVAL : 0);
      const list = await req(d.base, 'GET', '/api/v1/sessions');
      const byId = new Map(list.body.sessions.map((s) => [s.id, s]));
      for (const id of ids) {
        const s = (await getReady(d.base, `/api/v1/sessions/${id}`)).body;
        assert.ok(s && byId.has(id), `round ${round}: session ${id} lost`);
        assert.equal(s.state, 'running', `round ${round}: ${id} ${s.error}`);
        const mine = acked.filter((a) => a.id === id);
        const old = mine.filter((a) => a.wall < limit);
        if (!old.length) continue;
        // the restored controls are those of a control at least as recent
        // as the last one acknowledged before the window
        const last = old[old.length - 1];
        if (!(s.status.t >= last.t)) {
          assert.fail(`round ${round}: ${id} at t = ${s.status.t} before a control at ${last.t} ` +
            `acked ${(kill - last.wall).toFixed(3)} s before the kill; ${d.stderr()}`);
        }
        const allowed = [...mine.slice(mine.indexOf(last)).map((a) => a.beta), ...(id in cut ? [cut[id]] : [])];
        assert.ok(allowed.some((b) => Math.abs(b - s.status.beta_target) < 1e-9),
          `round ${round}: ${id} beta_target ${s.status.beta_target} not among ${allowed}`);
      }
      const e = (await req(d.base, 'GET', `/api/v1/experiments/${ex.body.id}`)).body;
      assert.ok(e, `round ${round}: experiment lost`);
      assert.equal(e.state, 'running', `round ${round}: experiment ${e.state} ${e.error}`);
      const s = (await req(d.base, 'GET', `/api/v1/sweeps/${sw.body.id}`)).body;
      assert.ok(s, `round ${round}: sweep lost`);
      const before = seen.filter((x) => x.wall < limit);
      if (before.length) {
        const b = before[before.length - 1];
        assert.ok(e.t >= b.t, `round ${round}: experiment went back from ${b.t} to ${e.t}`);
        assert.ok(s.done >= b.done, `round ${round}: sweep went back from ${b.done} to ${s.done} points`);
      }
      const es = (await getReady(d.base, `/api/v1/sessions/${e.session}`)).body;
      assert.equal(es.experiment, ex.body.id, `round ${round}: the experiment runs on its session again`);
      if (finished) {
        const again = await req(d.base, 'GET', `/api/v1/sweeps/${finished.id}`);
        assert.equal(again.text, finished.text, 'a finished sweep is served byte for byte');
      } else if (s.state === 'done') {
        finished = { id: s.id, text: (await req(d.base, 'GET', `/api/v1/sweeps/${s.id}`)).text };
      }
    }
    // an unreadable spec: the session is listed as damaged, the daemon runs
    d.proc.kill('SIGKILL');
    await d.exited;
    // (spec.json, this build's, gone: the spec.bin an earlier build reads)
    rmSync(join(dir, 'sessions', ids[1], 'spec.json'));
    writeFileSync(join(dir, 'sessions', ids[1], 'spec.bin'), 'not a spec');
    const v = readFileSync(join(dir, 'sessions', ids[2], 'checkpoint.bin'));
    v[4] ^= 0x7f; // the version field of both checkpoints
    writeFileSync(join(dir, 'sessions', ids[2], 'checkpoint.bin'), v);
    writeFileSync(join(dir, 'sessions', ids[2], 'checkpoint.bin.prev'), v);
    d = await startDaemon(args);
    const dm = (await req(d.base, 'GET', `/api/v1/sessions/${ids[1]}`)).body;
    assert.equal(dm.state, 'damaged');
    assert.match(dm.error, /spec\.bin/);
    // both checkpoints of another version: re-created from its spec, its
    // controls replayed (replay.test.mjs), not damaged
    const dv = await untilReplayed(d.base, ids[2]);
    assert.equal(dv.state, 'running');
    assert.equal(dv.restored, 'replayed');
    assert.match(d.stderr(), new RegExp(`session ${ids[2]}: .*version.*re-created from its spec`));
    assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${ids[1]}`, { beta: 30 })).status, 409);
    assert.equal((await getReady(d.base, `/api/v1/sessions/${ids[3]}`)).body.state, 'running');
    // DELETE removes the files too
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${ids[1]}`)).status, 204);
    await until(() => !existsSync(join(dir, 'sessions', ids[1])), 3000, 'the files to go');
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
});

test('a restart after SIGTERM continues every session exactly where it stopped', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-term-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  try {
    const a = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 0.5 });
    const b = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 1.0 });
    await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body.state === 'finished', 20000, 'a');
    await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${b.body.id}`)).body.state === 'finished', 20000, 'b');
    const before = (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body;
    assert.equal((await d.stop()).code, 0);
    d = await startDaemon(args);
    const after = (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body;
    assert.equal(after.state, 'finished');
    assert.deepEqual(after.status, before.status, 'the status is restored bit for bit');
    // run the restored one on to 1.0 s: the same state as one never interrupted
    await req(d.base, 'PATCH', `/api/v1/sessions/${a.body.id}`, { until: 1.0 });
    await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body.state === 'finished', 20000, 'a again');
    const ra = (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body.status;
    const rb = (await req(d.base, 'GET', `/api/v1/sessions/${b.body.id}`)).body.status;
    for (const k of ['t', 'q', 'qd', 'feed_displacement', 'transport_velocity', 'e_input', 'steps'])
      assert.deepEqual(ra[k], rb[k], `${k} after the restart equals the uninterrupted run's`);
  } finally {
    await d.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});

// A private mount namespace with a full tmpfs as the data directory.
function fullDisk() {
  const probe = spawnSync('unshare', ['-m', 'sh', '-c', 'd=$(mktemp -d) && mount -t tmpfs -o size=64k tmpfs "$d" && umount "$d"; rmdir "$d"'], { encoding: 'utf8' });
  return probe.status === 0;
}

test('write errors (ENOSPC) put sessions, sweeps, experiments and fits in state "error"', { timeout: 60000 * SLOW, skip: !fullDisk() && 'unshare -m with a tmpfs is not possible here (needs root or user namespaces)' }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-full-'));
  // the daemon sees a tmpfs of 64 kB at dir, filled up but for its
  // directories; mount and daemon live in their own mount namespace
  const script = `mount -t tmpfs -o size=64k tmpfs "${dir}" && mkdir "${dir}/sessions" "${dir}/experiments" "${dir}/sweeps" && ` +
    `(dd if=/dev/zero of="${dir}/filler" bs=4k 2>/dev/null; true) && exec "${BIN}" "$@"`;
  const d = await startDaemon.call(null, [], { wrap: ['unshare', '-m', 'sh', '-c', script, 'sh'], tail: ['--data-dir', dir, '--checkpoint-interval', '0.2'] });
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', CHEAP);
    assert.equal(s.status, 201);
    const got = await until(async () => {
      const g = (await req(d.base, 'GET', `/api/v1/sessions/${s.body.id}`)).body;
      return g.state === 'error' && g;
    }, 5000, 'the session in state error');
    assert.match(got.error, /No space left on device/);
    const sw = await req(d.base, 'POST', '/api/v1/sweeps', { ...NO_FEED, beta: [20], rotations: ['cw'], t_end: 0.1 });
    const swe = await until(async () => {
      const g = (await req(d.base, 'GET', `/api/v1/sweeps/${sw.body.id}`)).body;
      return g.state === 'error' && g;
    }, 10000, 'the sweep in state error');
    assert.match(swe.error, /No space left on device/);
    const ex = await req(d.base, 'POST', '/api/v1/experiments', { session: { ...NO_FEED }, schedule: [{ beta: 50, until: 0.2 }] });
    const exe = await until(async () => {
      const g = (await req(d.base, 'GET', `/api/v1/experiments/${ex.body.id}`)).body;
      return g.state === 'error' && g;
    }, 10000, 'the experiment in state error');
    assert.match(exe.error, /No space left on device/);
    // a fit whose record is not on disk is not "done": a restart would
    // not find it
    const fit = await req(d.base, 'POST', '/api/v1/fits', { ...CHEAP, t_end: 0.5, free: ['e'], curve_step: 90,
      points: [{ beta: 20, rotation: 'cw', v: 0.07 }, { beta: 60, rotation: 'cw', v: 0.06 }] });
    assert.equal(fit.status, 202, fit.text);
    const fe = await until(async () => {
      const g = (await req(d.base, 'GET', `/api/v1/fits/${fit.body.id}`)).body;
      return g.state === 'error' && g;
    }, 10000, 'the fit in state error');
    assert.match(fe.error, /fits\/[0-9a-f]+\.bin: No space left on device/);
    const listed = (await req(d.base, 'GET', '/api/v1/fits?format=csv')).text;
    assert.ok(listed.includes(`${fit.body.id},error,`), listed);
    const m = await fetch(`${d.base}/metrics`).then((r) => r.text());
    const errors = Number((m.match(/^convsim_store_errors_total (\S+)$/m) || [])[1]);
    assert.ok(errors >= 4, `convsim_store_errors_total ${errors}`);
    assert.match(d.stderr(), /store: cannot .*No space left on device/);
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
});
