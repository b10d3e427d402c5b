// SPDX-License-Identifier: GPL-3.0-or-later
// A session's creation settles its steady start and runs its probe in the
// request's thread before it answers (docs/load.md "Creations that
// settle"): a 64 x 64 scene for about a CPU second. A client that leaves
// meanwhile is answered by nobody, so nothing is created for it: its
// session is not listed, holds no memory, no cores for its pace and no
// slot, and convsim_sessions_abandoned_total counts it; the same for an
// experiment on a fresh session. A client that waits is answered 201.
// An identification on an existing session measures its scene in the
// request's thread too, holding a settling slot: one whose client leaves
// meanwhile is withdrawn before it is attached, the session left as it
// was, and convsim_experiments_abandoned_total counts it; one on a fresh
// session is withdrawn before that session is built.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { once } from 'node:events';
import { connect } from 'node:net';
import { startDaemon, req, metric, until, SLOW } from './lib.mjs';

const LARGE = { scene: { columns: 64, layers: 64 }, pace: 0.01, sample_rate: 1 };
const metrics = async (d) => (await req(d.base, 'GET', '/metrics')).text;
const listed = async (d, what) => (await req(d.base, 'GET', `/api/v1/${what}`)).body[what];

// POST body to path on a socket of its own, closed once the daemon settles
// it; resolves to whatever the daemon wrote back on that socket (nothing).
async function leaveWhileSettling(d, path, body) {
  const sock = connect(d.port, '127.0.0.1');
  await once(sock, 'connect');
  const got = [];
  sock.on('data', (b) => got.push(b));
  sock.on('error', () => {});
  const text = JSON.stringify(body);
  sock.write(`POST ${path} HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
    `Content-Type: application/json\r\nContent-Length: ${Buffer.byteLength(text)}\r\n\r\n${text}`);
  await until(async () => metric(await metrics(d), 'convsim_settling') === 1, 10000,
    `${path} settling`);
  sock.destroy();
  return Buffer.concat(got).toString();
}

// The daemon is done with an abandoned request: counted abandoned (or,
// where it was not discarded, created).
async function settled(d, abandoned, created) {
  return until(async () => {
    const m = await metrics(d);
    return (metric(m, 'convsim_sessions_abandoned_total') >= abandoned ||
            metric(m, 'convsim_sessions_created_total') > created) &&
      metric(m, 'convsim_settling') === 0 && m;
  }, 30000, 'the abandoned request over');
}

test('a creation or a fresh experiment whose client leaves while it settles creates nothing; one that waits is created', { timeout: 180000 * SLOW }, async () => {
  const d = await startDaemon(['--max-sessions', '1', '--ring', '64', '--history', '64']);
  try {
    assert.equal(await leaveWhileSettling(d, '/api/v1/sessions', LARGE), '');
    let m = await settled(d, 1, 0);
    assert.deepEqual(await listed(d, 'sessions'), []);
    assert.equal(metric(m, 'convsim_sessions_abandoned_total'), 1);
    assert.equal(metric(m, 'convsim_sessions_created_total'), 0);
    assert.equal(metric(m, 'convsim_memory_reserved_bytes'), 0);
    assert.equal(metric(m, 'convsim_paced_cpu_cores'), 0);
    // its place under --max-sessions 1 is free: a default creation is 201
    const next = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1 });
    assert.equal(next.status, 201, next.text);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${next.body.id}`)).status, 204);

    // an experiment on a fresh session: neither is kept
    assert.equal(await leaveWhileSettling(d, '/api/v1/experiments',
      { session: LARGE, schedule: [{ beta: 38, until: 1 }] }), '');
    m = await settled(d, 2, 1);
    assert.deepEqual(await listed(d, 'experiments'), []);
    assert.deepEqual(await listed(d, 'sessions'), []);
    assert.equal(metric(m, 'convsim_sessions_abandoned_total'), 2);
    assert.equal(metric(m, 'convsim_sessions_created_total'), 1);
    assert.equal(metric(m, 'convsim_experiments_total'), 0);
    assert.equal(metric(m, 'convsim_memory_reserved_bytes'), 0);
    assert.equal(metric(m, 'convsim_paced_cpu_cores'), 0);

    // the same creation awaited, on a kept-alive connection: 201, listed
    const kept = await req(d.base, 'POST', '/api/v1/sessions', LARGE);
    assert.equal(kept.status, 201, kept.text);
    assert.deepEqual((await listed(d, 'sessions')).map((s) => s.id), [kept.body.id]);
    m = await metrics(d);
    assert.equal(metric(m, 'convsim_sessions_abandoned_total'), 2);
    assert.equal(metric(m, 'convsim_sessions_created_total'), 2);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('an identification on an existing session whose client leaves while it measures is withdrawn; the session stays the client\'s', { timeout: 180000 * SLOW }, async () => {
  const d = await startDaemon(['--ring', '64', '--history', '64', '--log-level', 'info']);
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions',
      { scene: { columns: 16, layers: 16 }, pace: 0.01, sample_rate: 1 });
    assert.equal(s.status, 201, s.text);
    const id = s.body.id;
    // two operating points of a 16 x 16 scene: four runs, about a second
    assert.equal(await leaveWhileSettling(d, '/api/v1/experiments',
      { session: id, identify: { beta: [30, 38] } }), '');
    const m = await until(async () => {
      const t = await metrics(d);
      return (metric(t, 'convsim_experiments_abandoned_total') >= 1 ||
              metric(t, 'convsim_experiments_total') >= 1) &&
        metric(t, 'convsim_settling') === 0 && t;
    }, 30000, 'the abandoned identification over');
    assert.deepEqual(await listed(d, 'experiments'), []);
    assert.equal(metric(m, 'convsim_experiments_abandoned_total'), 1);
    assert.equal(metric(m, 'convsim_experiments_total'), 0);
    assert.equal(metric(m, 'convsim_sessions_abandoned_total'), 0);
    // the session runs on as before, nothing attached, its controls the client's
    const g = await req(d.base, 'GET', `/api/v1/sessions/${id}`);
    assert.equal(g.body.state, 'running', g.text);
    assert.equal(g.body.experiment, null);
    const p = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 38 });
    assert.equal(p.status, 200, p.text);
    assert.match(d.stderr(), /experiment \w+ not started: its client left while it measured/);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('an identification on a fresh session whose client leaves while it measures is withdrawn before its session settles', { timeout: 180000 * SLOW }, async () => {
  const d = await startDaemon(['--ring', '64', '--history', '64', '--log-level', 'info']);
  try {
    assert.equal(await leaveWhileSettling(d, '/api/v1/experiments',
      { session: { scene: { columns: 16, layers: 16 }, pace: 0.01, sample_rate: 1 }, identify: { beta: [30, 38] } }), '');
    const m = await until(async () => {
      const t = await metrics(d);
      return (metric(t, 'convsim_experiments_abandoned_total') + metric(t, 'convsim_sessions_abandoned_total') +
              metric(t, 'convsim_experiments_total') >= 1) && metric(t, 'convsim_settling') === 0 && t;
    }, 30000, 'the abandoned identification over');
    assert.deepEqual(await listed(d, 'experiments'), []);
    assert.deepEqual(await listed(d, 'sessions'), []);
    // withdrawn once measured: its session was never built nor settled
    assert.equal(metric(m, 'convsim_experiments_abandoned_total'), 1);
    assert.equal(metric(m, 'convsim_sessions_abandoned_total'), 0);
    assert.equal(metric(m, 'convsim_sessions_created_total'), 0);
    assert.match(d.stderr(), /experiment \w+ not started: its client left while it measured/);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
