// SPDX-License-Identifier: GPL-3.0-or-later
// An identification or a closed loop measures its scene in the request's
// thread before it answers; the estimate that refuses it beyond
// --max-cpu-seconds (measure_bound.test.mjs) takes dem's steps for an
// adaptive method, whose settling alone took seconds (docs/load.md "What
// settling costs"). Now each measurement stops once the request's thread
// has used --max-cpu-seconds (core/cpu_bound.c) and the experiment is
// refused, nothing started: naming session.integrator.method with the
// methods of a fixed step for a fresh session of an adaptive method.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, metric, postStoppedAdaptive, SLOW } from './lib.mjs';

const BOUND = 0.3; // a closed loop's curve is estimated at 0.211 CPU s (dem's steps)
const FRESH = { session: { integrator: { method: 'dopri5' } } };
const stopped = (what) => new RegExp(`^${what} stopped at ([0-9.e+-]+) CPU s in this request's thread, ` +
  `past --max-cpu-seconds \\(${BOUND}\\): no estimate knows the steps of integrator\\.method dopri5 ` +
  '\\(adaptive\\); nothing was started: a session whose integrator\\.method has a fixed step ' +
  '\\(rk4, euler, dem\\)$');

test('an identification or a closed loop on a dopri5 session is stopped at --max-cpu-seconds 0.3 and refused; a default identification is started', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--max-cpu-seconds', String(BOUND), '--ring', '64', '--history', '64']);
  try {
    const cases = [
      [{ ...FRESH, identify: { beta: [38] } }, 'identify\'s slopes'],
      [{ ...FRESH, control: { setpoint: [{ v: 0.10, until: 2 }], controller: { kp: 2, ki: 800 } } },
        'control\'s measurements'],
    ];
    for (const [body, what] of cases) {
      const { detail, cpu } = await postStoppedAdaptive(d, '/api/v1/experiments', body,
        'session.integrator.method', BOUND);
      const m = detail.match(stopped(what));
      assert.ok(m, detail);
      const spent = Number(m[1]);
      assert.ok(spent >= BOUND && spent < BOUND + 0.05 * SLOW, `spent ${spent} CPU s`);
      assert.ok(cpu < BOUND + 0.25 * SLOW, `the daemon spent ${cpu} CPU s over the request`);
    }
    // nothing started: no experiment, no session
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/experiments')).body.experiments, []);
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
    const text = (await req(d.base, 'GET', '/metrics')).text;
    assert.equal(metric(text, 'convsim_sessions_created_total'), 0);
    assert.equal(metric(text, 'convsim_settling'), 0);
    // the default scene's identification under the same bound: started
    const ok = await req(d.base, 'POST', '/api/v1/experiments',
      { session: { pace: 'max' }, identify: { beta: [38] } });
    assert.equal(ok.status, 201, ok.text);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
