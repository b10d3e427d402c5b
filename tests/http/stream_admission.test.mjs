// SPDX-License-Identifier: GPL-3.0-or-later
// Streams in the cores for paced sessions (docs/budgets.md "Streams"): a
// stream of a running paced session is charged its expected CPU (records a
// simulated second times the cost of each, formatted and sent) with its
// session's hold, so that a stream beyond --max-paced-cores is refused 503
// with the budget named and what is taken, as the next creation is, and
// the running sessions and their streams go on untouched. Holds are the
// estimate from the scene (--cpu-probe 0) until the workers have measured
// (2 simulated s), so the refusal's numbers are known in advance.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import http from 'node:http';
import { startDaemon, req, metric, until, SLOW, g3, cores, fillPaced, pacedEstimates } from './lib.mjs';

// A stream's charge (server/admit/budget_stream.c): a wake-up and a number
// formatted, CPU s. That of a ?fields=trough&rate=10 stream of a default
// session (250 samples a simulated s), CPU s per simulated s: 10 wake-ups
// and 10 records of 9 numbers.
const WAKE = 75e-6, NUMBER = 1.0e-6;
const STREAM = 10 * WAKE + 10 * 9 * NUMBER;
const QUERY = '?format=ndjson&fields=trough&rate=10';

// Open a stream of session id: {status, body (parsed when refused),
// records (parsed NDJSON lines so far), close()}, once its head is in.
function open(base, id, query = QUERY) {
  return new Promise((resolve, reject) => {
    const st = { records: [], text: '' };
    const r = http.get(`${base}/api/v1/sessions/${id}/stream${query}`, { agent: false }, (res) => {
      st.status = res.statusCode;
      st.headers = res.headers;
      res.setEncoding('utf8');
      let buf = '';
      res.on('data', (c) => {
        if (st.status !== 200) { st.text += c; return; }
        buf += c;
        for (let at = buf.indexOf('\n'); at >= 0; at = buf.indexOf('\n')) {
          st.records.push(JSON.parse(buf.slice(0, at)));
          buf = buf.slice(at + 1);
        }
      });
      res.on('error', () => {});
      if (st.status === 200) resolve(st);
      else res.on('end', () => { st.body = JSON.parse(st.text); resolve(st); });
    });
    r.on('error', (e) => { if (!st.closed) reject(e); });
    st.close = () => { st.closed = true; r.destroy(); };
  });
}

test('paced budget: a stream beyond it gets 503 naming the budget, the running sessions and streams go on', { timeout: 90000 * SLOW }, async () => {
  // a budget of three default sessions and what lies halfway between two
  // streams and a fourth session: the sessions that fit leave room for two
  // streams (the estimate from a daemon of its own, read as fillPaced does)
  const c = (await pacedEstimates({ DEFAULT: {} })).DEFAULT;
  assert.ok(c > 2 * STREAM, `a default session's estimate ${c} is more than two streams' ${2 * STREAM}`);
  const limit = Number((3 * c + (2 * STREAM + c) / 2).toPrecision(3));
  const d = await startDaemon(['--max-paced-cores', String(limit), '--cpu-probe', '0']);
  const metrics = async () => (await req(d.base, 'GET', '/metrics')).text;
  const held = async () => metric(await metrics(), 'convsim_paced_cpu_cores');
  const streams = [];
  try {
    const { ids, cost, fit } = await fillPaced(d, limit, held, STREAM);
    assert.equal(cost, c);
    // the streams that fit in what is left, each charged STREAM
    const room = Math.floor((limit - fit * cost) / STREAM + 1e-9);
    for (let i = 0; i < room; i++) {
      const s = await open(d.base, ids[i % fit]);
      assert.equal(s.status, 200, `stream ${i + 1} of ${room} fits: ${s.text}`);
      streams.push(s);
    }
    const taken = fit * cost + room * STREAM;
    assert.ok(Math.abs(await held() - taken) < 1e-9, `held ${await held()}, expected ${taken}`);
    const before = await metrics();
    const refused = await open(d.base, ids[0]);
    assert.equal(refused.status, 503, refused.text);
    assert.equal(refused.headers['content-type'], 'application/problem+json');
    assert.equal(refused.headers['retry-after'], '5');
    assert.deepEqual(refused.body, {
      type: '/api/v1/problems/unavailable',
      title: 'Service unavailable',
      status: 503,
      detail: `this stream needs ${cores(STREAM)} (${g3(1e3 * STREAM)} ms of CPU per simulated s at pace 1) ` +
        `and running paced sessions and their streams hold ${g3(taken)} of the ${limit} cores for paced sessions ` +
        '(--max-paced-cores); nothing was opened, retry when some have ended or paused, or ask fewer records ' +
        '(rate, fields)',
      instance: `/api/v1/sessions/${ids[0]}/stream`,
      budget: 'cpu',
      limit,
    });
    const after = await metrics();
    for (const k of ['convsim_stream_clients', 'convsim_streams_opened_total', 'convsim_paced_cpu_cores',
      'convsim_memory_reserved_bytes']) {
      assert.equal(metric(after, k), metric(before, k), `${k}: nothing opened or held`);
    }
    assert.equal(metric(after, 'convsim_stream_clients'), room);
    // a creation counts the streams too: refused with them in what is taken
    const r = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
    assert.equal(r.status, 503, r.text);
    assert.equal(r.body.budget, 'cpu');
    assert.match(r.body.detail, new RegExp(`running paced sessions hold ${g3(taken).replace('.', '\\.')} of`));
    // the running ones are untouched: pace 1, running, their streams
    // delivering samples after the refusals
    const list = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
    assert.equal(list.length, fit);
    for (const s of list) {
      assert.equal(s.state, 'running', s.id);
      assert.equal(s.pace, 1, `${s.id} keeps pace 1`);
    }
    const t0 = list.find((s) => s.id === ids[0]).status.t;
    if (room > 0) {
      await until(() => streams[0].records.some((x) => x.type === 'sample' && x.t > t0), 10000 * SLOW,
        'a sample after the refusal');
    }
    // a paused session holds nothing, its streams neither: a stream of it
    // is admitted beyond the budget, and held again when it resumes
    const pause = await req(d.base, 'PATCH', `/api/v1/sessions/${ids[0]}`, { running: false });
    assert.equal(pause.status, 200, pause.text);
    const mine = streams.filter((_, i) => i % fit === 0).length;
    await until(async () => Math.abs(await held() - (taken - cost - mine * STREAM)) < 1e-9, 10000 * SLOW,
      'the paused session and its streams give their hold back');
    // closing a stream of a running session gives its charge back at once
    assert.ok(fit >= 2 && room >= 2, `${fit} sessions and ${room} streams fill the budget`);
    {
      const s = streams[1];
      s.close();
      await until(async () => metric(await metrics(), 'convsim_stream_clients') === room - 1, 10000 * SLOW,
        'the closed stream counted out');
      assert.ok(Math.abs(await held() - (taken - cost - mine * STREAM - STREAM)) < 1e-9);
    }
    // the charge counts the numbers of the fields asked: trough and rotor
    // are 14 a sample (t, beta, beta_target, 6 and 5), as the records say
    const before2 = await held();
    const rotor = await open(d.base, ids[1], '?format=ndjson&fields=trough,rotor&rate=10');
    streams.push(rotor);
    assert.equal(rotor.status, 200, rotor.text);
    assert.ok(Math.abs(await held() - before2 - (10 * WAKE + 10 * 14 * NUMBER)) < 1e-9,
      `held ${await held()} after ${before2}`);
    await until(() => rotor.records.some((x) => x.type === 'sample'), 10000 * SLOW, 'a sample');
    const sample = rotor.records.find((x) => x.type === 'sample');
    assert.equal(Object.entries(sample).filter(([k, v]) => k !== 'id' && typeof v === 'number').length, 14,
      JSON.stringify(sample));
    // a default stream of every sample: 50 wake-ups and 250 records of 35
    // numbers (5 columns), 12.5 ms of CPU per simulated s, more than the
    // whole budget's room
    const all = await open(d.base, ids[1], '?format=ndjson');
    assert.equal(all.status, 503, all.text);
    assert.match(all.body.detail, /^this stream needs 0\.0125 cores \(12\.5 ms of CPU per simulated s at pace 1\)/);
  } finally {
    for (const s of streams) s.close();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

// A stream is woken once a record but at most once per paced batch, 50 a
// wall second at any pace: at pace 0.1 a stream of every sample (250 a
// simulated s) is woken 25 times a wall second, at pace 10 a ?rate=10
// stream 50 times, not 100 (budget_stream.c srv_budget_streams_cpu).
test('paced budget: a stream is charged its wake-ups a wall second, at most 50, at any pace', { timeout: 60000 * SLOW }, async () => {
  const limit = 0.02;
  const d = await startDaemon(['--max-paced-cores', String(limit), '--cpu-probe', '0']);
  const held = async () => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_paced_cpu_cores');
  const streams = [];
  try {
    // pace 0.1, a default stream of every sample: 250 wake-ups and 250
    // records of 35 numbers a simulated s, a tenth of that a wall s
    const slow = await req(d.base, 'POST', '/api/v1/sessions', { pace: 0.1, until: 600 });
    assert.equal(slow.status, 201, slow.text);
    const h0 = await held();
    const all = await open(d.base, slow.body.id, '?format=ndjson');
    streams.push(all);
    assert.equal(all.status, 200, all.text);
    const charge = 0.1 * (250 * WAKE + 250 * 35 * NUMBER);
    const h1 = await held();
    assert.ok(Math.abs(h1 - h0 - charge) < 1e-9, `held ${h1} after ${h0}: the stream ${h1 - h0}, expected ${charge}`);
    all.close();
    await until(async () => Math.abs(await held() - h0) < 1e-9, 10000 * SLOW, 'the closed stream gives its charge back');
    // pace 1 to 10 with a ?rate=10 trough stream open: its 10 records a
    // simulated s are 100 a wall s, woken 50 times: 5 wake-ups a simulated s
    const fast = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
    assert.equal(fast.status, 201, fast.text);
    const cost = (await held()) - h0;
    const thin = await open(d.base, fast.body.id);
    streams.push(thin);
    assert.equal(thin.status, 200, thin.text);
    const perS = cost + 5 * WAKE + 10 * 9 * NUMBER;
    assert.ok(10 * perS > limit, `pace 10 needs ${10 * perS} cores, beyond ${limit}`);
    const r = await req(d.base, 'PATCH', `/api/v1/sessions/${fast.body.id}`, { pace: 10 });
    assert.equal(r.status, 422, r.text);
    assert.equal(r.body.field, 'pace');
    assert.equal(r.body.detail, `this session needs ${cores(10 * perS)} (${g3(1e3 * perS)} ms of CPU per ` +
      `simulated s at pace 10), more than the ${limit} cores for paced sessions (--max-paced-cores); ` +
      'nothing was changed, lower the pace');
    // the greatest pace the cores allow, with the stream's wake-ups capped
    // on the way there (at pace p: 10 p of them a wall s, at most 50)
    const need = (p) => p * (cost + 10 * 9 * NUMBER) + Math.min(10 * p, 50) * WAKE;
    let lo = 0, hi = 100;
    for (let i = 0; i < 100; i++) { const mid = (lo + hi) / 2; if (need(mid) <= limit) lo = mid; else hi = mid; }
    assert.ok(Math.abs(r.body.max - lo) < 1e-9 * lo, `max ${r.body.max}, the greatest pace that fits ${lo}`);
    assert.ok(need(r.body.max) <= limit * (1 + 1e-12) && need(r.body.max * 1.001) > limit);
    assert.equal((await req(d.base, 'GET', `/api/v1/sessions/${fast.body.id}`)).body.pace, 1);
  } finally {
    for (const s of streams) s.close();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
