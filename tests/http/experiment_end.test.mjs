// SPDX-License-Identifier: GPL-3.0-or-later
// An experiment that ends early ends its segments with it (docs/api.md
// "Experiments"): DELETE of the session it runs on leaves it `aborted`,
// its segments done kept and every other one `aborted`, not pending or
// running for ever; the same in its CSV and after a restart on the same
// data directory.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, CHEAP, SLOW } from './lib.mjs';

const states = (body) => body.segments.map((s) => s.state);
const csvStates = (text) => text.trim().split('\n').slice(1).map((row) => row.split(',')[5]);

test('DELETE of its session: the experiment is aborted, its segments not done too, also after a restart', { timeout: 90000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-expend-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const ex = await req(d.base, 'POST', '/api/v1/experiments', {
      session: s.body.id,
      schedule: [{ beta: 40, until: 0.3 }, { beta: 120, until: 300 }, { beta: 60, until: 600 }],
    });
    assert.equal(ex.status, 201, ex.text);
    const path = `/api/v1/experiments/${ex.body.id}`;
    // the first segment done, the second running, the third pending
    const mid = await until(async () => {
      const g = (await req(d.base, 'GET', path)).body;
      return g.segments[1].state === 'running' && g;
    }, 20000, 'the second segment running');
    assert.deepEqual(states(mid), ['done', 'running', 'pending']);
    const del = await req(d.base, 'DELETE', `/api/v1/sessions/${s.body.id}`);
    assert.equal(del.status, 204, del.text);
    const ended = await until(async () => {
      const g = (await req(d.base, 'GET', path)).body;
      return g.state !== 'running' && g;
    }, 2000, 'the experiment ended');
    assert.equal(ended.state, 'aborted', JSON.stringify(ended));
    assert.equal(ended.error, 'the session was deleted or the daemon stopped');
    assert.deepEqual(states(ended), ['done', 'aborted', 'aborted']);
    assert.equal(typeof ended.segments[0].steady_velocity, 'number');
    for (const seg of ended.segments.slice(1)) {
      assert.equal(seg.steady_velocity, null);
      assert.equal(seg.steady, null);
    }
    const csv = await req(d.base, 'GET', `${path}?format=csv`);
    assert.equal(csv.status, 200, csv.text);
    assert.deepEqual(csvStates(csv.text), ['done', 'aborted', 'aborted'], csv.text);
    assert.equal((await req(d.base, 'GET', `/api/v1/sessions/${s.body.id}`)).status, 404);

    // the record written at the end says the same after a restart
    assert.equal((await d.stop()).code, 0, d.stderr());
    d = await startDaemon(args);
    const back = await req(d.base, 'GET', path);
    assert.equal(back.status, 200, back.text);
    assert.equal(back.body.state, 'aborted');
    assert.equal(back.body.error, ended.error);
    assert.deepEqual(states(back.body), ['done', 'aborted', 'aborted']);
    assert.deepEqual(back.body.segments, ended.segments);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});

test('a session deleted before its experiment\'s first segment ends: every segment aborted', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon([]);
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const ex = await req(d.base, 'POST', '/api/v1/experiments', {
      session: s.body.id,
      schedule: [{ beta: 40, until: 300 }, { beta: 120, until: 600 }],
    });
    assert.equal(ex.status, 201, ex.text);
    const path = `/api/v1/experiments/${ex.body.id}`;
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${s.body.id}`)).status, 204);
    const ended = await until(async () => {
      const g = (await req(d.base, 'GET', path)).body;
      return !['waiting', 'running'].includes(g.state) && g;
    }, 2000, 'the experiment ended');
    assert.equal(ended.state, 'aborted', JSON.stringify(ended));
    assert.deepEqual(states(ended), ['aborted', 'aborted']);
    const list = (await req(d.base, 'GET', '/api/v1/experiments')).body.experiments;
    const entry = list.find((e) => e.id === ex.body.id);
    assert.deepEqual(states(entry), ['aborted', 'aborted']);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('until during an experiment: one before its end is 409 naming until and changes nothing; null or a later one is taken', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon([]);
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const spath = `/api/v1/sessions/${s.body.id}`;
    const ex = await req(d.base, 'POST', '/api/v1/experiments', {
      session: s.body.id,
      schedule: [{ beta: 40, until: 0.2 }, { beta: 120, until: 300 }],
    });
    assert.equal(ex.status, 201, ex.text);
    const path = `/api/v1/experiments/${ex.body.id}`;
    const running = await until(async () => {
      const g = (await req(d.base, 'GET', path)).body;
      return g.state === 'running' && g;
    }, 20000, 'the experiment running');
    // the session, without an until of its own, runs on past the
    // schedule's end: its start plus 300 s
    assert.equal((await req(d.base, 'GET', spath)).body.until, null);
    const end = running.t_start + 300;
    const r = await req(d.base, 'PATCH', spath, { until: end - 100 });
    assert.equal(r.status, 409, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.body.status, 409);
    assert.equal(r.body.type, '/api/v1/problems/conflict');
    assert.equal(r.body.field, 'until');
    assert.equal(r.body.detail, `experiment ${ex.body.id} runs the session to t = ${+end.toPrecision(6)} s: ` +
      `until (${+(end - 100).toPrecision(6)} s) must be at least that, or null, until it ends`);
    assert.equal((await req(d.base, 'GET', spath)).body.until, null, 'until unchanged');
    assert.equal((await req(d.base, 'GET', path)).body.state, 'running');
    const later = await req(d.base, 'PATCH', spath, { until: 400 });
    assert.equal(later.status, 200, later.text);
    assert.equal(later.body.until, 400);
    const none = await req(d.base, 'PATCH', spath, { until: null });
    assert.equal(none.status, 200, none.text);
    assert.equal(none.body.until, null);
    assert.equal(running.segments.length, 2);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('until between an experiment\'s 201 and its start: one before its end is 409 and changes nothing', { timeout: 60000 * SLOW }, async () => {
  // a session whose worker spends about a tenth of a second a sample outside
  // its lock, so that a PATCH right after the experiment's 201 arrives
  // before the worker has begun it (the experiment still waiting)
  const d = await startDaemon([]);
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', {
      scene: { drive: 'ideal', columns: 16, layers: 32 }, sample_rate: 1, pace: 'max', until: 1e4,
    });
    assert.equal(s.status, 201, s.text);
    const spath = `/api/v1/sessions/${s.body.id}`;
    await until(async () => (await req(d.base, 'GET', spath)).body.status.t >= 1, 20000, 'the session running');
    for (let round = 0; round < 3; round++) {
      const before = (await req(d.base, 'GET', spath)).body;
      const ex = await req(d.base, 'POST', '/api/v1/experiments', {
        session: s.body.id, schedule: [{ beta: 40, until: 5000 }],
      });
      assert.equal(ex.status, 201, ex.text);
      const r = await req(d.base, 'PATCH', spath, { beta: 100, until: before.status.t + 1000 });
      assert.equal(r.status, 409, r.text);
      assert.equal(r.body.field, 'until');
      const exp = (await req(d.base, 'GET', `/api/v1/experiments/${ex.body.id}`)).body;
      assert.equal(exp.state, 'running');
      const end = exp.t_start + 5000;
      assert.equal(r.body.detail, `experiment ${ex.body.id} runs the session to t = ${+end.toPrecision(6)} s: ` +
        `until (${+(before.status.t + 1000).toPrecision(6)} s) must be at least that, or null, until it ends`);
      const after = (await req(d.base, 'GET', spath)).body;
      assert.equal(after.until, 1e4, 'until unchanged');
      assert.equal(after.status.beta_target, 40, 'beta: the experiment\'s');
      assert.equal((await req(d.base, 'DELETE', `/api/v1/experiments/${ex.body.id}`)).status, 204);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
