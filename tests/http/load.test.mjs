// SPDX-License-Identifier: GPL-3.0-or-later
// Fifty sessions, each with its own streaming client, run at once without
// an error; metrics move with them.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, openStream, metric, until, NO_FEED, SLOW } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

test('50 sessions with a stream each', { timeout: 120000 * SLOW }, async () => {
  const m0 = (await req(d.base, 'GET', '/metrics')).text;
  const N = 50;
  const ids = [];
  const readers = [];
  const read = async (id, i) => {
    const recs = [];
    let end = null;
    for await (const rec of openStream(d.base, `/api/v1/sessions/${id}/stream?fields=trough,rotor`)) {
      if (rec.event === 'end') { end = rec.data.reason; break; }
      if (rec.event === 'sample') recs.push(rec);
    }
    return { i, end, recs };
  };
  for (let i = 0; i < N; i++) {
    const r = await req(d.base, 'POST', '/api/v1/sessions',
      { ...NO_FEED, params: { beta: 20 + i }, pace: 1, until: 2, sample_rate: 100 });
    assert.equal(r.status, 201, r.text);
    ids.push(r.body.id);
    readers.push(read(r.body.id, i));
  }
  const results = await Promise.all(readers);
  for (const { i, end, recs } of results) {
    assert.equal(end, 'finished', `session ${i}`);
    assert.ok(recs.length >= 20, `session ${i}: ${recs.length} samples`);
    for (let k = 1; k < recs.length; k++) assert.ok(recs[k].id > recs[k - 1].id);
    assert.equal(recs.at(-1).data.t, 2);
    assert.ok(Math.abs(recs.at(-1).data.beta - (20 + i)) < 1e-9, 'each stream carries its own session');
  }
  // a stream's client leaves once the daemon has sent its end and closed
  // it, which may be a moment after the client read the end
  const m1 = await until(async () => {
    const m = (await req(d.base, 'GET', '/metrics')).text;
    return metric(m, 'convsim_stream_clients') === 0 && m;
  }, 5000 * SLOW, 'the stream clients to leave');
  assert.equal(metric(m1, 'convsim_sessions'), N);
  assert.equal(metric(m1, 'convsim_sessions_created_total') - metric(m0, 'convsim_sessions_created_total'), N);
  assert.equal(metric(m1, 'convsim_streams_opened_total') - metric(m0, 'convsim_streams_opened_total'), N);
  assert.ok(metric(m1, 'convsim_steps_total') > metric(m0, 'convsim_steps_total'));
  assert.ok(metric(m1, 'convsim_stream_records_total') >= N * 20);
  assert.equal(metric(m1, 'convsim_stream_clients'), 0);
  assert.equal(metric(m1, 'convsim_http_requests_total{status="201"}') -
    metric(m0, 'convsim_http_requests_total{status="201"}'), N);
  assert.equal(metric(m1, 'convsim_http_requests_total{status="500"}'), 0);
  for (const id of ids) assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${id}`)).status, 204);
  const m2 = (await req(d.base, 'GET', '/metrics')).text;
  assert.equal(metric(m2, 'convsim_sessions'), 0);
  assert.equal(metric(m2, 'convsim_sessions_deleted_total') - metric(m1, 'convsim_sessions_deleted_total'), N);
});
