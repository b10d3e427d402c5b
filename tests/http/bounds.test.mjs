// SPDX-License-Identifier: GPL-3.0-or-later
// Bounds the API states once and keeps everywhere: a refused value names the
// one range the daemon holds to (docs/api.md's PATCH table, the OpenAPI
// document), and a trajectory's stride gives rows exactly that far apart
// (docs/api-streams.md "Trajectory"), however large or small it is.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, CHEAP, SLOW } from './lib.mjs';

let d, id, path;
before(async () => {
  d = await startDaemon(['--max-cpu-seconds', '300']);
  const c = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 2 });
  assert.equal(c.status, 201, c.text);
  id = c.body.id;
  path = `/api/v1/sessions/${id}`;
  await until(async () => (await req(d.base, 'GET', path)).body.state === 'finished', 30000 * SLOW, 'finish');
});
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

test('trajectory: a stride keeps only rows on its grid, however large; 0 or less is 400', async () => {
  const all = (await req(d.base, 'GET', `${path}/trajectory`)).body;
  assert.ok(all.count > 100, `${all.count} rows`);
  for (const stride of [0.96, 1e17, 1e300]) {
    const r = await req(d.base, 'GET', `${path}/trajectory?stride=${encodeURIComponent(stride)}`);
    assert.equal(r.status, 200, r.text);
    assert.equal(r.body.stride, stride);
    const ts = r.body.rows.map((row) => row[0]);
    for (const t of ts) assert.ok(Math.abs(t / stride - Math.round(t / stride)) < 1e-6, `t ${t} off the ${stride} s grid`);
    assert.equal(r.body.count, ts.length);
    assert.equal(r.body.count, Math.floor(2 / stride + 1e-9) + 1, `stride ${stride}: ${ts.slice(0, 4)}`);
  }
  for (const q of ['stride=0', 'stride=-0.012', 'stride=-0']) {
    const r = await req(d.base, 'GET', `${path}/trajectory?${q}`);
    assert.equal(r.status, 400, `${q}: ${r.text}`);
    assert.equal(r.body.type, '/api/v1/problems/bad-query');
    assert.equal(r.body.field, 'stride');
  }
});
