// SPDX-License-Identifier: GPL-3.0-or-later
// SIGTERM (and SIGINT) with sessions running and streams open: every
// stream gets an "end" record with reason "shutdown" and the daemon exits 0.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, CHEAP, NO_FEED, SLOW } from './lib.mjs';

async function readAll(res) {
  const dec = new TextDecoder();
  let text = '';
  for await (const chunk of res.body) text += dec.decode(chunk, { stream: true });
  return text;
}

for (const signal of ['SIGTERM', 'SIGINT']) {
  test(`${signal} with open streams exits cleanly`, { timeout: 60000 * SLOW }, async () => {
    const d = await startDaemon();
    const ids = [];
    for (const body of [{ ...NO_FEED }, { ...CHEAP }, { ...NO_FEED, pace: 'max', until: 1e6 }]) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', body);
      assert.equal(r.status, 201);
      ids.push(r.body.id);
    }
    // a sweep in the pool as well
    const sw = await req(d.base, 'POST', '/api/v1/sweeps',
      { ...CHEAP, beta: [30, 60, 90, 120], t_end: 0.5 });
    assert.equal(sw.status, 202);
    const streams = await Promise.all(ids.map((id, i) => fetch(
      `${d.base}/api/v1/sessions/${id}/stream${i % 2 ? '?format=ndjson' : ''}`)));
    for (const s of streams) assert.equal(s.status, 200);
    const bodies = streams.map(readAll);
    await new Promise((r) => setTimeout(r, 300));
    const t0 = Date.now();
    const { code, sig } = await d.stop(signal);
    assert.equal(sig, null, d.stderr());
    assert.equal(code, 0, d.stderr());
    assert.ok(Date.now() - t0 < 10000 * SLOW, 'exits promptly');
    const texts = await Promise.all(bodies);
    assert.match(texts[0], /event: end\ndata: \{"reason":"shutdown"\}\n\n$/);
    assert.match(texts[1], /\{"type":"end","reason":"shutdown"\}\n$/);
    assert.match(texts[2], /event: end\ndata: \{"reason":"shutdown"\}\n\n$/);
    assert.match(d.stderr(), /stopped cleanly|^$/);
  });
}
