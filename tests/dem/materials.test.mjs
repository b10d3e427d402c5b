// SPDX-License-Identifier: GPL-3.0-or-later
// dem/materials.json, the DEM map's named materials (docs/materials.md):
// every value the runner passes to convsim-dem is there, in a physical
// range, and named by a source note that either reports the figure it
// rests on (wheat's: with the paper's year) or says "assumed:" and why; docs/dem.md's materials table shows the file's
// values. No LIGGGHTS needed.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';

const ROOT = new URL('../..', import.meta.url).pathname;
const MATS = JSON.parse(readFileSync(`${ROOT}dem/materials.json`, 'utf8'));
const VALUES = ['d_min', 'd_max', 'density', 'youngs_real', 'poisson',
  'e_pp', 'mu_pp', 'roll_pp', 'e_pw', 'mu_pw', 'roll_pw'];

test('every material has every value, in a physical range', () => {
  assert.deepEqual(Object.keys(MATS.materials).sort(), ['glass', 'wheat']);
  for (const [name, m] of Object.entries(MATS.materials)) {
    for (const k of VALUES) assert.equal(typeof m[k], 'number', `${name}.${k}`);
    assert.ok(m.d_min > 0 && m.d_min < m.d_max && m.d_max < 0.02, name);
    assert.ok(m.density > 500 && m.density < 8000, name);
    assert.ok(m.youngs_real >= MATS.map.youngs_ladder[0], name);
    assert.ok(m.poisson > 0 && m.poisson < 0.5, name);
    for (const k of ['e_pp', 'e_pw']) assert.ok(m[k] > 0 && m[k] < 1, `${name}.${k}`);
    for (const k of ['mu_pp', 'mu_pw', 'roll_pp', 'roll_pw']) assert.ok(m[k] > 0 && m[k] < 1, `${name}.${k}`);
  }
});

test('every value is named by a source note: a cited year or "assumed:"', () => {
  for (const [name, m] of Object.entries(MATS.materials)) {
    const named = Object.keys(m.sources).flatMap((k) => k.split(/,\s*/));
    // d_min and d_max may share the label's source (glass: the beads' sizes)
    for (const k of VALUES.filter((v) => !(name === 'glass' && v.startsWith('d_')))) {
      assert.ok(named.includes(k), `${name}.${k} has no source note`);
    }
    // a measured value's note reports the figure; wheat's also name the paper's year
    for (const [k, note] of Object.entries(m.sources)) {
      const cited = name === 'wheat' ? /\b(19|20)\d\d\b/.test(note) : /\d/.test(note);
      assert.ok(note.startsWith('assumed: ') || cited, `${name} ${k}: ${note}`);
    }
  }
});

test("docs/dem.md's materials table shows the file's values", () => {
  const md = readFileSync(`${ROOT}docs/dem.md`, 'utf8');
  const row = (label) => {
    const line = md.split('\n').find((l) => l.startsWith(`| ${label} |`));
    assert.ok(line, label);
    return line.split('|').slice(2, 4).map((c) => c.trim());
  };
  const { glass, wheat } = MATS.materials;
  const mm = (m) => `${(m.d_min * 1000).toFixed(1)}–${(m.d_max * 1000).toFixed(1)} mm`;
  const pair = (a, b) => `${a.toFixed(2)} / ${b.toFixed(2)}`;
  assert.ok(row('diameters')[0].startsWith(mm(glass)));
  assert.ok(row('diameters')[1].startsWith(mm(wheat)));
  assert.deepEqual(row('density'), [`${glass.density} kg/m³`, `${wheat.density} kg/m³`]);
  assert.deepEqual(row("Poisson's ratio"), [String(glass.poisson), String(wheat.poisson.toFixed(2))]);
  assert.deepEqual(row('restitution grain–grain / grain–deck')[1], pair(wheat.e_pp, wheat.e_pw));
  assert.deepEqual(row('friction grain–grain / grain–deck')[1], pair(wheat.mu_pp, wheat.mu_pw));
  assert.deepEqual(row('rolling friction (epsd2) grain–grain / grain–deck')[1], pair(wheat.roll_pp, wheat.roll_pw));
  assert.deepEqual(row("Young's modulus, real → run"), ['63 GPa → 2·10⁸ Pa', '0.3 GPa → 2·10⁸ Pa']);
  assert.equal(glass.youngs_real, 63e9);
  assert.equal(wheat.youngs_real, 0.3e9);
  assert.equal(MATS.map.youngs_map, 2e8);
});
