// SPDX-License-Identifier: GPL-3.0-or-later
// The model error in the daemon (docs/dem.md "Model error"): a session's
// status, the stream's hello and every control event carry model_error,
// model_error_uncertainty, model_checked and model_check_note for the scene
// as its controls stand, recomputed on each control; the expected values
// are the DEM map's (tests/bench/results/model_check.csv: |v_column -
// v_DEM| plus the DEM's seed spread at a map point).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { startDaemon, req, streamUntil, until, SLOW } from './lib.mjs';

// The map's rows for liggghts-bed4 (4 layers), by "beta,rotation".
const MAP = (() => {
  const [head, ...rows] = readFileSync(new URL('../bench/results/model_check.csv', import.meta.url), 'utf8')
    .trim().split('\n');
  const c = Object.fromEntries(head.split(',').map((n, i) => [n, i]));
  const m = {};
  for (const r of rows.map((l) => l.split(','))) {
    if (r[c.preset] !== 'liggghts-bed4') continue;
    m[`${Number(r[c.beta_deg])},${r[c.rotation]}`] =
      Math.abs(Number(r[c.v_column]) - Number(r[c.v_dem])) + Number(r[c.v_dem_sd]);
  }
  return m;
})();

// A CSV answer's rows as objects by column name; a JSON number as its cell.
async function csvRows(path) {
  const r = await req(d.base, 'GET', path);
  assert.equal(r.status, 200, r.text);
  const [head, ...rows] = r.text.trim().split('\n').map((l) => l.split(','));
  return rows.map((cells) => Object.fromEntries(head.map((n, i) => [n, cells[i]])));
}
const cell = (x) => (x === null ? '' : String(x));

let d;
before(async () => { d = await startDaemon(); });
after(async () => { await d.stop(); });

test('model_error: the calibrated bed moved from 30 to 150 deg cw takes the map\'s value there, then is not checked at 170', { timeout: 30000 * SLOW }, async () => {
  assert.ok(MAP['30,cw'] > 0 && MAP['150,cw'] > MAP['30,cw'], 'the map has the two points');
  const a = await req(d.base, 'POST', '/api/v1/sessions',
    { preset: 'liggghts-bed4', params: { beta: 30 }, pace: 1 });
  assert.equal(a.status, 201);
  const id = a.body.id;
  let st = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.status;
  assert.equal(st.model_checked, true);
  assert.ok(Math.abs(st.model_error - MAP['30,cw']) < 1e-12, `${st.model_error} at 30 deg cw, the map's ${MAP['30,cw']}`);
  assert.ok(st.model_error_uncertainty > 0);
  assert.match(st.model_check_note, /^DEM check: within ±0\.003 m\/s here/);
  assert.equal(st.feed_warning, null);
  const h0 = await streamUntil(d.base, id, (r) => r.type === 'hello' && r);
  assert.equal(h0.model_error, st.model_error);

  // the stream, open before the control, carries the new value in the control's record
  const control = streamUntil(d.base, id, (r) => r.type === 'control' && r.beta === 150 && r);
  await new Promise((r) => setTimeout(r, 300));
  const p = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 150 });
  assert.equal(p.status, 200);
  assert.ok(Math.abs(p.body.status.model_error - MAP['150,cw']) < 1e-12,
    `the PATCH answer: ${p.body.status.model_error}, the map's ${MAP['150,cw']} at 150 deg cw`);
  st = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.status;
  assert.equal(st.model_checked, true);
  assert.ok(Math.abs(st.model_error - MAP['150,cw']) < 1e-12, `${st.model_error} at 150 deg cw`);
  assert.match(st.model_check_note, /^DEM check: within ±0\.008 m\/s here/);
  const ev = await control;
  assert.equal(ev.model_checked, true);
  assert.ok(Math.abs(ev.model_error - MAP['150,cw']) < 1e-12, `the control record: ${ev.model_error}`);
  // a stream opened after the control starts from the new value
  const h1 = await streamUntil(d.base, id, (r) => r.type === 'hello' && r);
  assert.equal(h1.model_error, st.model_error);

  // beyond the measured angles: not checked, the note names the range
  const q = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 170 });
  assert.equal(q.status, 200);
  st = q.body.status;
  assert.equal(st.model_checked, false);
  assert.equal(st.model_error, null);
  assert.equal(st.model_error_uncertainty, null);
  assert.equal(st.model_check_note,
    'not checked against DEM at beta 170 deg cw: checked 15-165 deg cw (4 layers, liggghts-bed4)');
  assert.equal(st.feed_warning, st.model_check_note);
  // the sense is a control too: 30 deg ccw is a map point
  const r = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 30, rotation: 'ccw' });
  assert.equal(r.status, 200);
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.status.rotation === 'ccw', 5000 * SLOW, 'ccw');
  st = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.status;
  assert.ok(Math.abs(st.model_error - MAP['30,ccw']) < 1e-12, `${st.model_error} at 30 deg ccw`);
  // and the drive: another synchronous speed is not the map's machine
  const w = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { omega_ss: 140 });
  assert.equal(w.status, 200);
  assert.equal(w.body.status.model_checked, false);
  assert.match(w.body.status.model_check_note, /^not checked against DEM at omega_ss = 140 rad\/s/);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${id}`)).status, 204);
});

// The preset as it is against the map's beds of a depth, at (beta, sense)
// in the table: each material's |v_column - v_DEM| + sd, largest first.
function presetErrors(layers, beta, rotation) {
  const [head, ...rows] = readFileSync(new URL('../bench/results/model_check.csv', import.meta.url), 'utf8')
    .trim().split('\n');
  const c = Object.fromEntries(head.split(',').map((n, i) => [n, i]));
  return rows.map((l) => l.split(',')).filter((r) => r[c.preset] === 'czubak2016' && r[c.settings] === '' &&
    Number(r[c.layers]) === layers && Number(r[c.beta_deg]) === beta && r[c.rotation] === rotation)
    .map((r) => ({ material: r[c.material],
      err: Math.abs(Number(r[c.v_column]) - Number(r[c.v_dem])) + Number(r[c.v_dem_sd]) }))
    .sort((a, b) => b.err - a.err);
}

test('model_error: a default 2-layer session moved from 30 to 150 deg takes the map\'s value there against each material; another depth names the nearest', { timeout: 20000 * SLOW }, async () => {
  const a = await req(d.base, 'POST', '/api/v1/sessions', { params: { beta: 30 }, scene: { layers: 2 }, pace: 1 });
  assert.equal(a.status, 201);
  const note = (e) => `DEM check: within ±${e[0].err.toFixed(3)} m/s here (czubak2016 against ${e[0].material}, 2 layers` +
    e.slice(1).map((x) => `; against ${x.material} ±${x.err.toFixed(3)}`).join('') + ')';
  for (const beta of [30, 150]) {
    const e = presetErrors(2, beta, 'cw');
    assert.deepEqual(e.map((x) => x.material).sort(), ['glass', 'wheat'], `both materials at ${beta} deg`);
    const st = beta === 30 ? (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body.status
      : (await req(d.base, 'PATCH', `/api/v1/sessions/${a.body.id}`, { beta })).body.status;
    assert.equal(st.model_checked, true, `${beta} deg`);
    assert.ok(Math.abs(st.model_error - e[0].err) < 1e-12, `${st.model_error} at ${beta} deg, the map's ${e[0].err}`);
    assert.equal(st.model_check_note, note(e));
    assert.equal(st.feed_warning, null);
  }
  // a depth the map has not: the nearest depth's bed, in one sentence
  const b = await req(d.base, 'POST', '/api/v1/sessions', { scene: { layers: 3 }, pace: 1 });
  assert.equal(b.status, 201);
  const sb = (await req(d.base, 'GET', `/api/v1/sessions/${b.body.id}`)).body.status;
  assert.equal(sb.model_checked, false);
  assert.equal(sb.model_error, null);
  assert.equal(sb.model_check_note, 'not checked against DEM for 3-layer beds: nearest checked bed is 2 layers, czubak2016 against glass');
  assert.equal(sb.feed_warning, sb.model_check_note);
  const c = await req(d.base, 'POST', '/api/v1/sessions', { preset: 'liggghts-bed4', scene: { layers: 2 }, pace: 1 });
  assert.equal(c.status, 201);
  const sc = (await req(d.base, 'GET', `/api/v1/sessions/${c.body.id}`)).body.status;
  assert.equal(sc.model_checked, false);
  assert.equal(sc.model_check_note,
    'not checked against DEM for 2-layer beds: nearest checked bed is 4 layers, liggghts-bed4');
  for (const id of [a.body.id, b.body.id, c.body.id])
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${id}`)).status, 204);
});

test('model_error: a sweep\'s points and an experiment\'s segments carry the map\'s value at their angle, in JSON and CSV', { timeout: 30000 * SLOW }, async () => {
  const sw = await req(d.base, 'POST', '/api/v1/sweeps',
    { preset: 'liggghts-bed4', beta: [30, 150, 170], rotations: ['cw'], t_end: 1 });
  assert.equal(sw.status, 202, sw.text);
  const at = (beta) => sw.body.points.find((p) => p.beta === beta);
  assert.ok(Math.abs(at(30).model_error - MAP['30,cw']) < 1e-12, `sweep at 30: ${at(30).model_error}`);
  assert.ok(Math.abs(at(150).model_error - MAP['150,cw']) < 1e-12, `sweep at 150: ${at(150).model_error}`);
  assert.equal(at(150).model_checked, true);
  assert.equal(at(170).model_checked, false);
  assert.equal(at(170).model_error, null);
  assert.match(at(170).model_check_note, /beta 170 deg cw/);
  // the CSV export carries the same: model_error, its uncertainty, model_checked
  const csv = await csvRows(`/api/v1/sweeps/${sw.body.id}?format=csv`);
  assert.deepEqual(csv.map((r) => [r.beta, r.model_error, r.model_error_uncertainty, r.model_checked]),
    [30, 150, 170].map((b) => [String(b), cell(at(b).model_error), cell(at(b).model_error_uncertainty),
      String(at(b).model_checked)]));
  assert.equal(csv[2].model_error, '');
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sweeps/${sw.body.id}`)).status, 204);

  const s = await req(d.base, 'POST', '/api/v1/sessions', { preset: 'liggghts-bed4', params: { beta: 30 }, pace: 1 });
  assert.equal(s.status, 201);
  const x = await req(d.base, 'POST', '/api/v1/experiments',
    { session: s.body.id, schedule: [{ beta: 30, until: 0.002 }, { beta: 150, until: 0.004 }] });
  assert.equal(x.status, 201, x.text);
  const seg = x.body.segments;
  assert.ok(Math.abs(seg[0].model_error - MAP['30,cw']) < 1e-12, `segment at 30: ${seg[0].model_error}`);
  assert.ok(Math.abs(seg[1].model_error - MAP['150,cw']) < 1e-12, `segment at 150: ${seg[1].model_error}`);
  await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${x.body.id}`)).body.state === 'done', 10000 * SLOW, 'the experiment');
  const xcsv = await csvRows(`/api/v1/experiments/${x.body.id}?format=csv`);
  assert.deepEqual(xcsv.map((r) => [r.beta, r.model_error, r.model_error_uncertainty, r.model_checked]),
    seg.map((g) => [String(g.beta), cell(g.model_error), cell(g.model_error_uncertainty), 'true']));
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${s.body.id}`)).status, 204);
});
