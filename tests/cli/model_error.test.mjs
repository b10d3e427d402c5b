// SPDX-License-Identifier: GPL-3.0-or-later
// convsim run's summary carries the model error of its scene (docs/dem.md
// "Model error"): at a point of the DEM map the map's |v_column - v_DEM|
// plus the DEM's seed spread (tests/bench/results/model_check.csv); where
// the scene is not checked, null, model_checked false and a note naming the
// nearest checked point, which feed_warning repeats.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { readFileSync } from 'node:fs';
import '../tether.mjs'; // nothing started here outlives the test

const CONVSIM = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const summary = (preset, ...set) => JSON.parse(execFileSync(CONVSIM, ['run', '-q', '-d', '0.2',
  ...(preset ? ['-p', preset] : []), ...set.flatMap((s) => ['--set', s])], { encoding: 'utf8' }));

// liggghts-bed4's row at beta, rotation: the expected model error
function mapError(beta, rotation) {
  const [head, ...rows] = readFileSync(new URL('../bench/results/model_check.csv', import.meta.url), 'utf8')
    .trim().split('\n');
  const c = Object.fromEntries(head.split(',').map((n, i) => [n, i]));
  const r = rows.map((l) => l.split(',')).find((r) => r[c.preset] === 'liggghts-bed4' &&
    Number(r[c.beta_deg]) === beta && r[c.rotation] === rotation);
  return Math.abs(Number(r[c.v_column]) - Number(r[c.v_dem])) + Number(r[c.v_dem_sd]);
}

test('model_error: the calibrated bed at 150 deg cw carries the map\'s value there', () => {
  const s = summary('liggghts-bed4', 'beta=150');
  assert.equal(s.model_checked, true);
  assert.ok(Math.abs(s.model_error - mapError(150, 'cw')) < 1e-12, `${s.model_error} against ${mapError(150, 'cw')}`);
  assert.ok(s.model_error_uncertainty > 0 && s.model_error_uncertainty < s.model_error);
  assert.match(s.model_check_note, /^DEM check: within ±0\.008 m\/s here \(liggghts-bed4, 4 layers\)$/);
  assert.equal(s.feed_warning, null);
});

test('model_error: the table\'s column-model v is this build\'s (make model-check computes it)', () => {
  // tests/bench/model_check.py's run at 150 deg cw against the committed row
  const [head, ...rows] = readFileSync(new URL('../bench/results/model_check.csv', import.meta.url), 'utf8')
    .trim().split('\n');
  const c = Object.fromEntries(head.split(',').map((n, i) => [n, i]));
  const row = rows.map((l) => l.split(',')).find((r) => r[c.preset] === 'liggghts-bed4' &&
    Number(r[c.beta_deg]) === 150 && r[c.rotation] === 'cw');
  const v = JSON.parse(execFileSync(CONVSIM, ['run', '-p', 'liggghts-bed4', '--set', 'layers=4', '--set', 'beta=150',
    '--set', 'rotation=cw', '--set', 'feed_coupling=false', '-d', '2', '--set', 'transient=0.5', '-q'],
  { encoding: 'utf8' })).transport_velocity;
  assert.ok(Math.abs(v - Number(row[c.v_column])) < 1e-5 * Math.abs(v), `v ${v}, the table's ${row[c.v_column]}`);
});

test('model_error: not checked at another depth, the note names the nearest checked bed', () => {
  const s = summary('liggghts-bed4', 'beta=150', 'layers=2');
  assert.equal(s.model_checked, false);
  assert.equal(s.model_error, null);
  assert.equal(s.model_error_uncertainty, null);
  assert.equal(s.model_check_note, 'not checked against DEM for 2-layer beds: nearest checked bed is 4 layers, liggghts-bed4');
  assert.equal(s.feed_warning, s.model_check_note);
  // the preset as it is, at a depth the map has not: the nearest depth's bed
  const p = summary(null, 'beta=150', 'layers=3');
  assert.equal(p.model_checked, false);
  assert.match(p.model_check_note,
    /^not checked against DEM for 3-layer beds: nearest checked bed is [24] layers, czubak2016 against (glass|wheat)$/);
  // and another machine: the preset named plainly
  const q = summary(null, 'beta=150', 'layers=2', 'omega_ss=200');
  assert.equal(q.model_checked, false);
  assert.match(q.model_check_note, /^not checked against DEM at omega_ss = 200 rad\/s: the DEM map's machine is czubak2016's/);
  const n = summary(null, 'feed=false');
  assert.equal(n.model_checked, false);
  assert.equal(n.feed_warning, null);
});

test('model_error: a fit\'s curve is checked at the fitted values, not the start\'s', () => {
  const data = new URL('../bench/results/dem_bed4.csv', import.meta.url).pathname;
  const out = execFileSync(CONVSIM, ['fit', '-p', 'liggghts-bed4', '--data', data, '--free', 'mu',
    '--set', 'feed_coupling=false', '--curve-step', '15', '--threads', '1', '--max-iter', '1', '-q'], { encoding: 'utf8' });
  const f = JSON.parse(out);
  const mu = f.parameters[0].value;
  assert.ok(Math.abs(mu - 0.62285) > 1e-6, `mu moved from the preset's: ${mu}`);
  for (const rot of ['cw', 'ccw']) {
    const c = f.curve[rot];
    assert.equal(c.model_error.length, f.curve.beta.length);
    assert.deepEqual(c.model_checked, f.curve.beta.map(() => false), `${rot}: the fitted mu is no map entry's`);
    assert.ok(c.model_error.every((e) => e === null));
    assert.equal(c.model_check_note, 'not checked against DEM with this contact (mu differs): nearest checked is 4 layers, liggghts-bed4');
  }
});

test('model_error: convsim sweep\'s JSON points carry it at their angle', () => {
  const s = JSON.parse(execFileSync(CONVSIM, ['sweep', '-p', 'liggghts-bed4', '--set', 'feed_coupling=false', '--beta', '150:170:20',
    '--rotation', 'cw', '-d', '0.5', '-q', '-f', 'json'], { encoding: 'utf8' }));
  const [a, b] = s.points;
  assert.equal(a.beta, 150);
  assert.ok(Math.abs(a.model_error - mapError(150, 'cw')) < 1e-12, `${a.model_error} at 150 deg cw`);
  assert.equal(a.model_checked, true);
  assert.equal(b.model_checked, false);
  assert.equal(b.model_error, null);
});

// The committed CSV as rows of objects by column name.
function csvObjects(rel) {
  const [head, ...rows] = readFileSync(new URL(rel, import.meta.url), 'utf8').split('\n')
    .filter((l) => l && !l.startsWith('#'));
  const names = head.split(',');
  return rows.map((l) => Object.fromEntries(l.split(',').map((x, i) => [names[i], x])));
}

test('model_error: each DEM map bed with a calibrated column model is checked at its settings, with the map\'s value', () => {
  const table = csvObjects('../bench/results/model_check.csv').filter((r) => r.source.startsWith('dem_map.csv') && r.model.includes(' calibrated to '));
  const presets = csvObjects('../bench/model_presets.csv');
  assert.ok(table.length > 0, 'the map has calibrated beds (make bench-dem-calibrate)');
  const beds = new Map();
  for (const r of table) beds.set(`${r.material},${r.layers},${r.drive}`, beds.get(`${r.material},${r.layers},${r.drive}`) || r);
  for (const [key, r] of beds) {
    const line = presets.find((p) => `${p.material},${p.layers},${p.drive}` === key);
    assert.ok(line, `${key}: its line in model_presets.csv`);
    assert.equal(r.settings, line.settings, `${key}: the table is the presets' (make model-check)`);
    // one point of each sense and angle: the report's rule picks one row a point
    const at = table.filter((x) => `${x.material},${x.layers},${x.drive}` === key).map((x) => `${Number(x.beta_deg)},${x.rotation}`);
    assert.equal(new Set(at).size, at.length, `${key}: one row a point`);
    const s = summary(r.preset, ...r.settings.split(';'), `layers=${r.layers}`, `beta=${r.beta_deg}`, `rotation=${r.rotation}`);
    const want = Math.abs(Number(r.v_column) - Number(r.v_dem)) + Number(r.v_dem_sd);
    assert.equal(s.model_checked, true, `${key} at ${r.beta_deg}: ${s.model_check_note}`);
    assert.ok(Math.abs(s.model_error - want) < 1e-12, `${key} at ${r.beta_deg}: ${s.model_error} against ${want}`);
    // the model as the table names it (a drive of the map's other than the preset's own: "at e = ...")
    assert.equal(r.model, `${r.preset}${r.drive === 'a150' ? ' at e = 0.03225' : ''} calibrated to ${r.material}`);
    assert.ok(s.model_check_note.endsWith(`(${r.model}, ${r.layers} layers)`), s.model_check_note);
    // the table's v_column is this build's column model, one-way as model_check.py runs it
    const v = JSON.parse(execFileSync(CONVSIM, ['run', '-p', r.preset, ...r.settings.split(';').flatMap((x) => ['--set', x]),
      '--set', `layers=${r.layers}`, '--set', `beta=${r.beta_deg}`, '--set', `rotation=${r.rotation}`,
      '--set', 'feed_coupling=false', '-d', '2', '--set', 'transient=0.5', '-q'], { encoding: 'utf8' })).transport_velocity;
    assert.ok(Math.abs(v - Number(r.v_column)) < 1e-5 * Math.abs(v), `${key}: v ${v}, the table's ${r.v_column}`);
  }
});

test('model_error: a map point\'s value is the report\'s row: the map\'s cell, the softest modulus within the overlap bound', () => {
  // glass one grain deep at 45 deg cw: 2e8 Pa overlaps 1.045 % of a
  // diameter, so the point is a stiffer rung's: the softest within the
  // bound (4e8 or 8e8 Pa; dem_points.py's rule)
  const rows = csvObjects('../bench/results/dem_map.csv').filter((r) => r.material === 'glass' && r.layers === '1' &&
    r.drive === 'preset' && Number(r.beta_deg) === 45 && r.rotation === 'cw' && Number(r.cell_width_d) === 4 &&
    (r.role === 'map' || r.role === 'stiffness'));
  const soft = rows.find((r) => Number(r.youngs_pa) === 2e8);
  const within = rows.filter((r) => Number(r.youngs_pa) > 2e8 && Number(r.overlap_max_rel) <= 0.01)
    .sort((a, b) => Number(a.youngs_pa) - Number(b.youngs_pa));
  assert.ok(Number(soft.overlap_max_rel) > 0.01 && within.length > 0);
  const stiff = within[0];
  const point = csvObjects('../bench/results/model_check.csv').filter((r) => r.material === 'glass' && r.layers === '1' &&
    r.drive === 'preset' && Number(r.beta_deg) === 45 && r.rotation === 'cw' && r.model.includes(' calibrated to '));
  assert.equal(point.length, 1);
  assert.equal(Number(point[0].v_dem), Number(stiff.v_dem));
  // and at 30 deg, where 2e8 Pa is within the bound, the 2e8 row (not the 8e8 check nor the wider cell)
  const p30 = csvObjects('../bench/results/model_check.csv').find((r) => r.material === 'glass' && r.layers === '1' &&
    r.drive === 'preset' && Number(r.beta_deg) === 30 && r.rotation === 'cw' && r.model.includes(' calibrated to '));
  assert.equal(p30.v_dem, '0.0978932');
});

test('model_error: every complete bed of the DEM map (all 13 clockwise angles) is calibrated and checked, glass 8 grains and wheat among them', () => {
  const key = (r) => `${r.material},${r.layers},${r.drive}`;
  const angles = new Map();
  for (const r of csvObjects('../bench/results/dem_map.csv')) {
    if (r.role !== 'map' || r.rotation !== 'cw' || Number(r.cell_width_d) !== 4) continue;
    if (!angles.has(key(r))) angles.set(key(r), new Set());
    angles.get(key(r)).add(Number(r.beta_deg));
  }
  const complete = [...angles].filter(([, s]) => s.size === 13).map(([k]) => k);
  for (const k of ['glass,1,preset', 'glass,2,preset', 'glass,4,preset', 'glass,8,preset', 'wheat,1,preset', 'wheat,2,preset'])
    assert.ok(complete.includes(k), `${k}: complete in the map`);
  const presets = csvObjects('../bench/model_presets.csv');
  // the calibrated beds' rows (not the default preset's, under either drive)
  const table = csvObjects('../bench/results/model_check.csv').filter((r) => r.source.startsWith('dem_map.csv') &&
    r.model.includes(' calibrated to '));
  assert.deepEqual(presets.map(key).sort(), [...complete].sort(), 'the calibrated beds are the complete ones (make bench-dem-calibrate)');
  assert.deepEqual([...new Set(table.map(key))].sort(), [...complete].sort(), 'each has its rows (make model-check)');
  // an 8-grain glass scene and a wheat scene at 150 deg cw: checked, with the map's value there
  for (const k of ['glass,8,preset', 'wheat,1,preset']) {
    const r = table.find((x) => key(x) === k && Number(x.beta_deg) === 150 && x.rotation === 'cw');
    const s = summary(r.preset, ...r.settings.split(';'), `layers=${r.layers}`, 'beta=150');
    assert.equal(s.model_checked, true, `${k}: ${s.model_check_note}`);
    const want = Math.abs(Number(r.v_column) - Number(r.v_dem)) + Number(r.v_dem_sd);
    assert.ok(Math.abs(s.model_error - want) < 1e-12, `${k}: ${s.model_error} against ${want}`);
    assert.match(s.model_check_note, new RegExp(`calibrated to ${r.material}, ${r.layers} layers\\)$`));
  }
});

test('model_error: the preset as it is is checked against every material\'s bed at every depth, angle and drive of the map', () => {
  // the default's entries: its settings empty, or a drive's changes (e=...)
  const table = csvObjects('../bench/results/model_check.csv').filter((r) => r.preset === 'czubak2016' &&
    r.model.startsWith('czubak2016 ') && r.model.includes(' against '));
  const materials = new Set(table.map((r) => r.material));
  assert.ok(materials.has('glass') && materials.has('wheat'), [...materials].join(' '));
  assert.ok(table.some((r) => r.drive === 'preset' && r.settings === ''), 'the preset\'s own drive');
  // the map's points: (drive, layers, beta, rotation) -> rows, a material each
  const at = new Map();
  for (const r of table) {
    assert.equal(r.settings === '', r.drive === 'preset', `${r.drive}: ${r.settings}`);
    const k = `${r.drive},${r.layers},${Number(r.beta_deg)},${r.rotation}`;
    at.set(k, [...(at.get(k) || []), r]);
  }
  const fmt = (x) => x.toFixed(3);
  // a material without a row at (beta, sense) is checked at the mirror
  // image (the preset's machine is symmetric): its row at 180 - beta the
  // other way, the same distance
  const mirror = (r) => r === 'cw' ? 'ccw' : 'cw';
  for (const [k, own] of at) {
    const [drive, layers, beta, rotation] = k.split(',');
    const rows = [...materials].map((m) => own.find((r) => r.material === m) ||
      (at.get(`${drive},${layers},${180 - Number(beta)},${mirror(rotation)}`) || []).find((r) => r.material === m))
      .filter(Boolean);
    const err = rows.map((r) => Math.abs(Number(r.v_column) - Number(r.v_dem)) + Number(r.v_dem_sd));
    const top = err.indexOf(Math.max(...err));
    const s = summary(null, ...own[0].settings.split(';').filter(Boolean), `layers=${layers}`, `beta=${beta}`,
      `rotation=${rotation}`);
    assert.equal(s.model_checked, true, `${k}: ${s.model_check_note}`);
    assert.ok(Math.abs(s.model_error - err[top]) < 1e-12, `${k}: ${s.model_error}, the largest of ${err}`);
    const others = rows.map((r, i) => (i === top ? '' : `; against ${r.material} ±${fmt(err[i])}`)).join('');
    assert.equal(s.model_check_note,
      `DEM check: within ±${fmt(err[top])} m/s here (${rows[top].model}, ${layers} layers${others})`);
    assert.equal(s.feed_warning, null);
  }
  // the table's v_column is this build's preset, one-way as model_check.py runs it (one point a bed)
  for (const key of new Set(table.map((r) => `${r.settings}|${r.layers}`))) {
    const r = table.find((x) => `${x.settings}|${x.layers}` === key);
    const v = JSON.parse(execFileSync(CONVSIM, ['run', ...r.settings.split(';').filter(Boolean).flatMap((x) => ['--set', x]),
      '--set', `layers=${r.layers}`, '--set', `beta=${r.beta_deg}`,
      '--set', `rotation=${r.rotation}`, '--set', 'feed_coupling=false', '-d', '2', '--set', 'transient=0.5', '-q'],
    { encoding: 'utf8' })).transport_velocity;
    assert.ok(Math.abs(v - Number(r.v_column)) < 1e-5 * Math.abs(v), `${key}: v ${v}, the table's ${r.v_column}`);
  }
});
