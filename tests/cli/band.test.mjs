// SPDX-License-Identifier: GPL-3.0-or-later
// `convsim sweep --band-from FIT.json` (fit/fit_source.c): a study
// takes a fit's result and every point gets the 95 % band from the fit's
// covariance by the delta method the fit's own band uses. At the fit's
// curve points (same beta, same settings) the study's bands are the
// fit's, bit for bit; each band holds its point's v and is wider than 0;
// a varied fitted parameter takes the grid's values and leaves the band;
// the mirror images' bands are their sources' mirrored; the CSV has
// band_lower,band_upper only with bands; a file that is not a fit's
// result, or one without a covariance, is refused (exit 2) naming
// --band-from. CONVSIM names the binary.
import { test, before } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const run = (...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: 300000 });
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const dir = mkdtempSync(join(tmpdir(), 'convsim-band-'));
const CHEAP = ['--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '--duration', '2'];
const FIT = join(dir, 'fit.json');
let fit;

before(() => {
  // data: the model's curve with a +-3 % pattern on it, sigma 5 mm/s
  const sweep = run('sweep', ...CHEAP, '--beta', '20:160:20', '--rotation', 'cw', '-q');
  assert.equal(sweep.code, 0, sweep.err);
  const rows = sweep.out.trim().split('\n').slice(1).map((l) => l.split(','));
  const data = join(dir, 'data.csv');
  writeFileSync(data, 'beta,rotation,v,sigma\n' +
    rows.map((r, i) => `${r[0]},cw,${(Number(r[2]) * (1 + 0.03 * ((i % 3) - 1))).toFixed(6)},0.005`).join('\n') + '\n');
  const f = run('fit', '--data', data, '--free', 'e,mu', ...CHEAP, '--curve-step', '30', '-q', '-o', FIT);
  assert.equal(f.code, 0, f.err);
  fit = JSON.parse(readFileSync(FIT, 'utf8'));
  assert.equal(fit.status, 'converged');
});

test('at the fit\'s curve points the study\'s bands are the fit\'s own, bit for bit; each holds v and is wider than 0', () => {
  const r = run('sweep', ...CHEAP, '--beta', '0:180:30', '--rotation', 'cw', '--band-from', FIT, '-q', '-f', 'json');
  assert.equal(r.code, 0, r.err);
  const s = JSON.parse(r.out);
  assert.deepEqual(s.band, { level: 0.95, parameters: ['e', 'mu'], varied: [] });
  assert.deepEqual(s.points.map((p) => p.beta), fit.curve.beta);
  // (the fit's grid is k times 30 deg in rad, the study's beta 30 k deg
  // converted: at some points the angles differ in the last bit, and v and
  // the band with them, by round-off)
  let exact = 0;
  const near = (a, b, what) => assert.ok(Math.abs(a - b) <= 1e-12 * Math.abs(b), `${what}: ${a} vs ${b}`);
  s.points.forEach((p, k) => {
    near(p.velocity, fit.curve.cw.fit[k], `beta ${p.beta}: v at the fitted values`);
    near(p.band.lower, fit.curve.cw.band.lower[k], `beta ${p.beta}: lower`);
    near(p.band.upper, fit.curve.cw.band.upper[k], `beta ${p.beta}: upper`);
    exact += p.band.lower === fit.curve.cw.band.lower[k] && p.band.upper === fit.curve.cw.band.upper[k];
    assert.ok(p.band.lower < p.velocity && p.velocity < p.band.upper, `beta ${p.beta}: ${JSON.stringify(p.band)} holds ${p.velocity}`);
    // at least the point's own error bar's share (the normal quantile: the data had sigma)
    assert.ok(p.band.upper - p.band.lower >= 2 * 1.959963984540054 * p.uncertainty * (1 - 1e-12), `beta ${p.beta}`);
  });
  assert.ok(exact >= 4, `${exact} of 7 bit for bit`);
});

test('a varied fitted parameter takes the grid\'s values and leaves the band; the mirror images take their sources\' bands mirrored', () => {
  const r = run('sweep', ...CHEAP, '--vary', 'mu=0.3,0.6', '--vary', 'beta=30,150', '--band-from', FIT, '-q', '-f', 'json');
  assert.equal(r.code, 0, r.err);
  const s = JSON.parse(r.out);
  assert.deepEqual(s.band, { level: 0.95, parameters: ['e'], varied: ['mu'] });
  assert.deepEqual(s.reductions, ['mirror']);
  const at = (mu, beta, rot) => s.points.find((p) => p.mu === mu && p.beta === beta && p.rotation === rot);
  for (const p of s.points) {
    assert.ok(p.band.lower < p.velocity && p.velocity < p.band.upper, JSON.stringify(p));
    if (p.mirrored) {
      const src = at(p.mu, 180 - p.beta, 'cw');
      assert.equal(p.band.lower, -src.band.upper);
      assert.equal(p.band.upper, -src.band.lower);
    }
  }
  // mu is the grid's at every point (0.3 and 0.6, not the fitted value)
  assert.notEqual(at(0.3, 30, 'cw').velocity, at(0.6, 30, 'cw').velocity);
  // uncorrelated e and mu: e's share alone is narrower than both shares
  // (mu varied at its fitted value: the same point)
  const uncorrelated = join(dir, 'uncorrelated.json');
  writeFileSync(uncorrelated, JSON.stringify({ ...fit, correlation: [[1, 0], [0, 1]] }));
  const both = JSON.parse(run('sweep', ...CHEAP, '--beta', '30', '--rotation', 'cw', '--band-from', uncorrelated, '-q', '-f', 'json').out).points[0];
  const eOnly = JSON.parse(run('sweep', ...CHEAP, '--vary', `mu=${fit.parameters[1].value}`, '--beta', '30', '--rotation', 'cw',
    '--band-from', uncorrelated, '-q', '-f', 'json').out).points[0];
  assert.equal(eOnly.velocity, both.velocity);
  assert.ok(eOnly.band.upper - eOnly.band.lower < both.band.upper - both.band.lower, `${JSON.stringify(eOnly.band)} vs ${JSON.stringify(both.band)}`);
});

test('the CSV has band_lower,band_upper only with bands', () => {
  const plain = run('sweep', ...CHEAP, '--beta', '30', '--rotation', 'cw', '-q');
  assert.equal(plain.out.split('\n')[0], 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
  const banded = run('sweep', ...CHEAP, '--beta', '30', '--rotation', 'cw', '--band-from', FIT, '-q');
  const [head, row] = banded.out.trim().split('\n');
  assert.equal(head, 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked,band_lower,band_upper');
  const cells = row.split(',');
  assert.equal(Number(cells[13]), fit.curve.cw.band.lower[1]);
  assert.equal(Number(cells[14]), fit.curve.cw.band.upper[1]);
});

test('bad --band-from: exit 2, a message naming it, nothing on stdout', () => {
  const noCov = structuredClone(fit);
  noCov.correlation[0][1] = noCov.correlation[1][0] = null;
  const cases = [
    [join(dir, 'missing.json'), /--band-from: cannot read '.*missing\.json'/],
    [(() => { const p = join(dir, 'not.json'); writeFileSync(p, 'beta,rotation,v\n'); return p; })(), /--band-from .*not the JSON result of convsim fit/],
    [(() => { const p = join(dir, 'nocov.json'); writeFileSync(p, JSON.stringify(noCov, null, 2)); return p; })(), /--band-from .*covariance is not determined/],
    [(() => { const p = join(dir, 'deep.json'); writeFileSync(p, `{"x":${'['.repeat(100000)}${']'.repeat(100000)}}`); return p; })(), /--band-from .*not the JSON result of convsim fit/],
    [(() => { const p = join(dir, 'cut.json'); writeFileSync(p, JSON.stringify(fit).slice(0, 200)); return p; })(), /--band-from .*not the JSON result of convsim fit/],
    [(() => { const p = join(dir, 'failed.json'); writeFileSync(p, JSON.stringify({ ...fit, status: 'failed' })); return p; })(), /--band-from .*the fit failed/],
  ];
  for (const [file, re] of cases) {
    const r = run('sweep', ...CHEAP, '--beta', '30', '--band-from', file, '-q');
    assert.equal(r.code, 2, `${file}: ${r.err}`);
    assert.match(r.err, re);
    assert.equal(r.out, '');
  }
});
