// SPDX-License-Identifier: GPL-3.0-or-later
// A control that would run a session on at a pace that alone needs more
// than --max-paced-cores is 422 out-of-range stating pace's range, the
// largest pace that fits as max: it names the pace, the field whose
// range it states, whichever member asked (docs/api-errors.md). `running`,
// `until` and `cpu_budget` resume a session at the pace it has, which
// needed no cores while it stood still: its streams opened meanwhile are
// charged with it, and a pace it was given then was taken unchecked. An
// experiment on a finished session runs it on at its pace too
// (`session.pace`). The detail names the member that asked; nothing
// changes, and the stated max is taken.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, metric, until, SLOW } from './lib.mjs';

const LIMIT = 1e-4;
// printf's %g (6 significant digits), as the detail writes a pace
const g6 = (x) => String(Number(x.toPrecision(6)));
const number = '[0-9.e+-]+';

test('running, until, cpu_budget and an experiment that resume a session beyond the whole budget: 422 naming the pace with its range', { timeout: 60000 * SLOW }, async () => {
  // paces so small that no worker measures its session's cost (50 ms of
  // CPU or 2 simulated s), no probe: every hold is the scene's estimate
  const d = await startDaemon(['--max-paced-cores', String(LIMIT), '--cpu-probe', '0']);
  const paced = async () => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_paced_cpu_cores');
  const get = async (path) => (await req(d.base, 'GET', path)).body;
  const streams = new AbortController();
  try {
    const first = await req(d.base, 'POST', '/api/v1/sessions', { pace: 0.001 });
    assert.equal(first.status, 201, first.text);
    const cost = (await paced()) / 0.001; // CPU s per simulated s, estimated
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${first.body.id}`)).status, 204);
    const pace = 0.9 * LIMIT / cost; // alone 0.9 of the budget; with a stream, more than all
    const twice = 2 * LIMIT / cost; // alone twice the budget
    // a session that holds no cores
    const still = async (body, stop) => {
      const r = await req(d.base, 'POST', '/api/v1/sessions', body);
      assert.equal(r.status, 201, r.text);
      const path = `/api/v1/sessions/${r.body.id}`;
      await stop(path);
      return path;
    };
    const refusal = (r, instance, field, who, at, verb = 'changed') => {
      const at6 = g6(at);
      assert.equal(r.status, 422, r.text);
      assert.equal(r.headers.get('content-type'), 'application/problem+json');
      assert.ok(r.body.max > 0.001 && r.body.max < at, `the largest pace that fits, below ${at}: ${r.text}`);
      assert.deepEqual(r.body, {
        type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422, detail: r.body.detail,
        instance, field, min: 0.001, max: r.body.max, budget: 'cpu', limit: LIMIT,
      });
      assert.match(r.body.detail, new RegExp(`^${who} would run it at its pace ${at6}: this session needs ${number} ` +
        `cores \\(${number} ms of CPU per simulated s at pace ${at6}\\), more than the 0\\.0001 cores for paced ` +
        `sessions \\(--max-paced-cores\\); nothing was ${verb}, lower the pace$`));
      return r.body.max;
    };
    const unchanged = async (path, was) => {
      const now = await get(path);
      assert.equal(now.state, was.state, path);
      assert.equal(now.pace, was.pace, path);
      assert.equal(await paced(), 0, 'nothing held');
    };

    // running: a paused session resumed, with a stream opened meanwhile
    const A = await still({ pace }, async (path) => {
      assert.equal((await req(d.base, 'PATCH', path, { running: false })).status, 200);
      const s = await fetch(`${d.base}${path}/stream`, { signal: streams.signal });
      assert.equal(s.status, 200);
      await until(async () => (await get(path)).streams === 1, 10000 * SLOW, 'the stream counted');
    });
    let was = await get(A);
    const maxA = refusal(await req(d.base, 'PATCH', A, { running: true }), A, 'pace', 'running', pace);
    await unchanged(A, was);

    // until: a finished session run on, its pace raised while it stood
    const B = await still({ pace, until: 0.001 }, async (path) => {
      await until(async () => (await get(path)).state === 'finished', 20000 * SLOW, 'B finished');
      assert.equal((await req(d.base, 'PATCH', path, { pace: twice })).status, 200);
    });
    was = await get(B);
    refusal(await req(d.base, 'PATCH', B, { until: 600 }), B, 'pace', 'until', twice);
    await unchanged(B, was);
    // an experiment on it: the session's pace, as an experiment names it
    const id = B.split('/').pop();
    refusal(await req(d.base, 'POST', '/api/v1/experiments', { session: id, schedule: [{ beta: 40, until: 0.002 }] }),
      '/api/v1/experiments', 'session.pace', 'the experiment', twice, 'attached');
    assert.equal((await get(B)).experiment ?? null, null, 'nothing attached');
    await unchanged(B, was);

    // cpu_budget: a session its CPU budget paused (pace max, then its pace)
    const C = await still({ pace: 'max' }, async (path) => {
      assert.equal((await req(d.base, 'PATCH', path, { cpu_budget: 0.001 })).status, 200);
      await until(async () => (await get(path)).pause_reason === 'cpu-budget', 20000 * SLOW, 'C paused by its budget');
      assert.equal((await req(d.base, 'PATCH', path, { pace: twice })).status, 200);
    });
    was = await get(C);
    refusal(await req(d.base, 'PATCH', C, { cpu_budget: 10 }), C, 'pace', 'cpu_budget', twice);
    await unchanged(C, was);

    // the max stated is taken, with the member that asked
    const ok = await req(d.base, 'PATCH', A, { running: true, pace: maxA });
    assert.equal(ok.status, 200, ok.text);
    assert.equal(ok.body.state, 'running');
  } finally {
    streams.abort();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
