// SPDX-License-Identifier: GPL-3.0-or-later
// pace "max" without an end gets one, 60 simulated seconds on (api.h
// API_DEFAULT_MAX_UNTIL, docs/api.md): on creation the answer's until says
// 60, and a PATCH that leaves a "max" session without an end ({"pace":
// "max", "until": null}, or "max" alone on a session without until)
// answers in `applied` the until it set, the one GET shows, not null.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, NO_FEED, SLOW } from './lib.mjs';

test('until null with pace max: the answer says the end applied', { timeout: 30000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 'max', until: null });
    assert.equal(c.status, 201, c.text);
    assert.equal(c.body.until, 60);
    assert.equal(c.body.pace, 'max');
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${c.body.id}`)).status, 204);

    for (const change of [{ pace: 'max', until: null }, { pace: 'max' }]) {
      const s = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1 });
      assert.equal(s.status, 201, s.text);
      assert.equal(s.body.until, null);
      const path = `/api/v1/sessions/${s.body.id}`;
      const p = await req(d.base, 'PATCH', path, change);
      assert.equal(p.status, 200, p.text);
      assert.equal(typeof p.body.applied.until, 'number', `${JSON.stringify(change)}: ${p.text}`);
      assert.deepEqual(p.body.applied, { pace: 'max', until: p.body.until }, JSON.stringify(change));
      assert.ok(p.body.until >= 60 && p.body.until < 60 + 10, p.text);
      assert.equal((await req(d.base, 'GET', path)).body.until, p.body.applied.until);
      assert.equal((await req(d.base, 'DELETE', path)).status, 204);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
