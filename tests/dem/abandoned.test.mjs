// SPDX-License-Identifier: GPL-3.0-or-later
// A LIGGGHTS session's creation whose client leaves while its bed settles
// (docs/load.md "Creations that settle"): the bed process watches the
// client's socket and is ended when it closes; the creation is then the
// same as a column session's whose client left: nothing created, counted
// in convsim_sessions_abandoned_total, logged at info as a client that
// left (not as a bed that did not start), the bed process ended and
// reaped, and its --max-dem-sessions slot free again: the next LIGGGHTS
// creation is 201.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { once } from 'node:events';
import { connect } from 'node:net';
import { startDaemon, req, metric, until, children, procState, SLOW } from '../http/lib.mjs';

// two layers: a bed of a few hundred grains that settles for a second or
// more, long enough to leave while it does
const BED = { scene: { feed_model: 'liggghts', layers: 2 }, pace: 'max', until: 0.01 };

const metrics = async (d) => (await req(d.base, 'GET', '/metrics')).text;

test('a LIGGGHTS creation whose client leaves while its bed settles creates nothing, is counted abandoned and frees its slot', { timeout: 180000 * SLOW }, async () => {
  const d = await startDaemon(['--worker-nice', '15', '--max-paced-cores', '4', '--log-level', 'info']);
  try {
    const sock = connect(d.port, '127.0.0.1');
    await once(sock, 'connect');
    const got = [];
    sock.on('data', (b) => got.push(b));
    sock.on('error', () => {});
    const text = JSON.stringify(BED);
    sock.write(`POST /api/v1/sessions HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
      `Content-Type: application/json\r\nContent-Length: ${Buffer.byteLength(text)}\r\n\r\n${text}`);
    // its bed process started and settles: leave
    const [bed] = await until(async () => {
      const c = children(d.proc.pid);
      if (got.length) assert.fail(`answered before a bed process started: ${Buffer.concat(got)}`);
      return c.length && c;
    }, 30000, 'the bed process');
    sock.destroy();
    // answered (to nobody) once its bed process is gone
    await until(async () => { const m = await metrics(d); return metric(m, 'convsim_http_requests_total{status="503"}') +
      metric(m, 'convsim_http_requests_total{status="201"}') >= 1; }, 30000, 'the creation over');
    await until(async () => procState(bed) === null, 10000, 'the bed process reaped');
    assert.equal(Buffer.concat(got).toString(), '', 'nobody was answered');
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
    const m = await metrics(d);
    assert.equal(metric(m, 'convsim_sessions_abandoned_total'), 1);
    assert.equal(metric(m, 'convsim_sessions_created_total'), 0);
    assert.deepEqual(children(d.proc.pid), [], 'no bed process left');
    assert.match(d.stderr(), /info: session \w+ not created: its client left while it settled/);
    assert.doesNotMatch(d.stderr(), /did not start/);

    // its slot under --max-dem-sessions 1 is free: the next one is created
    const next = await req(d.base, 'POST', '/api/v1/sessions', BED);
    assert.equal(next.status, 201, next.text);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${next.body.id}`)).status, 204);
    assert.equal(procState(next.body.bed.pid), null, 'no process, no zombie');
    assert.equal(metric(await metrics(d), 'convsim_sessions_abandoned_total'), 1);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
