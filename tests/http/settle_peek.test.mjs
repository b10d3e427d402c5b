// SPDX-License-Identifier: GPL-3.0-or-later
// An adaptive method's steps are known only once it runs, so no estimate
// before a paced dopri5 session's settling could refuse it: a 64 x 64 one
// settled whole (about 48 s on the clock), holding the only settling slot, before its
// probe refused it for needing 64 cores. Such a session now settles 0.2 CPU s
// first and is refused there where that settling alone needs twice the
// cores for paced sessions (server/admit/cpu_probe.c, srv_cpu_settle_peek;
// docs/load.md "What settling costs"); one that fits settles again from the
// start and is created. A creation of any pace whose settling would run to
// twice what --max-cpu-seconds leaves or more is refused there too: it
// settled up to the bound before.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, metric, postRefusedCpu, SLOW } from './lib.mjs';

const LARGE = { scene: { columns: 64, layers: 64 }, integrator: { method: 'dopri5' } };
const DETAIL = new RegExp('^this session needs ([0-9.e+]+) cores \\(([0-9.e+]+) ms of CPU per simulated s at ' +
  'pace 1\\), more than the 1 core for paced sessions \\(--max-paced-cores\\); nothing was created, lower ' +
  'the pace \\(measured over the first 0\\.2 CPU s of its settling: integrator\\.method dopri5 is adaptive\\)$');

test('a paced dopri5 session that needs far more than the paced cores is refused after 0.2 CPU s of its settling; one that fits is created', { timeout: 120000 * SLOW }, async () => {
  const d = await startDaemon(['--max-paced-cores', '1']);
  try {
    const { r, cpu } = await postRefusedCpu(d, '/api/v1/sessions', LARGE);
    const { detail, max, ...rest } = r.body;
    assert.deepEqual(rest, {
      type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422,
      instance: '/api/v1/sessions', field: 'pace', budget: 'cpu', limit: 1, min: 0.001,
    });
    const m = detail.match(DETAIL);
    assert.ok(m, detail);
    const need = Number(m[1]);
    // refused at twice the budget or more; the largest pace is the budget over the need
    assert.ok(need >= 2, detail);
    // (the detail prints three significant digits)
    assert.ok(Math.abs(max * Number(m[2]) / 1e3 - 1) < 5e-3, `max ${max} against ${m[2]} ms`);
    // the settling stopped at the peek (its whole settling took about 48 s on the clock)
    assert.ok(cpu < 3 * SLOW, `the daemon spent ${cpu} CPU s over the request`);
    // nothing was created or held: the settling slot and the cores are free
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
    const text = (await req(d.base, 'GET', '/metrics')).text;
    assert.equal(metric(text, 'convsim_sessions_created_total'), 0);
    assert.equal(metric(text, 'convsim_paced_cpu_cores'), 0);
    // the default scene with dopri5 at pace 0.01 needs about 0.08 cores: its
    // settling (about 4 CPU s) goes past the peek, starts again and ends
    const ok = await req(d.base, 'POST', '/api/v1/sessions', { integrator: { method: 'dopri5' }, pace: 0.01 });
    assert.equal(ok.status, 201, ok.text);
    assert.equal(ok.body.status.t, 0);
    assert.equal(ok.body.columns, 5);
    assert.equal(ok.body.layers, 8);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${ok.body.id}`)).status, 204);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

const UNPACED = { scene: { columns: 64, layers: 64, settle: 5 }, integrator: { method: 'dopri5' }, pace: 'max' };
const WHOLE = new RegExp('^the steady start\'s settling would take about ([0-9.e+]+) CPU s, twice what ' +
  '--max-cpu-seconds \\(20\\) leaves or more \\(its first ([0-9.e+]+) CPU s settled ([0-9.e+-]+) of ' +
  'scene\\.settle\'s 5 s; dopri5 is adaptive\\); nothing was created: a method of a fixed step \\(rk4, euler, ' +
  'dem\\), a shorter scene\\.settle or scene\\.start "rest"$');

test('a dopri5 creation whose settling would take twice --max-cpu-seconds is refused after 0.2 CPU s of it', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--max-cpu-seconds', '20']);
  try {
    const { r, cpu } = await postRefusedCpu(d, '/api/v1/sessions', UNPACED);
    const { detail, ...rest } = r.body;
    assert.deepEqual(rest, {
      type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422,
      instance: '/api/v1/sessions', field: 'integrator.method', budget: 'cpu', limit: 20,
      choices: ['rk4', 'euler', 'dem'],
    });
    const m = detail.match(WHOLE);
    assert.ok(m, detail);
    const [whole, spent, settled] = m.slice(1).map(Number);
    // the projection: the peek's rate over the whole scene.settle (three digits each)
    assert.ok(whole >= 40, detail);
    assert.ok(spent >= 0.2 && spent < 0.2 + 0.05 * SLOW, detail);
    assert.ok(settled > 0 && settled < 5 / 2, detail);
    assert.ok(Math.abs(whole / (spent / settled * 5) - 1) < 0.01, detail);
    // it settled the peek, not the 20 CPU s of the bound (a 64 x 64 dopri5 step takes milliseconds)
    assert.ok(cpu < 3 * SLOW, `the daemon spent ${cpu} CPU s over the request`);
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
