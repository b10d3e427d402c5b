// SPDX-License-Identifier: GPL-3.0-or-later
// A PATCH that breaks several admission rules at once gets the refusal of
// the first in admit_control's order (server/session/session_control.c):
// a member's limit (cpu_budget past --max-cpu-seconds: 422) before the
// session's state and before the members' checks against the session
// (until in the past, running a finished session: 409); a refused PATCH
// changes nothing.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, NO_FEED, SLOW } from './lib.mjs';

test('admission: cpu_budget past the limit wins over until in the past and running a finished session', { timeout: 30000 * SLOW }, async () => {
  const d = await startDaemon(['--max-cpu-seconds', '5']);
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 'max', until: 0.5 });
    assert.equal(c.status, 201, c.text);
    const path = `/api/v1/sessions/${c.body.id}`;
    await until(async () => (await req(d.base, 'GET', path)).body.state === 'finished', 20000 * SLOW, 'finish');
    const before = (await req(d.base, 'GET', path)).body;
    const refuse = async (body, status, field) => {
      const r = await req(d.base, 'PATCH', path, body);
      assert.equal(r.status, status, r.text);
      assert.equal(r.body.field, field, r.text);
      return r.body;
    };
    let b = await refuse({ until: 0.25, cpu_budget: 10 }, 422, 'cpu_budget');
    assert.equal(b.max, 5);
    b = await refuse({ running: true, cpu_budget: 10 }, 422, 'cpu_budget');
    assert.equal(b.max, 5);
    b = await refuse({ until: 0.25 }, 409, 'until');
    assert.match(b.detail, /^until \(0\.25 s\) lies in the past: the session is at t = /);
    b = await refuse({ running: true }, 409, 'running');
    assert.equal(b.detail, 'the session finished at until = 0.5 s; raise until to run on');
    b = await refuse({ running: true, beta: 100, until: 0.25 }, 409, 'until');
    const after = (await req(d.base, 'GET', path)).body;
    assert.equal(after.state, 'finished');
    assert.equal(after.status.t, before.status.t);
    assert.equal(after.cpu_limit, before.cpu_limit);
  } finally {
    await d.stop();
  }
});
