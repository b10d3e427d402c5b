// SPDX-License-Identifier: GPL-3.0-or-later
// A restore continues bit for bit (docs/durability.md): a pace-max session
// with a control on the way and an experiment, each killed with SIGKILL
// three times while running and restored, end with the same status and
// the same CSV, byte for byte, as an uninterrupted run of the same
// requests. Before, the measured step error's shadow was not in the
// checkpoint (another transport_velocity_uncertainty), and an
// experiment's segment commands were applied twice after a restore (once
// replayed from the control log, once by the experiment), which moved
// the estimator's restart (another mean velocity, steady flag and
// reversal time).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, sleep, CHEAP, SLOW } from './lib.mjs';

const KILLS = 3;

// The session's document once it answers (503 while it replays) and
// satisfies ok.
const settled = (d, path, ok, ms = 60000) => until(async () => {
  const r = await req(d.base, 'GET', path);
  return r.status === 200 && ok(r.body) && r;
}, ms, `${path} settled`);

// Whether a session in the data directory dir has written a checkpoint.
const checkpointed = (dir) => {
  const sessions = join(dir, 'sessions');
  return existsSync(sessions) && readdirSync(sessions).some((id) => existsSync(join(sessions, id, 'checkpoint.bin')));
};

// Run the same requests uninterrupted (d, no data directory) and with
// KILLS kills at random moments while work runs; what each ends with.
async function bothWays(steps, interval = 0.05) {
  let d = await startDaemon([]);
  let ref;
  try {
    ref = await steps(d, async () => {});
  } finally {
    await d.stop();
  }
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-exact-'));
  const args = ['--data-dir', dir, '--checkpoint-interval', String(interval)];
  d = await startDaemon(args);
  let got, kills = 0;
  try {
    got = await steps(d, async (running) => {
      // while running: kill at a random moment after its first checkpoint
      // (none yet: the experiment runs again from its start, the test
      // below), start again on the directory
      while (kills < KILLS && await running(d)) {
        await sleep((interval * 1000 + 50 + Math.random() * 300) * SLOW);
        // not before the first checkpoint (on a loaded machine it can come
        // later than the sleep): without one the experiment is run again,
        // not resumed
        await until(async () => checkpointed(dir), 30000 * SLOW, 'a first checkpoint');
        if (!(await running(d))) break;
        d.proc.kill('SIGKILL');
        await d.exited;
        kills++;
        d = await startDaemon(args);
      }
    }, () => d);
  } finally {
    await d.stop();
    rmSync(dir, { recursive: true, force: true });
  }
  return { ref, got, kills };
}

// What depends on wall time or identity, not on the simulation.
const physics = (st) => { const o = { ...st }; delete o.steps_per_s; delete o.rtf; return o; };

test(`a pace-max session killed ${KILLS} times ends bit for bit as an uninterrupted one`, { timeout: 180000 * SLOW }, async () => {
  const { ref, got, kills } = await bothWays(async (d0, interrupt, cur = () => d0) => {
    const d = () => cur();
    const id = (await req(d().base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 2 })).body.id;
    await settled(d(), `/api/v1/sessions/${id}`, (b) => b.state === 'finished');
    // a control at a time both runs share: where until stopped it
    const p = await req(d().base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 60, beta_rate: 30, until: 600 });
    assert.equal(p.status, 200, p.text);
    assert.equal(p.body.t_effective, 2);
    await interrupt(async (dd) => {
      // work remains until it finished at its until (not: is it "running"
      // now, which a poll just after the control can miss)
      const r = await req(dd.base, 'GET', `/api/v1/sessions/${id}`);
      return r.status !== 200 || !(r.body.state === 'finished' && r.body.status.t >= 600);
    });
    const g = await settled(d(), `/api/v1/sessions/${id}`, (b) => b.state === 'finished', 120000);
    // the trajectory's rows (since the last start, for the restored one)
    const tr = (await req(d().base, 'GET', `/api/v1/sessions/${id}/trajectory`)).body;
    return { status: g.body.status, fields: tr.fields, rows: tr.rows };
  });
  assert.ok(kills >= 1, `killed while running ${kills} times`);
  assert.ok(Number.isFinite(ref.status.step_error), 'a shadow measured the step error');
  assert.deepEqual(physics(got.status), physics(ref.status), `restored ${kills} times`);
  // every row the restored run recorded is the uninterrupted run's row at
  // that time, every column (the uncertainty's too)
  const byT = new Map(ref.rows.map((r) => [r[0], r]));
  const shared = got.rows.filter((r) => byT.has(r[0]));
  assert.ok(shared.length >= 10, `${shared.length} rows at shared times`);
  for (const r of shared) assert.deepEqual(r, byT.get(r[0]), `the row at t = ${r[0]}`);
});

test(`an experiment killed ${KILLS} times gives the uninterrupted run's CSV byte for byte`, { timeout: 180000 * SLOW }, async () => {
  const { ref, got, kills } = await bothWays(async (d0, interrupt, cur = () => d0) => {
    const d = () => cur();
    const ex = await req(d().base, 'POST', '/api/v1/experiments', {
      session: { ...CHEAP, pace: 'max' },
      schedule: [{ beta: 40, until: 240 }, { beta: 120, until: 560 }, { beta: 20, until: 880 }],
    });
    assert.equal(ex.status, 201, ex.text);
    const path = `/api/v1/experiments/${ex.body.id}`;
    await interrupt(async (dd) => ['waiting', 'running'].includes((await req(dd.base, 'GET', path)).body?.state));
    const e = await settled(d(), path, (b) => b.state === 'done' || b.state === 'interrupted' || b.state === 'aborted', 120000);
    assert.equal(e.body.state, 'done', JSON.stringify(e.body));
    const csv = (await req(d().base, 'GET', `${path}?format=csv`)).text;
    // the ids differ between the two runs; everything else must not
    return csv.split(ex.body.id).join('ID').split(e.body.session).join('SESSION');
  }, 0.3); // segments begin between a checkpoint and the kill: replayed from the log
  assert.ok(kills >= 1, `killed while running ${kills} times`);
  assert.equal(got, ref, `restored ${kills} times`);
});

// A closed loop commands beta every period; those commands are not
// flushed to the control log one by one (the experiment, resumed from the
// checkpoint, sends them again), and they do not restart the transport
// estimator. Killed three times, it still ends with the uninterrupted
// run's CSV byte for byte: its per-setpoint results, and each segment's
// mean velocity and error bar over the estimate since its command.
test(`a closed loop killed ${KILLS} times gives the uninterrupted run's CSV byte for byte`, { timeout: 180000 * SLOW }, async () => {
  const { ref, got, kills } = await bothWays(async (d0, interrupt, cur = () => d0) => {
    const d = () => cur();
    const ex = await req(d().base, 'POST', '/api/v1/experiments', {
      session: { pace: 'max' },
      control: { setpoint: [{ v: 0.1, until: 300 }, { v: -0.08, until: 600 }, { v: 0.05, until: 900 }],
        controller: { kp: 2, ki: 800 } },
      disturbances: [{ at: 450, set: { m_n: 0.75 } }],
    });
    assert.equal(ex.status, 201, ex.text);
    const path = `/api/v1/experiments/${ex.body.id}`;
    await interrupt(async (dd) => ['waiting', 'running'].includes((await req(dd.base, 'GET', path)).body?.state));
    const e = await settled(d(), path, (b) => !['waiting', 'running'].includes(b.state), 120000);
    assert.equal(e.body.state, 'done', JSON.stringify(e.body));
    assert.ok(e.body.segments.every((s, i) => i === 0 || Number.isFinite(s.mean_velocity)), 'an estimate per segment');
    const csv = (await req(d().base, 'GET', `${path}?format=csv`)).text;
    return csv.split(ex.body.id).join('ID').split(e.body.session).join('SESSION');
  }, 0.3);
  assert.ok(kills >= 1, `killed while running ${kills} times`);
  assert.equal(got, ref, `restored ${kills} times`);
});

// An experiment killed before its session's first checkpoint (none
// carries it) runs again from its first segment on the session that comes
// back from its spec at t = 0: done, the uninterrupted run's CSV byte for
// byte (docs/operations.md "What a crash can lose"). Before, it was listed
// `interrupted` with no segment done.
test('an experiment killed before its session\'s first checkpoint runs again from its start, byte for byte', { timeout: 180000 * SLOW }, async () => {
  const body = {
    session: { ...CHEAP, pace: 'max' },
    schedule: [{ beta: 40, until: 240 }, { beta: 120, until: 560 }, { beta: 20, until: 880 }],
  };
  const run = async (d, ex) => {
    const path = `/api/v1/experiments/${ex.id}`;
    const e = await settled(d, path, (b) => !['waiting', 'running'].includes(b.state), 120000);
    assert.equal(e.body.state, 'done', JSON.stringify(e.body));
    const csv = (await req(d.base, 'GET', `${path}?format=csv`)).text;
    return csv.split(ex.id).join('ID').split(ex.session).join('SESSION');
  };
  let d = await startDaemon([]);
  let ref;
  try {
    const ex = await req(d.base, 'POST', '/api/v1/experiments', body);
    assert.equal(ex.status, 201, ex.text);
    ref = await run(d, ex.body);
  } finally {
    await d.stop();
  }
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-exp0-'));
  // no checkpoint within the run: the session has none when it dies
  const args = ['--data-dir', dir, '--checkpoint-interval', '3600'];
  d = await startDaemon(args);
  try {
    const ex = await req(d.base, 'POST', '/api/v1/experiments', body);
    assert.equal(ex.status, 201, ex.text);
    const { id, session } = ex.body;
    // killed as soon as its record and its session's spec are on disk
    const files = [join(dir, 'experiments', `${id}.bin`), join(dir, 'sessions', session, 'spec.json')];
    const end = Date.now() + 10000 * SLOW;
    while (!files.every((f) => existsSync(f)) && Date.now() < end) await sleep(1);
    d.proc.kill('SIGKILL');
    await d.exited;
    assert.ok(files.every((f) => existsSync(f)), 'the records were on disk');
    assert.ok(!existsSync(join(dir, 'sessions', session, 'checkpoint.bin')), 'no checkpoint before the kill');
    assert.ok(!existsSync(join(dir, `experiment-${id}.json`)), 'killed before it ended');
    d = await startDaemon(args);
    const got = await run(d, ex.body);
    assert.equal(got, ref);
  } finally {
    await d.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});

// The same for an experiment attached to a session that had finished
// (its checkpoint, written when it stopped, does not carry the
// experiment): it begins again where the session stood, as it did.
test('an experiment attached to a finished session, killed before a checkpoint carried it, runs again byte for byte', { timeout: 180000 * SLOW }, async () => {
  const schedule = [{ beta: 40, until: 200 }, { beta: 120, until: 500 }];
  const once = async (d, dir, kill) => {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 50 });
    assert.equal(s.status, 201, s.text);
    const sid = s.body.id;
    await settled(d, `/api/v1/sessions/${sid}`, (b) => b.state === 'finished');
    const ex = await req(d.base, 'POST', '/api/v1/experiments', { session: sid, schedule });
    assert.equal(ex.status, 201, ex.text);
    const id = ex.body.id;
    if (kill) d = await kill(id, sid);
    const path = `/api/v1/experiments/${id}`;
    const e = await settled(d, path, (b) => !['waiting', 'running'].includes(b.state), 120000);
    assert.equal(e.body.state, 'done', JSON.stringify(e.body));
    assert.equal(e.body.t_start, 50);
    const csv = (await req(d.base, 'GET', `${path}?format=csv`)).text;
    return { d, csv: csv.split(id).join('ID').split(sid).join('SESSION') };
  };
  let d = await startDaemon([]);
  let ref;
  try {
    ({ csv: ref } = await once(d, null, null));
  } finally {
    await d.stop();
  }
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-exp1-'));
  const args = ['--data-dir', dir, '--checkpoint-interval', '3600'];
  d = await startDaemon(args);
  try {
    const got = await once(d, dir, async (id, sid) => {
      // once its record and its first command's line are on disk: the
      // restore must leave that line to the experiment, not replay it
      const rec = join(dir, 'experiments', `${id}.bin`);
      const log = join(dir, 'sessions', sid, 'controls.ndjson');
      const ready = () => existsSync(rec) && existsSync(log) && readFileSync(log, 'utf8').includes(id);
      const end = Date.now() + 10000 * SLOW;
      while (!ready() && Date.now() < end) await sleep(1);
      d.proc.kill('SIGKILL');
      await d.exited;
      assert.ok(ready(), 'its record and first command were on disk');
      assert.ok(existsSync(join(dir, 'sessions', sid, 'checkpoint.bin')), 'the session\'s checkpoint of its stop');
      assert.ok(!existsSync(join(dir, `experiment-${id}.json`)), 'killed before it ended');
      d = await startDaemon(args);
      return d;
    });
    d = got.d;
    assert.equal(got.csv, ref);
  } finally {
    await d.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});
