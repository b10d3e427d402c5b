// SPDX-License-Identifier: GPL-3.0-or-later
// The daemon's budgets, each against a real daemon given small limits by
// flags: memory (--max-memory: 422 for a session larger than the whole
// budget, 503 + Retry-After when full, nothing created), CPU
// (--max-cpu-seconds pauses a session with pause_reason "cpu-budget",
// --max-busy lets pace-max sessions take turns, --max-paced-cores admits
// paced sessions by the cores they need: 503 + Retry-After or 422, nothing
// created or changed), queued sweep points
// (--max-queued-points: 422 / 429 + Retry-After) and the connections of one
// client address (--max-client-connections: its own least active one closed
// to make room; 429 with a body only while all its others are answered,
// then closed at once; idle sockets closed after --connection-timeout, live
// streams kept). After each refusal another client is still served.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import http from 'node:http';
import net from 'node:net';
import { execFileSync } from 'node:child_process';
import { startDaemon, req, openStream, until, metric, near, sleep, NO_FEED, SLOW, CLI } from './lib.mjs';

const JSON_HEADERS = { 'Content-Type': 'application/json' };

// One GET from a given loopback source address; {status, headers, body}
// or {error} when the daemon closed the connection without an answer.
function getFrom(base, path, localAddress) {
  return new Promise((resolve) => {
    const r = http.get(base + path, { localAddress, agent: false }, (res) => {
      let text = '';
      res.on('data', (c) => { text += c; });
      res.on('end', () => resolve({ status: res.statusCode, headers: res.headers,
        body: text && JSON.parse(text) }));
    });
    r.on('error', (e) => resolve({ error: e.code || e.message }));
  });
}

// n idle TCP connections from localAddress (they never send a byte); each
// has .closedAt, a promise of the time the daemon closed it.
async function idleSockets(port, n, localAddress) {
  const socks = [];
  for (let i = 0; i < n; i++) {
    socks.push(await new Promise((resolve) => {
      const s = net.connect({ port, host: '127.0.0.1', localAddress }, () => resolve(s));
      s.closedAt = new Promise((done) => s.on('close', () => done(Date.now())));
      s.on('error', () => resolve(s)); // reset at accept: closed already
    }));
  }
  return socks;
}

async function metrics(base) {
  return (await req(base, 'GET', '/metrics')).text;
}

async function healthy(base) {
  const h = await req(base, 'GET', '/api/v1/health');
  assert.equal(h.status, 200, 'another client is still served');
}

test('memory: a session larger than the budget is 422 naming the field, a full budget 503', { timeout: 60000 * SLOW }, async () => {
  const budget = 64 * 1024 * 1024;
  const d = await startDaemon(['--max-memory', '64M']);
  try {
    // alone too large: 422, the largest layer count that fits as max
    const big = await req(d.base, 'POST', '/api/v1/sessions',
      { scene: { columns: 64, layers: 64 }, pace: 1 });
    assert.equal(big.status, 422, big.text);
    assert.equal(big.headers.get('content-type'), 'application/problem+json');
    assert.equal(big.body.type, '/api/v1/problems/out-of-range');
    assert.equal(big.body.field, 'scene.layers');
    assert.equal(big.body.budget, 'memory');
    assert.equal(big.body.limit, budget);
    assert.equal(big.body.min, 1);
    assert.ok(Number.isInteger(big.body.max) && big.body.max >= 1 && big.body.max < 64, big.text);
    assert.match(big.body.detail, /more than the whole memory budget of 64\.0 MiB \(--max-memory\)/);
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0);
    // the max it names fits, one more layer does not
    const fits = await req(d.base, 'POST', '/api/v1/sessions',
      { ...NO_FEED, scene: { columns: 64, layers: big.body.max }, pace: 0.001 });
    assert.equal(fits.status, 201, fits.text);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${fits.body.id}`)).status, 204);
    const over = await req(d.base, 'POST', '/api/v1/sessions',
      { scene: { columns: 64, layers: big.body.max + 1 }, pace: 0.001 });
    assert.equal(over.status, 422, over.text);
    assert.equal(metric(await metrics(d.base), 'convsim_memory_reserved_bytes'), 0, 'all given back');

    // default sessions until the budget is full: then 503, nothing created
    const ids = [];
    let refused;
    for (let i = 0; i < 20 && !refused; i++) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', { pace: 0.01 });
      if (r.status === 201) ids.push(r.body.id);
      else refused = r;
    }
    assert.ok(refused, 'the budget filled up');
    assert.equal(refused.status, 503, refused.text);
    assert.equal(refused.headers.get('retry-after'), '5');
    assert.equal(refused.body.type, '/api/v1/problems/unavailable');
    assert.equal(refused.body.budget, 'memory');
    assert.equal(refused.body.limit, budget);
    assert.match(refused.body.detail, /memory budget of 64\.0 MiB \(--max-memory\)/);
    const m = await metrics(d.base);
    const reserved = metric(m, 'convsim_memory_reserved_bytes');
    const need = reserved / ids.length;
    assert.ok(ids.length * need <= budget && (ids.length + 1) * need > budget,
      `${ids.length} sessions of ${need} bytes fill ${budget}`);
    assert.equal(metric(m, 'convsim_sessions'), ids.length, 'the refused session was not created');
    await healthy(d.base);
    // a deleted session gives its memory back
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${ids.pop()}`)).status, 204);
    const again = await req(d.base, 'POST', '/api/v1/sessions', { pace: 0.01 });
    assert.equal(again.status, 201, again.text);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('CPU: a session that spent --max-cpu-seconds pauses; a PATCH resumes it within the limit', { timeout: 60000 * SLOW }, async () => {
  const grant = 0.3;
  const d = await startDaemon(['--max-cpu-seconds', String(grant), '--heartbeat', '0.5']);
  try {
    const c = await req(d.base, 'POST', '/api/v1/sessions', { pace: 'max', until: 1e6 });
    assert.equal(c.status, 201, c.text);
    assert.equal(c.body.cpu_limit, grant);
    assert.equal(c.body.pause_reason, null);
    const id = c.body.id;
    const events = [];
    const reader = (async () => {
      for await (const rec of openStream(d.base, `/api/v1/sessions/${id}/stream?format=ndjson&fields=trough`)) {
        if (rec.type === 'paused') { events.push(rec); break; }
      }
    })();
    const paused = await until(async () => {
      const s = await req(d.base, 'GET', `/api/v1/sessions/${id}`);
      return s.body.state === 'paused' && s.body;
    }, 20000, 'the CPU budget to pause the session');
    assert.equal(paused.pause_reason, 'cpu-budget');
    assert.ok(paused.cpu_seconds >= grant && paused.cpu_seconds < grant + 0.2, `${paused.cpu_seconds}`);
    assert.ok(paused.status.t > 0);
    await reader;
    assert.equal(events[0].reason, 'cpu-budget');
    // it stays paused: no more CPU, no more simulated time
    await sleep(400);
    const still = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;
    assert.equal(still.status.t, paused.status.t);
    assert.equal(still.cpu_seconds, paused.cpu_seconds);

    // a grant beyond the limit is refused whole
    const tooMuch = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { cpu_budget: 10 });
    assert.equal(tooMuch.status, 422, tooMuch.text);
    assert.equal(tooMuch.body.field, 'cpu_budget');
    assert.equal(tooMuch.body.max, grant);
    const same = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;
    assert.equal(same.state, 'paused');
    assert.equal(same.cpu_limit, paused.cpu_limit);

    // resume: a fresh grant from now, then paused again when spent
    const r = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { running: true });
    assert.equal(r.status, 200, r.text);
    assert.equal(r.body.state, 'running');
    assert.equal(r.body.pause_reason, null);
    assert.ok(Math.abs(r.body.cpu_limit - (paused.cpu_seconds + grant)) < 1e-6, `${r.body.cpu_limit}`);
    const again = await until(async () => {
      const s = await req(d.base, 'GET', `/api/v1/sessions/${id}`);
      return s.body.state === 'paused' && s.body;
    }, 20000, 'the second grant to be spent');
    assert.equal(again.pause_reason, 'cpu-budget');
    assert.ok(again.status.t > paused.status.t);
    // a smaller explicit grant, and a client's pause says "client"
    const g = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { cpu_budget: 0.1 });
    assert.equal(g.status, 200, g.text);
    assert.equal(g.body.state, 'running');
    assert.equal(g.body.applied.cpu_budget, 0.1);
    const p = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { running: false });
    assert.equal(p.body.pause_reason, 'client');
    await healthy(d.base);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('CPU: with --max-busy 1 two pace-max sessions take turns, one stepping at a time', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--max-busy', '1']);
  try {
    const ids = [];
    for (let i = 0; i < 2; i++) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 'max', until: 1e5 });
      assert.equal(r.status, 201, r.text);
      ids.push(r.body.id);
    }
    let sawWaiting = false;
    const list = await until(async () => {
      const m = await metrics(d.base);
      assert.ok(metric(m, 'convsim_cpu_slots_busy') <= 1, 'at most --max-busy step at once');
      if (metric(m, 'convsim_cpu_slots_waiting') === 1) sawWaiting = true;
      await sleep(100);
      const all = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
      return all.every((s) => s.cpu_seconds > 0.3) && all;
    }, 30000, 'both sessions to use CPU');
    assert.ok(sawWaiting, 'the other one waited its turn');
    const [a, b] = list.map((s) => s.cpu_seconds);
    assert.ok(a / b > 0.5 && a / b < 2, `fair shares of CPU: ${a} vs ${b}`);
    // the one left alone runs without waiting
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${ids[0]}`)).status, 204);
    await until(async () => metric(await metrics(d.base), 'convsim_cpu_slots_waiting') === 0, 5000, 'no one waiting');
    const s = (await req(d.base, 'GET', `/api/v1/sessions/${ids[1]}`)).body;
    assert.equal(s.waiting_for_cpu, false);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('CPU: a short pace-max run that finished reports the CPU it took, not the first read of its clock', { timeout: 60000 * SLOW }, async () => {
  // the same run by the command line: its cpu_seconds is the run's own
  const cli = JSON.parse(execFileSync(CLI, ['run', '-q', '--duration', '2', '--set', 'beta=150', '--set', 'layers=2'], { encoding: 'utf8' }));
  assert.ok(cli.cpu_seconds > 0.001, `the CLI's ${cli.cpu_seconds}`);
  const d = await startDaemon();
  try {
    const r = await req(d.base, 'POST', '/api/v1/sessions',
      { params: { beta: 150 }, scene: { layers: 2 }, pace: 'max', until: 2 });
    assert.equal(r.status, 201, r.text);
    const s = await until(async () => {
      const v = (await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}`)).body;
      return v.state === 'finished' && v;
    }, 10000 * SLOW, 'the run to finish');
    assert.equal(s.status.t, 2);
    // a 2-s run takes a few ms; the worker reads its clock every 10 ms of
    // wall time, and before the read at the stop reported ~0.1 ms
    assert.ok(s.cpu_seconds > 0.3 * cli.cpu_seconds && s.cpu_seconds < 20 * cli.cpu_seconds,
      `the session's ${s.cpu_seconds} s against the CLI's ${cli.cpu_seconds} s`);
    const listed = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.find((x) => x.id === r.body.id);
    assert.equal(listed.cpu_seconds, s.cpu_seconds);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('paced CPU: a creation, pace change or resume beyond --max-paced-cores is 503 (422 alone), nothing changes', { timeout: 60000 * SLOW }, async () => {
  // Paces so small that no session runs long enough for its worker to
  // measure its cost (50 ms of CPU or 2 simulated s), and no probe at
  // creation (--cpu-probe 0; paced_cost.test.mjs tests it): every hold is
  // the estimate from the scene, read back once (under the sanitizers a
  // probe measures each session anew, more than twice the estimate).
  const limit = 1e-4;
  const d = await startDaemon(['--max-paced-cores', String(limit), '--cpu-probe', '0']);
  const paced = async () => metric(await metrics(d.base), 'convsim_paced_cpu_cores');
  const get = async (id) => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;
  const refused = (r, status, field, verb) => {
    assert.equal(r.status, status, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.body.type, status === 503 ? '/api/v1/problems/unavailable' : '/api/v1/problems/out-of-range');
    assert.equal(r.headers.get('retry-after'), status === 503 ? '5' : null);
    assert.equal(r.body.budget, 'cpu');
    assert.equal(r.body.limit, limit);
    assert.equal(r.body.field, field);
    assert.match(r.body.detail, new RegExp(`0\\.0001 cores for paced sessions \\(--max-paced-cores\\); nothing was ${verb}`));
  };
  try {
    const a = await req(d.base, 'POST', '/api/v1/sessions', { pace: 0.001 });
    assert.equal(a.status, 201, a.text);
    const cost = (await paced()) / 0.001; // CPU s per simulated s, estimated
    assert.ok(cost > 1e-4 && cost < 0.1, `a default session's estimate: ${cost}`);
    const pace = (share) => share * limit / cost; // the pace that needs share x limit
    const A = `/api/v1/sessions/${a.body.id}`;
    assert.equal((await req(d.base, 'PATCH', A, { pace: pace(0.6) })).status, 200);
    near(await paced(), 0.6 * limit, 1e-12, 'A holds 0.6 of the budget');

    // a creation that does not fit beside A: 503, nothing created or held
    const before = await metrics(d.base);
    refused(await req(d.base, 'POST', '/api/v1/sessions', { pace: pace(0.5) }), 503, 'pace', 'created');
    const after = await metrics(d.base);
    for (const k of ['convsim_sessions', 'convsim_sessions_created_total', 'convsim_memory_reserved_bytes',
      'convsim_paced_cpu_cores']) assert.equal(metric(after, k), metric(before, k), k);
    await healthy(d.base);

    // a pace that alone needs more than the budget: 422 with the largest that fits
    const big = await req(d.base, 'PATCH', A, { pace: pace(2) });
    refused(big, 422, 'pace', 'changed');
    near(big.body.max, pace(1), 1e-9 * pace(1), 'max: the pace that needs the whole budget');
    assert.equal(big.body.min, 0.001);
    near((await get(a.body.id)).pace, pace(0.6), 1e-12, 'A kept its pace');

    // a pace change that does not fit beside another session: 503
    const b = await req(d.base, 'POST', '/api/v1/sessions', { pace: pace(0.3) });
    assert.equal(b.status, 201, b.text);
    near(await paced(), 0.9 * limit, 1e-12, 'A and B hold 0.9');
    refused(await req(d.base, 'PATCH', A, { pace: pace(0.8), beta: 60 }), 503, 'pace', 'changed');
    const a1 = await get(a.body.id);
    near(a1.pace, pace(0.6), 1e-12, 'A kept its pace');
    assert.notEqual(Math.round(a1.status.beta_target), 60, 'nothing of the refused PATCH was applied');
    near(await paced(), 0.9 * limit, 1e-12, 'the holds did not change');

    // a paused session gives its hold back; its resume is refused when
    // another took the room, and allowed when it is free again
    assert.equal((await req(d.base, 'PATCH', A, { running: false })).status, 200);
    near(await paced(), 0.3 * limit, 1e-12, 'A paused holds nothing');
    const c = await req(d.base, 'POST', '/api/v1/sessions', { pace: pace(0.5) });
    assert.equal(c.status, 201, c.text);
    const paused = await get(a.body.id);
    refused(await req(d.base, 'PATCH', A, { running: true }), 503, 'running', 'changed');
    const still = await get(a.body.id);
    assert.equal(still.state, 'paused');
    assert.equal(still.status.t, paused.status.t);
    near(await paced(), 0.8 * limit, 1e-12, 'B and C hold 0.8');
    await healthy(d.base);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${c.body.id}`)).status, 204);
    near(await paced(), 0.3 * limit, 1e-12, 'a deleted session holds nothing');
    const resumed = await req(d.base, 'PATCH', A, { running: true });
    assert.equal(resumed.status, 200, resumed.text);
    assert.equal(resumed.body.state, 'running');
    near(await paced(), 0.9 * limit, 1e-12, 'A resumed holds 0.6 again');

    // an experiment on a finished paced session runs it on: it needs the
    // session's hold first (503 naming "session", nothing attached), and
    // gets it when there is room
    const f = await req(d.base, 'POST', '/api/v1/sessions', { pace: pace(0.05), until: 0.001 });
    assert.equal(f.status, 201, f.text);
    const F = `/api/v1/sessions/${f.body.id}`;
    const finished = async () => (await get(f.body.id)).state === 'finished';
    for (let i = 0; i < 200 && !(await finished()); i++) await new Promise((r) => setTimeout(r, 50));
    assert.ok(await finished(), 'F reached its until');
    near(await paced(), 0.9 * limit, 1e-12, 'a finished session holds nothing');
    const e = await req(d.base, 'POST', '/api/v1/sessions', { pace: pace(0.08) });
    assert.equal(e.status, 201, e.text);
    const schedule = { session: f.body.id, schedule: [{ beta: 40, until: 0.001 }] };
    const exps = async () => (await req(d.base, 'GET', '/api/v1/experiments')).body.experiments.length;
    const nexp = await exps();
    const tF = (await get(f.body.id)).status.t;
    refused(await req(d.base, 'POST', '/api/v1/experiments', schedule), 503, 'session', 'attached');
    assert.equal(await exps(), nexp, 'no experiment was created');
    const f1 = await get(f.body.id);
    assert.equal(f1.state, 'finished');
    assert.equal(f1.status.t, tF, 'F did not run on');
    assert.equal(f1.experiment ?? null, null, 'nothing attached to F');
    near(await paced(), 0.98 * limit, 1e-12, 'the holds did not change');
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${e.body.id}`)).status, 204);
    const x = await req(d.base, 'POST', '/api/v1/experiments', schedule);
    assert.equal(x.status, 201, x.text);
    assert.equal(await exps(), nexp + 1);
    near(await paced(), 0.95 * limit, 1e-12, 'F holds its need again');
    assert.equal((await req(d.base, 'DELETE', F)).status, 204);

    // pace "max" is not paced (--max-busy takes turns): never refused for CPU
    const max = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 'max', until: 0.5 });
    assert.equal(max.status, 201, max.text);
    near(await paced(), 0.9 * limit, 1e-12, 'pace max holds nothing');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('paced CPU: a running session holds its measured cost times its pace; paused or deleted, nothing', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon([]);
  const paced = async () => metric(await metrics(d.base), 'convsim_paced_cpu_cores');
  try {
    const m = await metrics(d.base);
    assert.ok(metric(m, 'convsim_paced_cpu_budget_cores') > 0, 'the budget is shown');
    assert.equal(metric(m, 'convsim_paced_cpu_cores'), 0);
    const s = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1 });
    assert.equal(s.status, 201, s.text);
    const id = s.body.id, S = `/api/v1/sessions/${id}`;
    const estimate = await paced();
    // after 2 simulated s (or 50 ms of CPU) the worker's own measure
    // replaces the estimate: it matches the session's CPU per simulated s
    const measured = await until(async () => { const p = await paced(); return p !== estimate && p; },
      10000, 'the worker to measure its cost');
    const v = (await req(d.base, 'GET', S)).body;
    const mean = v.cpu_seconds / v.status.t;
    assert.ok(measured / mean > 0.5 && measured / mean < 2, `held ${measured}, used ${mean} CPU s per simulated s`);
    assert.equal((await req(d.base, 'PATCH', S, { pace: 2 })).status, 200);
    const twice = await paced();
    assert.ok(twice / measured > 1.4 && twice / measured < 2.8, `pace 2 holds about twice: ${twice} vs ${measured}`);
    assert.equal((await req(d.base, 'PATCH', S, { running: false })).status, 200);
    assert.equal(await paced(), 0, 'paused: nothing');
    assert.equal((await req(d.base, 'PATCH', S, { running: true })).status, 200);
    assert.ok(await paced() > 0, 'resumed');
    assert.equal((await req(d.base, 'DELETE', S)).status, 204);
    assert.equal(await paced(), 0, 'deleted: nothing');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('sweep points: 422 beyond the whole budget, 429 + Retry-After when queued points fill it', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--max-queued-points', '10', '--pool-threads', '1']);
  try {
    // the first sweep's points take about 0.1 s of CPU each (300 s of the machine alone), so
    // that none is done before the next request asks for room: at 2 s each, a quiet machine
    // finished two of them within the 17 ms between the requests and made room (under the
    // sanitizers, SLOW 4, a quarter as long: about 0.6 s a point there, 20 s less to wait)
    const body = (n, t_end = 2) => ({ ...NO_FEED, beta: Array.from({ length: n }, (_, i) => 10 * i), rotations: ['cw'], t_end });
    const huge = await req(d.base, 'POST', '/api/v1/sweeps', body(11));
    assert.equal(huge.status, 422, huge.text);
    assert.equal(huge.body.field, 'beta');
    assert.equal(huge.body.max, 10);
    assert.equal(huge.body.budget, 'sweep-points');
    const first = await req(d.base, 'POST', '/api/v1/sweeps', body(8, 300 / SLOW));
    assert.equal(first.status, 202, first.text);
    assert.equal(metric(await metrics(d.base), 'convsim_sweep_points_queued') <= 8, true);
    const full = await req(d.base, 'POST', '/api/v1/sweeps', body(4));
    assert.equal(full.status, 429, full.text);
    assert.match(full.headers.get('retry-after'), /^[1-9][0-9]*$/);
    assert.equal(full.body.type, '/api/v1/problems/limit-reached');
    assert.equal(full.body.budget, 'sweep-points');
    assert.equal(full.body.limit, 10);
    assert.match(full.body.detail, /--max-queued-points/);
    const list = (await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps;
    assert.equal(list.length, 1, 'nothing was created');
    await healthy(d.base);
    await until(async () => (await req(d.base, 'GET', `/api/v1/sweeps/${first.body.id}`)).body.state === 'done',
      40000, 'the first sweep to finish');
    assert.equal(metric(await metrics(d.base), 'convsim_sweep_points_queued'), 0);
    const later = await req(d.base, 'POST', '/api/v1/sweeps', body(4));
    assert.equal(later.status, 202, later.text);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

// A stream of path from localAddress, kept open: .beats counts its
// heartbeats, .closed says whether the daemon ended it; close() ends it.
function streamFrom(base, path, localAddress) {
  return new Promise((resolve, reject) => {
    const r = http.get(base + path, { localAddress, agent: false }, (res) => {
      const st = { status: res.statusCode, beats: 0, closed: false, close: () => r.destroy() };
      res.setEncoding('utf8');
      res.on('data', (c) => { st.beats += (c.match(/"heartbeat"/g) || []).length; });
      res.on('close', () => { st.closed = true; });
      resolve(st);
    });
    r.on('error', reject);
  });
}

test('connections: beyond its budget a client\'s own least active connection is closed; 429 only while all its others are answered, then closed at once; streams outlive the idle timeout', { timeout: 60000 * SLOW }, async () => {
  const cap = 3;
  const d = await startDaemon(['--max-client-connections', String(cap), '--connection-timeout', '2',
    '--heartbeat', '0.5']);
  const socks = [];
  const streams = [];
  try {
    // cap idle sockets: one more connection closes the oldest of them (not
    // another address's, not a newer one) and is answered
    const idle = await idleSockets(d.port, cap, '127.0.0.2');
    socks.push(...idle);
    for (const k of idle) k.closedAt.then(() => { k.gone = true; });
    await sleep(100);
    const served = await getFrom(d.base, '/api/v1/health', '127.0.0.2');
    assert.equal(served.status, 200, JSON.stringify(served));
    await sleep(200);
    assert.deepEqual(idle.map((k) => !!k.gone), [true, false, false], 'the oldest idle socket was closed');
    assert.ok(metric(await metrics(d.base), 'convsim_connections_evicted_total') >= 1);
    for (const k of idle) k.destroy();
    await sleep(100);

    // cap streams (being answered): nothing of the address can be closed,
    // so the next connection is over its budget: 429 with a body
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1 });
    assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${s.body.id}`, { running: false })).status, 200);
    for (let i = 0; i < cap; i++) {
      streams.push(await streamFrom(d.base, `/api/v1/sessions/${s.body.id}/stream?format=ndjson`, '127.0.0.2'));
      assert.equal(streams[i].status, 200);
    }
    const over = await getFrom(d.base, '/api/v1/health', '127.0.0.2');
    assert.equal(over.status, 429, JSON.stringify(over));
    assert.equal(over.headers['retry-after'], '1');
    assert.equal(over.headers.connection, 'close');
    assert.equal(over.headers['content-type'], 'application/problem+json');
    assert.equal(over.body.type, '/api/v1/problems/limit-reached');
    assert.equal(over.body.budget, 'connections');
    assert.equal(over.body.limit, cap);
    assert.match(over.body.detail, /more than 3 connections open.*--max-client-connections.*every other one is being answered/);
    // a POST beyond the budget creates nothing
    const post = await new Promise((resolve) => {
      const r = http.request(d.base + '/api/v1/sessions', { method: 'POST', localAddress: '127.0.0.2',
        agent: false, headers: JSON_HEADERS }, (res) => { res.resume(); res.on('end', () => resolve(res.statusCode)); });
      r.on('error', (e) => resolve(e.code));
      r.end('{}');
    });
    assert.equal(post, 429);
    assert.equal(metric(await metrics(d.base), 'convsim_sessions'), 1);
    // another client address is served
    await healthy(d.base);
    // beyond the grace (8 more waiting for their 429), the next is closed at once
    socks.push(...await idleSockets(d.port, 8, '127.0.0.2'));
    await sleep(100);
    const dropped = await getFrom(d.base, '/api/v1/health', '127.0.0.2');
    assert.ok(dropped.error, `closed without an answer: ${JSON.stringify(dropped)}`);
    assert.ok(metric(await metrics(d.base), 'convsim_connections_dropped_total') >= 1);
    await healthy(d.base);

    // the streams of the paused session (heartbeats only) outlive the 2-s
    // idle timeout, while the idle sockets are closed by it
    const t0 = Date.now();
    const beats0 = streams.map((k) => k.beats);
    await sleep(4000);
    streams.forEach((k, i) => {
      assert.ok(!k.closed, `stream ${i} stayed open`);
      assert.ok(k.beats - beats0[i] >= 5, `stream ${i}: ${k.beats - beats0[i]} heartbeats`);
    });
    const when = await Promise.all(socks.slice(cap).map((k) => k.closedAt));
    assert.ok(when.every((t) => t - t0 < 4000 * SLOW), 'idle sockets were closed by --connection-timeout');
    // closed by the client: the daemon sees it at its next heartbeat
    for (const k of streams) k.close();
    await until(async () => (await getFrom(d.base, '/api/v1/health', '127.0.0.2')).status === 200,
      5000, 'the client served again once its streams are gone');
  } finally {
    for (const k of streams) k.close();
    for (const k of socks) k.destroy();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('--help prints every budget with its default; a timeout not above the heartbeat is refused', async () => {
  const { spawnSync } = await import('node:child_process');
  const { BIN } = await import('./lib.mjs');
  const h = spawnSync(BIN, ['--help'], { encoding: 'utf8' });
  assert.equal(h.status, 0);
  for (const re of [/--max-memory BYTES .*\n.*default [0-9.]+ GiB: 3\/4 of this machine's memory/,
    /--max-cpu-seconds S .*\n.*default 1800/, /--max-busy N .*default \d+: the cores/,
    /--max-paced-cores C .*\n.*default [0-9.]+: half the cores/,
    /--max-client-connections N .*default 64/, /--max-connections N .*default 1024/,
    /--connection-timeout S .*\n.*default 30/, /--max-queued-points N .*default 4096/]) {
    assert.match(h.stdout, re);
  }
  const bad = spawnSync(BIN, ['--port', '0', '--heartbeat', '30', '--connection-timeout', '20'], { encoding: 'utf8' });
  assert.equal(bad.status, 2);
  assert.match(bad.stderr, /--connection-timeout \(20 s\) must exceed --heartbeat \(30 s\)/);
});
