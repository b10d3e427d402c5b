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

test('cpu_budget: every refusal names one range, [0.001, --max-cpu-seconds], and changes nothing', async () => {
  const spec = (await req(d.base, 'GET', '/api/v1/openapi.json')).body;
  const schema = spec.components.schemas.Control.properties.cpu_budget;
  const before = (await req(d.base, 'GET', path)).body;
  for (const v of [0, -1, 0.0005, 1e-300, 300.5, 1e9, 1e10, '1e309']) {
    const body = typeof v === 'string' ? `{"cpu_budget":${v}}` : { cpu_budget: v };
    const r = await req(d.base, 'PATCH', path, body);
    assert.equal(r.status, 422, `${v}: ${r.text}`);
    assert.equal(r.body.type, '/api/v1/problems/out-of-range', r.text);
    assert.equal(r.body.field, 'cpu_budget', r.text);
    assert.equal(r.body.min, 0.001, `${v}: ${r.text}`);
    assert.equal(r.body.max, 300, `${v}: ${r.text}`);
    assert.match(r.body.detail, /\[0\.001, 300\]/, r.text);
  }
  assert.equal(schema.minimum, 0.001, JSON.stringify(schema));
  assert.equal(schema.exclusiveMinimum, undefined, JSON.stringify(schema));
  for (const v of [0.001, 300]) {
    const r = await req(d.base, 'PATCH', path, { cpu_budget: v });
    assert.equal(r.status, 200, `${v}: ${r.text}`);
  }
  const now = (await req(d.base, 'GET', path)).body;
  assert.equal(now.state, before.state);
});

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

test('trajectory: a stride a hair off a whole multiple gives that multiple\'s rows, and says so', async () => {
  const all = (await req(d.base, 'GET', `${path}/trajectory`)).body;
  const exact = (await req(d.base, 'GET', `${path}/trajectory?stride=${2 * all.stride}`)).body;
  assert.ok(exact.count > 50, `${exact.count} rows`);
  // as a stride rounded in a spreadsheet or typed from a plot reads:
  // within a millionth of 2 x recorded, so taken as that multiple
  for (const off of [1 + 4e-7, 1 - 4e-7]) {
    const asked = 2 * all.stride * off;
    const r = await req(d.base, 'GET', `${path}/trajectory?stride=${asked}`);
    assert.equal(r.status, 200, r.text);
    assert.equal(r.body.stride, 2 * all.stride, `asked ${asked}`);
    assert.equal(r.body.count, exact.count, `asked ${asked}: rows ${r.body.rows.map((row) => row[0]).slice(-3)}`);
    assert.deepEqual(r.body.rows, exact.rows);
  }
  const csv = await req(d.base, 'GET', `${path}/trajectory?format=csv&stride=${2 * all.stride * (1 + 4e-7)}`);
  assert.equal(csv.text.trim().split('\n').length, exact.count + 1);
  // further off, still a 400 that names the recorded spacing
  const bad = await req(d.base, 'GET', `${path}/trajectory?stride=${2 * all.stride * (1 + 1e-4)}`);
  assert.equal(bad.status, 400, bad.text);
  assert.equal(bad.body.field, 'stride');
  assert.equal(bad.body.detail, `stride must be a whole multiple of the recorded spacing, now ${all.stride} s (got ${2 * all.stride * (1 + 1e-4)})`);
});

test('a query parameter without a value or given twice is 400 naming it, never read as absent or as its first', async () => {
  for (const [q, field] of [
    ['/api/v1/sessions?format', 'format'],
    ['/api/v1/sessions?format=csv&format=json', 'format'],
    ['/api/v1/sessions?scope=local&format=json&scope=all', 'scope'],
    [`${path}?format`, 'format'],
    [`${path}/trajectory?from=1&from=2`, 'from'],
    [`${path}/trajectory?stride`, 'stride'],
    [`${path}/stream?limit`, 'limit'],
    [`${path}/stream?limit=1&since=0&limit=5`, 'limit'],
  ]) {
    const r = await req(d.base, 'GET', q);
    assert.equal(r.status, 400, `${q}: ${r.text}`);
    assert.equal(r.body.type, '/api/v1/problems/bad-query', r.text);
    assert.equal(r.body.field, field, r.text);
  }
  const ok = await req(d.base, 'GET', '/api/v1/sessions?format=csv&scope=local');
  assert.equal(ok.status, 200, ok.text);
});

test('a number in a query is decimal: hexadecimal, inf and nan are 400 naming the parameter; the stream\'s rate has its maximum in the OpenAPI document', async () => {
  for (const [q, field] of [
    [`${path}/trajectory?from=0x10`, 'from'],
    [`${path}/trajectory?to=inf`, 'to'],
    [`${path}/trajectory?stride=nan`, 'stride'],
    [`${path}/trajectory?from=1%20`, 'from'],
    [`${path}/stream?rate=0x10`, 'rate'],
    [`${path}/stream?rate=100001`, 'rate'],
    [`${path}/stream?rate=1e`, 'rate'],
    [`${path}/trajectory?stride=0x1`, 'stride'],
    [`${path}/trajectory?stride=%201`, 'stride'],
    [`${path}/stream?since=0x10`, 'since'],
    [`${path}/stream?limit=0x1`, 'limit'],
  ]) {
    const r = await req(d.base, 'GET', q);
    assert.equal(r.status, 400, `${q}: ${r.text}`);
    assert.equal(r.body.type, '/api/v1/problems/bad-query', r.text);
    assert.equal(r.body.field, field, r.text);
  }
  const ok = await req(d.base, 'GET', `${path}/trajectory?from=1.5e0&to=%2B2`);
  assert.equal(ok.status, 200, ok.text);
  assert.ok(ok.body.rows.every((row) => row[0] >= 1.5 && row[0] <= 2), ok.text.slice(0, 200));
  const spec = (await req(d.base, 'GET', '/api/v1/openapi.json')).body;
  const rate = Object.values(spec.paths).flatMap((m) => Object.values(m)).flatMap((o) => o.parameters ?? [])
    .find((prm) => prm.name === 'rate');
  assert.equal(rate.schema.maximum, 100000, JSON.stringify(rate));
});

test('a dimensionless setting\'s range is named without a unit; one with a unit keeps it', async () => {
  const mu = await req(d.base, 'PATCH', path, { mu: 5 });
  assert.equal(mu.status, 422, mu.text);
  assert.equal(mu.body.field, 'mu', mu.text);
  assert.match(mu.body.detail, /mu must be a finite number in \[0, 2\]$/, mu.text);
  const beta = await req(d.base, 'PATCH', path, { beta: 200 });
  assert.equal(beta.status, 422, beta.text);
  assert.match(beta.body.detail, /in \[0, 180\] deg$/, beta.text);
});

test('a session no real-time pace can hold is told to run at pace "max", never given a range with max below min', async () => {
  // 2,500 CPU s a simulated s: a sample (1e-4 s) within a second of CPU, no pace from 0.001 within
  // one core; start "rest": nothing to settle, so only the pace is in question
  const slow = { scene: { ...CHEAP.scene, start: 'rest' }, integrator: { dt: 2e-10 }, sample_rate: 10000 };
  const c = await req(d.base, 'POST', '/api/v1/sessions', { ...slow, pace: 0.001 });
  assert.equal(c.status, 422, c.text);
  assert.equal(c.body.field, 'pace', c.text);
  assert.equal(c.body.budget, 'cpu', c.text);
  assert.ok(!('max' in c.body) || c.body.max >= c.body.min, c.text);
  assert.match(c.body.detail, /pace "max"/, c.text);
  // the same session at pace "max" is not held by that budget; a PATCH to a pace is refused alike
  const m = await req(d.base, 'POST', '/api/v1/sessions', { ...slow, pace: 'max', until: 1e-4 });
  assert.equal(m.status, 201, m.text);
  const path = `/api/v1/sessions/${m.body.id}`;
  await until(async () => (await req(d.base, 'GET', path)).body.state === 'finished', 30000 * SLOW, 'finish');
  const p = await req(d.base, 'PATCH', path, { pace: 1, until: 1 });
  assert.equal(p.status, 422, p.text);
  assert.ok(!('max' in p.body) || p.body.max >= p.body.min, p.text);
  assert.match(p.body.detail, /pace "max"/, p.text);
  assert.equal((await req(d.base, 'GET', path)).body.pace, 'max');
  assert.equal((await req(d.base, 'DELETE', path)).status, 204);
});

test('a session whose sample or steady start would outlast what a worker can interrupt is refused at once, at any pace', { timeout: 30000 * SLOW }, async () => {
  const count = async () => (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length;
  const before = await count();
  const tiny = { ...CHEAP, integrator: { dt: 1e-12 } };
  for (const [url, body, field] of [
    ['/api/v1/sessions', { ...tiny, pace: 'max' }, /^integrator\.dt$/],
    ['/api/v1/sessions', { ...tiny, scene: { ...CHEAP.scene, start: 'rest' }, pace: 'max', until: 1 }, /^integrator\.dt$/],
    ['/api/v1/experiments', { session: tiny, schedule: [{ beta: 38, until: 1 }] }, /integrator\.dt$/],
    ['/api/v1/sessions', { scene: { ...CHEAP.scene, settle: 10 }, integrator: { dt: 1e-8 }, pace: 'max' }, /^scene\.settle$/],
    // a 1-g eliminator on a 1e6 N s/m damper (|lambda| 1e9 1/s): no step
    // is both stable (2.6e-9 s) and long enough, so the remedy named is
    // more samples a simulated second (each interval shorter)
    ['/api/v1/sessions', { params: { b_s2: 1e6, m2: 0.001 }, pace: 'max' }, /^sample_rate$/],
  ]) {
    const t0 = Date.now();
    const r = await req(d.base, 'POST', url, body);
    assert.ok(Date.now() - t0 < 5000 * SLOW, `answered after ${Date.now() - t0} ms`);
    assert.equal(r.status, 422, r.text);
    assert.equal(r.body.type, '/api/v1/problems/out-of-range', r.text);
    assert.match(r.body.field, field, r.text);
    assert.equal(r.body.budget, 'cpu', r.text);
    assert.ok(r.body.min < r.body.max, r.text);
    if (r.body.field === 'sample_rate') {
      assert.equal(r.body.max, 10000);
      assert.ok(r.body.min > 250, r.text);
      assert.match(r.body.detail, /no stable step is long enough \(integrator\.dt [0-9.e-]+ s needed, this machine's bound 2\.6e-09 s\); nothing was created: a sample_rate of at least/);
    }
  }
  assert.equal(await count(), before);
});

test('a sweep or fit whose one run would outlast --max-cpu-seconds is refused whole at once; nothing is started', { timeout: 30000 * SLOW }, async () => {
  const count = async (kind) => (await req(d.base, 'GET', `/api/v1/${kind}`)).body[kind].length;
  const before = [await count('sweeps'), await count('fits')];
  const one = { beta: [30], rotations: ['cw'] };
  const peaks = { free: ['e'], peaks: [{ rotation: 'cw', beta: 38 }, { rotation: 'cw', beta: 128 }] };
  for (const [url, body, field] of [
    ['/api/v1/sweeps', { ...CHEAP, integrator: { dt: 1e-12 }, ...one, t_end: 1 }, 'integrator.dt'],
    ['/api/v1/sweeps', { ...CHEAP, integrator: { dt: 1e-8 }, ...one, t_end: 100 }, 't_end'],
    ['/api/v1/sweeps', { ...CHEAP, vary: { dt: [1e-3, 1e-12] }, rotations: ['cw'], t_end: 1 }, 'integrator.dt'],
    ['/api/v1/fits', { ...CHEAP, integrator: { dt: 1e-12 }, ...peaks, t_end: 1 }, 'integrator.dt'],
  ]) {
    const t0 = Date.now();
    const r = await req(d.base, 'POST', url, body);
    assert.ok(Date.now() - t0 < 5000 * SLOW, `answered after ${Date.now() - t0} ms`);
    assert.equal(r.status, 422, r.text);
    assert.equal(r.body.type, '/api/v1/problems/out-of-range', r.text);
    assert.equal(r.body.field, field, r.text);
    assert.equal(r.body.budget, 'cpu', r.text);
    assert.ok(r.body.min < r.body.max, r.text);
  }
  assert.deepEqual([await count('sweeps'), await count('fits')], before);
  // within the bound: accepted as before
  const ok = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, ...one, t_end: 0.5 });
  assert.equal(ok.status, 202, ok.text);
});
