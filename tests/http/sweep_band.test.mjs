// SPDX-License-Identifier: GPL-3.0-or-later
// Bands on a study from a fit (POST /api/v1/sweeps with "band_from_fit"):
// every point gets the 95 % band of the fit's covariance by the fit's own
// delta method; at the fit's curve points they are the fit's band (bit
// for bit or to round-off), each holds its v and is wider than 0; the
// daemon's table is the CLI's (`convsim sweep --band-from` on the fit's
// result) bit for bit; a varied fitted parameter leaves the band; an
// unknown fit, a fit not finished, or a band_from_fit that is no string is
// refused naming the field, and nothing is started.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import Ajv2020 from 'ajv/dist/2020.js';
import { startDaemon, req, until, CHEAP, SLOW, CLI } from './lib.mjs';

const CHEAP_CLI = ['--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '-q'];
const cli = (...args) => execFileSync(CLI, ['sweep', ...CHEAP_CLI, ...args], { encoding: 'utf8' });

let d, ajv, fit, fitId;
const ID = 'https://convsim.invalid/openapi.json';
function valid(name, value) {
  const v = ajv.getSchema(`${ID}#/components/schemas/${name}`);
  assert.ok(v(value), `${name}: ${ajv.errorsText(v.errors)}`);
}
const finished = (kind, id) => until(async () => {
  const r = await req(d.base, 'GET', `/api/v1/${kind}/${id}`);
  return ['done', 'failed'].includes(r.body.state) && r.body;
}, 200000 * SLOW, `${kind} ${id}`);

before(async () => {
  d = await startDaemon();
  ajv = new Ajv2020({ strict: false, allErrors: true });
  ajv.addSchema({ ...(await req(d.base, 'GET', '/api/v1/openapi.json')).body, $id: ID });
  // data: the model's curve with a +-3 % pattern on it, sigma 5 mm/s
  const rows = cli('--beta', '20:160:20', '--rotation', 'cw', '--duration', '2').trim().split('\n').slice(1).map((l) => l.split(','));
  const points = rows.map((r, i) => ({ beta: Number(r[0]), rotation: 'cw', v: Number((Number(r[2]) * (1 + 0.03 * ((i % 3) - 1))).toFixed(6)), sigma: 0.005 }));
  const f = await req(d.base, 'POST', '/api/v1/fits', { ...CHEAP, t_end: 2, free: ['e', 'mu'], points, curve_step: 30 });
  assert.equal(f.status, 202, f.text);
  fitId = f.body.id;
  fit = (await finished('fits', fitId)).result;
  assert.equal(fit.status, 'converged');
});
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

test('a beta sweep with band_from_fit: the fit\'s own band at its curve points, each holding v; the CLI\'s table bit for bit', { timeout: 200000 * SLOW }, async () => {
  const body = { ...CHEAP, t_end: 2, beta: { from: 0, to: 180, step: 30 }, rotations: ['cw'], band_from_fit: fitId };
  const r = await req(d.base, 'POST', '/api/v1/sweeps', body);
  assert.equal(r.status, 202, r.text);
  const s = await finished('sweeps', r.body.id);
  valid('SweepCreate', body);
  valid('Sweep', s);
  assert.deepEqual(s.band, { level: 0.95, fit: fitId, parameters: ['e', 'mu'], varied: [] });
  let exact = 0;
  s.points.forEach((p, k) => {
    const lo = fit.curve.cw.band.lower[k], hi = fit.curve.cw.band.upper[k];
    assert.ok(Math.abs(p.band.lower - lo) <= 1e-12 * Math.abs(lo), `beta ${p.beta}: ${p.band.lower} vs ${lo}`);
    assert.ok(Math.abs(p.band.upper - hi) <= 1e-12 * Math.abs(hi), `beta ${p.beta}: ${p.band.upper} vs ${hi}`);
    exact += p.band.lower === lo && p.band.upper === hi;
    assert.ok(p.band.lower < p.velocity && p.velocity < p.band.upper, `beta ${p.beta}`);
  });
  assert.ok(exact >= 4, `${exact} of 7 bit for bit`);
  // the CLI on the fit's result writes the daemon's table
  const file = join(mkdtempSync(join(tmpdir(), 'convsim-sweep-band-')), 'fit.json');
  writeFileSync(file, JSON.stringify(fit));
  const csv = (await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}?format=csv`)).text;
  assert.match(csv.split('\n')[0], /,tol_met,model_error,model_error_uncertainty,model_checked,band_lower,band_upper$/);
  assert.equal(csv, cli('--beta', '0:180:30', '--rotation', 'cw', '--duration', '2', '--band-from', file));
});

test('a study varying a fitted parameter: the grid\'s values, that parameter out of the band, mirror images mirrored', { timeout: 200000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, t_end: 2, vary: { mu: [0.3, 0.6], beta: [30, 150] }, band_from_fit: fitId });
  assert.equal(r.status, 202, r.text);
  const s = await finished('sweeps', r.body.id);
  valid('Sweep', s);
  assert.deepEqual(s.band.parameters, ['e']);
  assert.deepEqual(s.band.varied, ['mu']);
  assert.deepEqual(s.reductions, ['mirror']);
  for (const p of s.points) {
    assert.ok(p.band.lower < p.velocity && p.velocity < p.band.upper, JSON.stringify(p));
    if (!p.mirrored) continue;
    const src = s.points.find((q) => q.mu === p.mu && q.beta === 180 - p.beta && q.rotation === 'cw');
    assert.deepEqual([p.band.lower, p.band.upper], [-src.band.upper, -src.band.lower]);
  }
  // without band_from_fit: no band anywhere, the CSV as before
  const plain = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, t_end: 2, beta: [30], rotations: ['cw'] });
  const ps = await finished('sweeps', plain.body.id);
  assert.equal(ps.band, undefined);
  assert.equal(ps.points[0].band, undefined);
  assert.match((await req(d.base, 'GET', `/api/v1/sweeps/${plain.body.id}?format=csv`)).text.split('\n')[0], /,tol_met,model_error,model_error_uncertainty,model_checked$/);
});

test('bad band_from_fit: a 4xx naming it, nothing started', { timeout: 60000 * SLOW }, async () => {
  const count = async () => (await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length;
  const before = await count();
  // a fit still running (a long one, deleted after)
  const slow = await req(d.base, 'POST', '/api/v1/fits', { ...CHEAP, t_end: 60, free: ['e'], points: fit.points.map(({ beta, rotation, v }) => ({ beta, rotation, v })) });
  assert.equal(slow.status, 202, slow.text);
  const cases = [
    [{ band_from_fit: 'nosuch' }, 422, /band_from_fit: no fit has the id 'nosuch'/],
    [{ band_from_fit: slow.body.id }, 422, new RegExp(`band_from_fit: fit '${slow.body.id}' is (queued|running); a band needs a finished fit`)],
    [{ band_from_fit: 5 }, 400, /band_from_fit must be a fit's id/],
    [{ band_from_fit: '' }, 422, /^band_from_fit has 0 bytes; a fit's id has 1 to 23$/],
  ];
  for (const [extra, status, re] of cases) {
    const r = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, t_end: 2, beta: [30], ...extra });
    assert.equal(r.status, status, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.body.field, 'band_from_fit');
    assert.match(r.body.detail, re);
  }
  assert.equal(await count(), before);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/fits/${slow.body.id}`, undefined, { 'Content-Type': 'application/json' })).status, 204);
});
