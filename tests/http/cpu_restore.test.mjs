// SPDX-License-Identifier: GPL-3.0-or-later
// A session's CPU grant is an acknowledged control like any other
// (docs/durability.md: none is lost to a restart): after a SIGTERM or a
// kill -9, whether or not a checkpoint came after it, the session keeps
// the last cpu_budget it was given (and the CPU it spent of it:
// cpu_spent.test.mjs, docs/budgets.md), and one its budget paused comes
// back paused by the budget (pause_reason "cpu-budget", not "client"), so
// that running: true grants it --max-cpu-seconds again.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, untilReplayed, sleep, CHEAP, SLOW } from './lib.mjs';

const MAX = 300; // --max-cpu-seconds

for (const [signal, interval] of [['SIGTERM', '3600'], ['SIGKILL', '0.2']]) {
  test(`${signal}: the CPU grant and a budget's pause survive the restart`, { timeout: 90000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsimd-cpu-'));
    const args = ['--data-dir', dir, '--max-cpu-seconds', String(MAX), '--checkpoint-interval', interval];
    let d = await startDaemon(args);
    try {
      const granted = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
      const spent = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 1e5 });
      const client = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
      for (const c of [granted, spent, client]) assert.equal(c.status, 201, c.text);
      const at = (c) => `/api/v1/sessions/${c.body.id}`;
      let r = await req(d.base, 'PATCH', at(granted), { cpu_budget: 120 });
      assert.equal(r.status, 200, r.text);
      r = await req(d.base, 'PATCH', at(spent), { cpu_budget: 0.05 });
      assert.equal(r.status, 200, r.text);
      r = await req(d.base, 'PATCH', at(client), { cpu_budget: 60, running: false });
      assert.equal(r.status, 200, r.text);
      await until(async () => (await req(d.base, 'GET', at(spent))).body.pause_reason === 'cpu-budget',
        30000 * SLOW, 'the budget to pause it');
      await sleep(1000); // checkpoints after the controls (SIGKILL's interval is 0.2 s)
      await d.stop(signal);
      d = await startDaemon(args);
      for (const c of [granted, spent, client]) await untilReplayed(d.base, c.body.id);
      const g = (await req(d.base, 'GET', at(granted))).body;
      assert.equal(g.state, 'running');
      assert.ok(Math.abs(g.cpu_limit - 120) < 0.5, `granted: cpu_limit ${g.cpu_limit}, want 120`);
      const s = (await req(d.base, 'GET', at(spent))).body;
      assert.equal(s.state, 'paused');
      assert.equal(s.pause_reason, 'cpu-budget');
      const c = (await req(d.base, 'GET', at(client))).body;
      assert.equal(c.state, 'paused');
      assert.equal(c.pause_reason, 'client');
      assert.ok(Math.abs(c.cpu_limit - 60) < 0.5, `client: cpu_limit ${c.cpu_limit}, want 60`);
      // resumed as before the restart: a fresh --max-cpu-seconds from now
      r = await req(d.base, 'PATCH', at(spent), { running: true });
      assert.equal(r.status, 200, r.text);
      assert.equal(r.body.state, 'running');
      assert.ok(r.body.cpu_limit >= MAX, `resumed: cpu_limit ${r.body.cpu_limit}`);
    } finally {
      assert.equal((await d.stop()).code, 0, d.stderr());
    }
  });
}
