// SPDX-License-Identifier: GPL-3.0-or-later
// Admission keeps its word (docs/budgets.md "Budgets and load"): with
// the cores for paced sessions full, the next session is refused with 503
// and a problem body naming the budget, and the sessions already running
// keep their pace: not the newest refused and everyone slowed down. Holds
// are the estimate from the scene (--cpu-probe 0) until the workers have
// measured, so the refusal's numbers are known in advance.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, metric, until, sleep, SLOW, pacedBusy, fillPaced, pacedEstimates } from './lib.mjs';

test('paced budget full: the next session gets 503 with the budget named, the running ones keep pace 1', { timeout: 90000 * SLOW }, async () => {
  const limit = 0.01;
  const d = await startDaemon(['--max-paced-cores', String(limit), '--cpu-probe', '0']);
  const held = async () => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_paced_cpu_cores');
  try {
    // the first one tells the estimate (CPU s per simulated s at pace 1)
    const { ids, cost, fit } = await fillPaced(d, limit, held);
    const before = (await req(d.base, 'GET', '/metrics')).text;
    const r = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
    assert.equal(r.status, 503, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.headers.get('retry-after'), '5');
    // the holds summed as the daemon sums them, in the order they came
    let sum = 0;
    for (let i = 0; i < fit; i++) sum += cost;
    assert.deepEqual(r.body, pacedBusy(cost, cost, 1, sum, limit));
    const after = (await req(d.base, 'GET', '/metrics')).text;
    for (const k of ['convsim_sessions', 'convsim_sessions_created_total', 'convsim_paced_cpu_cores']) {
      assert.equal(metric(after, k), metric(before, k), `${k}: nothing created or held`);
    }
    // the running ones are untouched: pace 1 and running, also once their
    // workers have measured them (2 simulated s) and their holds follow
    // the measure, which may exceed the estimate: none is paced down
    // (sanitizer builds measure several times the estimate: there only
    // what the refusal itself changed is checked)
    const list = async () => (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
    if (SLOW === 1) await until(async () => (await list()).every((s) => s.status.t > 3), 30000, 'the sessions measured');
    else await sleep(500);
    const now = await list();
    assert.equal(now.length, fit);
    for (const s of now) {
      assert.equal(s.state, 'running', s.id);
      assert.equal(s.pace, 1, `${s.id} keeps pace 1`);
    }
    assert.doesNotMatch(d.stderr(), /paced down/);
    // and still nothing more is admitted
    const again = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
    assert.equal(again.status, 503, again.text);
    assert.equal(again.body.budget, 'cpu');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

// A burst of creations is admitted by each session's steady cost: the
// probe measures a copy without the shadow that measures the step error
// (it runs over a session's first 40 periods only), and a session's first
// measured window, its start, does not replace that cost (docs/budgets.md
// "Cores for paced sessions"). With the shadow in the probe a default
// session was admitted for 2.3-2.6 times its estimate, and a burst that
// fits by the steady cost was refused from about the 12th of 20.
test('a burst of paced sessions that fits by their steady cost is admitted whole, and they keep pace 1', { timeout: 90000 * SLOW }, async () => {
  const n = 20;
  // the estimate from the scene (no probe), read from a daemon of its own
  const cost = (await pacedEstimates({ DEFAULT: {} })).DEFAULT;
  assert.ok(cost > 1e-4 && cost < 0.01, `a default session's estimate: ${cost}`);
  const limit = Number((1.5 * n * cost).toPrecision(3));
  const d = await startDaemon(['--max-paced-cores', String(limit)]);
  const held = async () => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_paced_cpu_cores');
  try {
    const statuses = [];
    for (let i = 0; i < n; i++) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
      statuses.push(r.status);
      if (r.status !== 503) continue;
      // a refusal states a need that does not fit beside the holds
      const m = /needs ([\d.e+-]+) cores? .* hold ([\d.e+-]+) of the ([\d.e+-]+) cores/.exec(r.body.detail);
      assert.ok(m && Number(m[1]) + Number(m[2]) > Number(m[3]), r.body.detail);
    }
    // all 20 on a quiet machine; a loaded one makes the probe measure
    // dearer than the estimate, and the last few may be refused (with the
    // shadow in the probe, refused from about the 12th). Sanitizer builds
    // run the probe several times slower: there only that every answer is
    // a creation or the budget's refusal
    assert.ok(statuses.every((s) => s === 201 || s === 503), statuses.join(', '));
    if (SLOW === 1) {
      const first = statuses.indexOf(503);
      assert.ok(first === -1 || first >= 15, `${n} sessions in ${limit} cores: ${statuses.join(', ')}`);
    }
    assert.ok(await held() <= limit * (1 + 1e-9), `the holds within the budget: ${await held()}`);
    // once measured past their start (two windows of 2 simulated s) they
    // all run at pace 1: none was paced down
    const list = async () => (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
    if (SLOW === 1) await until(async () => (await list()).every((s) => s.status.t > 4.5), 30000, 'the sessions measured');
    for (const s of await list()) {
      assert.equal(s.state, 'running', s.id);
      assert.equal(s.pace, 1, `${s.id} keeps pace 1`);
    }
    assert.doesNotMatch(d.stderr(), /paced down/);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
