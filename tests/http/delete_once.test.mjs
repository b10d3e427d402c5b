// SPDX-License-Identifier: GPL-3.0-or-later
// One deletion, one 204 (docs/api-errors.md): DELETE of a session, sweep,
// fit or experiment answers 204 once; a DELETE after it, or one that arrives while
// another is deleting the same object, gets the 404 a GET of an unknown id
// gets, body for body. Many DELETEs of one object at the same moment (on
// connections opened beforehand, so that they reach the daemon together)
// once answered 204 to two of them. An experiment's run on a fresh
// session, which goes with the one DELETE that answers 204.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import http from 'node:http';
import { startDaemon, req, CHEAP, NO_FEED } from './lib.mjs';

const ROUNDS = 200;
const AT_ONCE = 16;

let d, agent;
before(async () => {
  d = await startDaemon([]);
  agent = new http.Agent({ keepAlive: true, maxSockets: AT_ONCE + 4 });
});
after(async () => {
  agent.destroy();
  assert.equal((await d.stop()).code, 0, d.stderr());
});

// one request on the agent's kept connections: {status, body}
const call = (method, path, body) => new Promise((resolve, reject) => {
  const text = body === undefined ? '' : JSON.stringify(body);
  const r = http.request({
    host: '127.0.0.1', port: d.port, method, path, agent,
    headers: { 'Content-Type': 'application/json', ...(text ? { 'Content-Length': Buffer.byteLength(text) } : {}) },
  }, (res) => {
    let t = '';
    res.on('data', (c) => { t += c; });
    res.on('end', () => resolve({ status: res.statusCode, ctype: res.headers['content-type'], text: t }));
  });
  r.on('error', reject);
  if (text) r.write(text);
  r.end();
});

const KINDS = {
  sessions: { ...NO_FEED, pace: 1 },
  sweeps: { ...NO_FEED, beta: { from: 10, to: 170, step: 1 }, rotations: ['cw'], t_end: 0.1 },
  fits: { ...CHEAP, free: ['mu'], points: [{ beta: 60, rotation: 'cw', v: 0.1 }], t_end: 1, max_iter: 1 },
  experiments: { session: { ...NO_FEED, pace: 1 }, schedule: [{ beta: 38, until: 600 }] },
};

for (const [kind, body] of Object.entries(KINDS)) {
  test(`${kind}: a second DELETE is the 404 of an unknown id`, async () => {
    const c = await req(d.base, 'POST', `/api/v1/${kind}`, body);
    assert.ok(c.status === 201 || c.status === 202, c.text);
    const path = `/api/v1/${kind}/${c.body.id}`;
    const first = await req(d.base, 'DELETE', path);
    assert.equal(first.status, 204, first.text);
    assert.equal(first.text, '');
    const again = await req(d.base, 'DELETE', path);
    assert.equal(again.status, 404, again.text);
    assert.equal(again.headers.get('content-type'), 'application/problem+json');
    const get = await req(d.base, 'GET', path);
    assert.equal(get.status, 404);
    assert.deepEqual(again.body, { ...get.body, instance: path });
    assert.equal(again.body.type, '/api/v1/problems/not-found');
    assert.equal(again.body.detail, `no ${kind.slice(0, -1)} with id "${c.body.id}"`);
  });

  test(`${kind}: ${AT_ONCE} DELETEs of one at once: one 204, the others that 404`, { timeout: 120000 }, async () => {
    const twice = [];
    for (let k = 0; k < ROUNDS; k++) {
      const c = await call('POST', `/api/v1/${kind}`, body);
      assert.ok(c.status === 201 || c.status === 202, c.text);
      const id = JSON.parse(c.text).id;
      const path = `/api/v1/${kind}/${id}`;
      // every connection open and idle before the DELETEs go
      await Promise.all(Array.from({ length: AT_ONCE + 4 }, () => call('GET', '/api/v1/health')));
      // GETs among them hold a job's lock while the DELETEs look it up
      const [all] = await Promise.all([
        Promise.all(Array.from({ length: AT_ONCE }, () => call('DELETE', path))),
        Promise.all(Array.from({ length: 4 }, () => call('GET', path))),
      ]);
      const ok = all.filter((r) => r.status === 204);
      if (ok.length !== 1) twice.push(`round ${k}: ${all.map((r) => r.status).join(' ')}`);
      const unknown = await call('GET', path);
      assert.equal(unknown.status, 404);
      for (const r of all.filter((x) => x.status !== 204)) {
        assert.equal(r.status, 404, r.text);
        assert.equal(r.ctype, 'application/problem+json');
        assert.deepEqual(JSON.parse(r.text), JSON.parse(unknown.text));
      }
    }
    assert.deepEqual(twice, [], 'rounds whose DELETEs did not answer exactly one 204');
  });
}
