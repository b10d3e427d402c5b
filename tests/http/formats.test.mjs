// SPDX-License-Identifier: GPL-3.0-or-later
// One content negotiation for every result route: JSON and CSV by Accept
// or ?format=, 406 for an Accept naming neither, 400 for unknown query
// parameters on every route; the trajectory's rows exactly `stride` apart;
// the CLI and the daemon write the same trajectory and sweep columns and
// the same numbers; beta in mid-ramp with 15 significant digits at most;
// every problem type URI serves a page.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, SLOW, CHEAP, CLI } from './lib.mjs';

let d, sid, eid, wid;

before(async () => {
  d = await startDaemon();
  const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 1 });
  assert.equal(s.status, 201);
  sid = s.body.id;
  const e = await req(d.base, 'POST', '/api/v1/experiments', {
    session: { ...CHEAP }, schedule: [{ beta: 38, until: 0.5 }, { beta: 128, until: 1 }] });
  assert.equal(e.status, 201, e.text);
  eid = e.body.id;
  const w = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, beta: [30, 60], rotations: ['cw'], t_end: 0.5 });
  assert.equal(w.status, 202, w.text);
  wid = w.body.id;
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${sid}`)).body.state === 'finished', 30000 * SLOW, 'session');
  await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${eid}`)).body.state === 'done', 30000 * SLOW, 'experiment');
  await until(async () => (await req(d.base, 'GET', `/api/v1/sweeps/${wid}`)).body.state === 'done', 30000 * SLOW, 'sweep');
});
after(async () => { await d?.stop(); });

const results = () => [
  ['/api/v1/sessions', 'id,state,t,beta'],
  [`/api/v1/sessions/${sid}`, 'id,state,t,beta'],
  [`/api/v1/sessions/${sid}/trajectory`, 't,beta,beta_target,x,y'],
  ['/api/v1/experiments', 'experiment,session,segment,beta,until'],
  [`/api/v1/experiments/${eid}`, 'experiment,session,segment,beta,until'],
  ['/api/v1/sweeps', 'sweep,state,done,total,t_end'],
  [`/api/v1/sweeps/${wid}`, 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked'],
];

test('every result route answers JSON or CSV, by Accept and by ?format=', async () => {
  for (const [path, head] of results()) {
    const j = await req(d.base, 'GET', path);
    assert.equal(j.headers.get('content-type'), 'application/json', path);
    assert.ok(j.body && typeof j.body === 'object', path);
    const sep = path.includes('?') ? '&' : '?';
    for (const c of [await req(d.base, 'GET', path, undefined, { Accept: 'text/csv' }),
      await req(d.base, 'GET', `${path}${sep}format=csv`),
      await req(d.base, 'GET', path, undefined, { Accept: 'application/json;q=0.5, text/csv' })]) {
      assert.equal(c.status, 200, path);
      assert.equal(c.headers.get('content-type'), 'text/csv', path);
      assert.ok(c.text.startsWith(head), `${path}: ${c.text.slice(0, 80)}`);
      const lines = c.text.trim().split('\n');
      assert.ok(lines.length >= 2, `${path} has rows`);
      const width = lines[0].split(',').length;
      for (const l of lines) assert.equal(l.split(',').length, width, `${path}: ${l}`);
    }
    const j2 = await req(d.base, 'GET', path, undefined, { Accept: 'text/csv;q=0.1, application/json' });
    assert.equal(j2.headers.get('content-type'), 'application/json', path);
    const bad = await req(d.base, 'GET', path, undefined, { Accept: 'application/xml' });
    assert.equal(bad.status, 406, path);
    assert.equal(bad.body.type, '/api/v1/problems/not-acceptable');
    const fmt = await req(d.base, 'GET', `${path}${sep}format=xml`);
    assert.equal(fmt.status, 400, path);
  }
  // the experiment's CSV carries its segments' numbers exactly
  const e = (await req(d.base, 'GET', `/api/v1/experiments/${eid}`)).body;
  const rows = (await req(d.base, 'GET', `/api/v1/experiments/${eid}?format=csv`)).text.trim().split('\n');
  const head = rows[0].split(',');
  assert.equal(rows.length, 1 + e.segments.length);
  e.segments.forEach((g, k) => {
    const cell = (name) => rows[k + 1].split(',')[head.indexOf(name)];
    assert.equal(cell('beta'), String(g.beta));
    assert.equal(Number(cell('mean_velocity')), g.mean_velocity);
    assert.equal(cell('steady'), String(g.steady));
  });
});

test('unknown query parameters are a 400 naming the ones the route takes', async () => {
  const cases = [
    [`/api/v1/sessions/${sid}/trajectory?fromm=1`, 'fromm', /did you mean "from"/],
    ['/api/v1/sessions?limit=3', 'limit', /takes format/],
    ['/api/v1/presets?format=csv', 'format', /takes none/],
    [`/api/v1/sweeps/${wid}?formta=csv`, 'formta', /did you mean "format"/],
    [`/api/v1/sessions/${sid}/stream?limt=1`, 'limt', /did you mean "limit"/],
  ];
  for (const [path, field, detail] of cases) {
    const r = await req(d.base, 'GET', path);
    assert.equal(r.status, 400, path);
    assert.equal(r.body.type, '/api/v1/problems/bad-query');
    assert.equal(r.body.field, field);
    assert.match(r.body.detail, detail);
  }
});

test('trajectory rows lie exactly `stride` apart, also for a coarser ?stride=', async () => {
  const j = (await req(d.base, 'GET', `/api/v1/sessions/${sid}/trajectory`)).body;
  const t = j.rows.map((r) => r[0]);
  assert.ok(t.length > 50);
  for (let i = 1; i < t.length; i++) assert.ok(Math.abs(t[i] - t[i - 1] - j.stride) < 1e-9, `${t[i - 1]} -> ${t[i]}, stride ${j.stride}`);
  const k = (await req(d.base, 'GET', `/api/v1/sessions/${sid}/trajectory?stride=${3 * j.stride}`)).body;
  assert.equal(k.stride, Math.round(3 * j.stride * 1e9) / 1e9); // a time: to the nanosecond
  for (let i = 1; i < k.rows.length; i++) assert.ok(Math.abs(k.rows[i][0] - k.rows[i - 1][0] - k.stride) < 1e-9);
  const bad = await req(d.base, 'GET', `/api/v1/sessions/${sid}/trajectory?stride=${j.stride * 1.5}`);
  assert.equal(bad.status, 400);
  assert.match(bad.body.detail, /multiple of the recorded spacing/);
  assert.equal(j.fields.length, j.units.length);
});

test('the CLI writes the daemon\'s trajectory and sweep columns and its numbers', async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-'));
  const out = join(dir, 'traj.csv');
  const summary = JSON.parse(execFileSync(CLI, ['run', '--duration', '0.05', '--set', 'drive=ideal',
    '--set', 'columns=1', '--set', 'layers=2', '--out', out, '-q']).toString());
  const cliHead = readFileSync(out, 'utf8').split('\n')[0];
  const daemonHead = (await req(d.base, 'GET', `/api/v1/sessions/${sid}/trajectory?format=csv`)).text.split('\n')[0];
  assert.equal(cliHead, daemonHead);
  assert.equal(summary.integrator.rtol, 1e-6);
  assert.match(execFileSync(CLI, ['run', '--duration', '0.01', '-q']).toString(), /"rtol": 1e-06,/);
  const sweep = execFileSync(CLI, ['sweep', '--beta', '30', '--rotation', 'cw', '--duration', '0.5',
    '--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '-q']).toString().trim().split('\n');
  const daemon = (await req(d.base, 'GET', `/api/v1/sweeps/${wid}?format=csv`)).text.trim().split('\n');
  assert.equal(sweep[0], daemon[0]);
  // the same point, measured by both, printed alike (the same double)
  assert.equal(sweep[1], daemon[1]);
});

test('each problem type URI serves a page that explains it', async () => {
  const r = await req(d.base, 'GET', '/api/v1/sessions/nope');
  assert.equal(r.status, 404);
  const page = await req(d.base, 'GET', r.body.type);
  assert.equal(page.status, 200);
  assert.match(page.headers.get('content-type'), /^text\/html/);
  assert.match(page.text, /No session, experiment, sweep/);
  for (const slug of ['malformed-json', 'wrong-type', 'bad-query', 'not-found', 'method-not-allowed',
    'not-acceptable', 'conflict', 'body-too-large', 'unsupported-media-type', 'out-of-range',
    'unknown-field', 'invalid-value', 'limit-reached', 'unavailable']) {
    const p = await req(d.base, 'GET', `/api/v1/problems/${slug}`);
    assert.equal(p.status, 200, slug);
    assert.ok(page.text.includes(`href="${slug}"`), slug);
    /* rendered: the explanation's code spans are <code>, no raw backticks */
    assert.doesNotMatch(p.text, /`/, slug);
  }
  const range = await req(d.base, 'GET', '/api/v1/problems/out-of-range');
  assert.match(range.text, /<code>field<\/code> names it/);
  assert.equal((await req(d.base, 'GET', '/api/v1/problems/nonsense')).status, 404);
});

test('numbers as the user gave them: beta in degrees as sent, times on the grid as k dt', async () => {
  const r = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, params: { beta: 121.9 }, pace: 'max', until: 0.5 });
  assert.equal(r.status, 201, r.text);
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}`)).body.state === 'finished', 30000);
  const s = await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}`);
  /* the text, not only the value: 121.9, never 121.89999999999999 */
  assert.match(s.text, /"beta":121\.9[,}]/);
  assert.match(s.text, /"beta_target":121\.9[,}]/);
  assert.match(s.text, /"t":0\.5[,}]/);
  const csv = (await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}/trajectory?format=csv`)).text.trim().split('\n');
  for (const line of csv.slice(1)) {
    const [t, beta, target] = line.split(',');
    assert.equal(beta, '121.9', line);
    assert.equal(target, '121.9', line);
    assert.match(t, /^\d+(\.\d{1,9})?$/, `t on the grid: ${line}`);
  }
  const e = await req(d.base, 'POST', '/api/v1/experiments', { session: CHEAP, schedule: [{ beta: 38, until: 0.6 }, { beta: 128, until: 1.2 }],
    keep_session: true });
  assert.equal(e.status, 201, e.text);
  await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${e.body.id}`)).body.state === 'done', 60000);
  /* beta in mid-ramp, which the model made: 15 significant digits at most
   * (31.4878125, never 31.487812499999997), in the trajectory's CSV */
  const sess = (await req(d.base, 'GET', `/api/v1/experiments/${e.body.id}`)).body.session;
  const traj = (await req(d.base, 'GET', `/api/v1/sessions/${sess}/trajectory?format=csv`)).text.trim().split('\n').slice(1);
  const ramp = traj.map((l) => l.split(',')[1]).filter((b) => b !== '38' && b !== '128');
  assert.ok(ramp.length >= 5, `rows in mid-ramp: ${ramp.length}`);
  for (const b of ramp) assert.ok(b.replace(/^-?0*\.?0*/, '').replace('.', '').length <= 15, `beta ${b}`);
  const rows = (await req(d.base, 'GET', `/api/v1/experiments/${e.body.id}?format=csv`)).text.trim().split('\n').slice(1);
  assert.equal(rows.length, 2);
  for (const row of rows) {
    const c = row.split(',');
    for (const k of [6, 7, 13]) assert.match(c[k], /^(|\d+(\.\d{1,9})?)$/, `column ${k} of ${row}`);
  }
  assert.ok(rows[1].split(',')[13] !== '', 'the beta change has its reversal time');
});

test('stream records carry times on the sample grid as k dt, in NDJSON and SSE', async () => {
  /* 250 samples a second: every sample's t is a multiple of 0.004 s and reads so
   * (16.016, never 16.016000000000002), as do the events' and heartbeats' */
  const r = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 20, sample_rate: 250 });
  assert.equal(r.status, 201, r.text);
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}`)).body.state === 'finished', 60000 * SLOW);
  await req(d.base, 'PATCH', `/api/v1/sessions/${r.body.id}`, { beta: 128, until: 21 });
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${r.body.id}`)).body.state === 'finished', 60000 * SLOW);
  for (const [format, pattern] of [['ndjson', /"t":([^,}]+)/], ['sse', /"t":([^,}]+)/]]) {
    const text = await (await fetch(`${d.base}/api/v1/sessions/${r.body.id}/stream?format=${format}&since=0&limit=6000`)).text();
    let samples = 0;
    for (const line of text.split('\n')) {
      const m = line.match(pattern);
      if (!m) continue;
      const t = m[1];
      assert.match(t, /^\d+(\.\d{1,9})?$/, `${format}: t as k dt: ${line.slice(0, 120)}`);
      if (/"type":"sample"|^data: \{"t"/.test(line)) {
        samples++;
        assert.equal(Number(t), Math.round(Number(t) * 250) / 250, `${format}: t on the 250 Hz grid: ${t}`);
      }
    }
    assert.ok(samples > 4000, `${format}: ${samples} samples read`);
  }
});
