// SPDX-License-Identifier: GPL-3.0-or-later
// Calibration fits as jobs (POST /api/v1/fits): bad input refused whole with
// a 422 naming the field and nothing started; a fit's life (queued or
// running with progress, done with its result as JSON and CSV, listed,
// deleted); DELETE cancels a running fit, whose driver then stops; fits
// outlive a kill -9 of the daemon (--data-dir).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, CHEAP, SLOW } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(['--log-level', 'info']); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const JSON_CT = { 'Content-Type': 'application/json' };
const POINTS = [
  { beta: 20, rotation: 'cw', v: 0.07 },
  { beta: 60, rotation: 'cw', v: 0.06 },
  { beta: 100, rotation: 'cw', v: -0.03 },
  { beta: 140, rotation: 'cw', v: -0.09 },
];
const body = (extra = {}) => ({ ...CHEAP, t_end: 2, free: ['e'], points: POINTS, curve_step: 45, ...extra });

test('bad input: 422 naming the field, nothing started', { timeout: 30000 * SLOW }, async () => {
  const before = (await req(d.base, 'GET', '/api/v1/fits')).text;
  const cases = [
    [{ points: [{ beta: 200, rotation: 'cw', v: 0.1 }, ...POINTS] }, 'points[0].beta', /beta must be a finite number in \[0, 180\] deg/],
    [{ free: ['ee'] }, 'free[0]', /unknown parameter 'ee' \(did you mean 'e'\?\)/],
    [{ free: ['rotation'] }, 'free[0]', /'rotation' cannot be fitted/],
    [{ free: ['beta'] }, 'free[0]', /'beta' cannot be fitted/],
    [{ free: ['e', 'mu'], points: POINTS.slice(0, 1) }, 'points', /1 data for 2 free parameters/],
    [{ points: [POINTS[0], { ...POINTS[0], v: 0.08 }] }, 'points[1]', /duplicates points\[0\]/],
    [{ points: undefined, csv: 'beta,v\n30,0.1\n60,0.05\n' }, 'csv', /column 'rotation' is missing/],
    [{ points: undefined, csv: 'beta,rotation,v\n200,cw,0.1\n60,cw,0.05\n' }, 'points[0].beta', /finite number/],
    // a CSV number is a plain decimal one: no hexadecimal, inf or nan (read as 16, Infinity, NaN)
    [{ points: undefined, csv: 'beta,rotation,v\n30,cw,0.1\n60,cw,0x10\n' }, 'csv', /^csv: CSV line 3: v must be a number, got '0x10'$/],
    [{ points: undefined, csv: 'beta,rotation,v\n0x1p4,cw,0.1\n60,cw,0.05\n' }, 'csv', /^csv: CSV line 2: beta must be a number, got '0x1p4'$/],
    [{ points: undefined, csv: 'beta,rotation,v\nnan,cw,0.1\n60,cw,0.05\n' }, 'csv', /^csv: CSV line 2: beta must be a number, got 'nan'$/],
    [{ points: undefined, csv: 'beta,rotation,v,sigma\n30,cw,0.1,0.01\n60,cw,0.05,infinity\n' }, 'csv',
      /^csv: CSV line 3: sigma must be a number, got 'infinity'$/],
    [{ points: undefined }, 'points', /no data/],
    [{ peaks: [{ rotation: 'cw', beta: 38 }] }, 'peaks', /points or peaks, not both/],
    [{ t_end: 0 }, 't_end', /t_end must exceed/],
    [{ free: [{ name: 'e', min: 0.1, max: 0.01 }] }, 'free[0].max', /bounds of 'e'/],
    [{ free: ['mu', { name: 'e', start: 5 }] }, 'free[1].start', /^the start of 'e' \(5\) lies outside its bounds \[0, 0\.5\]$/],
    [{ starts: 0 }, 'starts', /starts must be in \[1, 32\]/],
    [{ starts: 33 }, 'starts', /starts must be in \[1, 32\]/],
    [{ starts: 1.5 }, 'starts', /starts must be an integer/],
    // priors: on a free parameter, normal (sd) or log-normal (factor), within
    // the bounds, and only with the data's sigma
    [{ free: [{ name: 'e', prior: { mean: 0.02, sd: 0.002 } }] }, 'free[0].prior',
      /^a prior \(on 'e'\) needs the data's sigma, to weigh the two against each other: give sigma with every point$/],
    [{ free: [{ name: 'e', prior: { mean: 0.02 } }] }, 'free[0].prior',
      /^the prior on 'e' takes a mean with either sd \(normal\) or factor \(log-normal\), one of them$/],
    [{ free: [{ name: 'e', prior: { mean: 0.02, sd: 0.002, factor: 2 } }] }, 'free[0].prior', /either sd \(normal\) or factor/],
    [{ free: [{ name: 'e', max: 0.05, prior: { mean: 0.06, sd: 0.002 } }] }, 'free[0].prior.mean',
      /^the prior's mean of 'e' must lie within its bounds \[0, 0.05\] m$/],
    [{ free: [{ name: 'e', prior: { mean: 0.02, factor: 1 } }] }, 'free[0].prior.factor', /^the prior's factor of 'e' must be in \(1, 1e6\]$/],
    [{ free: [{ name: 'e', prior: { mean: 0.02, factor: 2 } }] }, 'free[0].prior',
      /^a log-normal prior on 'e' needs a positive lower bound: free it as e:MIN:MAX with MIN > 0$/],
    [{ free: [{ name: 'e', prior: { mean: 0.02, sd: 0 } }] }, 'free[0].prior.sd', /^the prior's sd of 'e' must be in \(0, 5\] m \(ten times its range\)$/],
    [{ free: [{ name: 'e', prior: { mean: 0.02, width: 1 } }] }, 'free[0].prior.width', /^unknown member "width"; expected any of: mean, sd, factor$/],
  ];
  for (const [extra, field, re] of cases) {
    const r = await req(d.base, 'POST', '/api/v1/fits', body(extra));
    assert.equal(r.status, 422, `${JSON.stringify(extra)}: ${r.text}`);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.body.field, field, r.text);
    assert.match(r.body.detail, re);
  }
  // NaN cannot be JSON: a string where a number belongs is a 400
  const t = await req(d.base, 'POST', '/api/v1/fits', body({ points: [{ beta: 'NaN', rotation: 'cw', v: 0.1 }] }));
  assert.equal(t.status, 400, t.text);
  assert.equal(t.body.field, 'points[0].beta');
  // a prior of the wrong shape is a 400 too
  for (const [prior, field, re] of [
    [{ sd: 0.002 }, 'free[0].prior.mean', /^free\[0\]\.prior\.mean must be a number$/],
    [0.02, 'free[0].prior', /^free\[0\]\.prior must be \{mean, sd\} or \{mean, factor\}$/],
  ]) {
    const w = await req(d.base, 'POST', '/api/v1/fits', body({ free: [{ name: 'e', prior }] }));
    assert.equal(w.status, 400, w.text);
    assert.equal(w.body.field, field, w.text);
    assert.match(w.body.detail, re);
  }
  assert.equal((await req(d.base, 'GET', '/api/v1/fits')).text, before);
});

test('a fit job: progress, JSON and CSV result, list, delete', { timeout: 240000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/fits', body({ starts: 2 }));
  assert.equal(r.status, 202, r.text);
  assert.equal(r.headers.get('location'), `/api/v1/fits/${r.body.id}`);
  assert.ok(['queued', 'running'].includes(r.body.state));
  assert.deepEqual(r.body.values, { e: 0.0215 });
  assert.equal(r.body.result, null);
  const path = `/api/v1/fits/${r.body.id}`;
  let seen = 0;
  const done = await until(async () => {
    const g = await req(d.base, 'GET', path);
    assert.ok(g.body.evaluations >= seen, 'evaluations never go back');
    seen = g.body.evaluations;
    return g.body.state === 'done' && g.body;
  }, 200000 * SLOW, 'the fit');
  assert.ok(done.evaluations > 4);
  const res = done.result;
  assert.equal(res.status, 'converged');
  assert.equal(res.parameters[0].name, 'e');
  assert.ok(res.parameters[0].standard_error > 0);
  assert.equal(res.points.length, 4);
  for (const p of res.points) assert.ok(Math.abs(p.residual - (p.model - p.v)) < 1e-12);
  assert.deepEqual(res.curve.beta, [0, 45, 90, 135, 180]);
  assert.equal(res.evaluations, done.evaluations);
  // two runs: the start and the middle of e's range; the result is the cheaper
  assert.equal(res.starts.length, 2);
  assert.deepEqual(res.starts.map((s) => s.start[0]), [0.0215, 0.5 * (res.parameters[0].min + res.parameters[0].max)]);
  assert.equal(res.starts[res.best_start].value[0], res.parameters[0].value);
  assert.ok(res.starts.every((s) => s.chi2 >= res.starts[res.best_start].chi2));
  assert.equal(res.rejected, 0);
  // the band: around the fitted curve, as wide as t(3 dof) times e's error moves v
  const { fit, band } = res.curve.cw;
  assert.ok(res.curve.band_quantile > 3.18 && res.curve.band_quantile < 3.19, String(res.curve.band_quantile));
  for (let k = 0; k < fit.length; k++) assert.ok(band.lower[k] < fit[k] && fit[k] < band.upper[k], `${k}: ${band.lower[k]} ${fit[k]} ${band.upper[k]}`);
  const csv = await req(d.base, 'GET', `${path}?format=csv`);
  assert.equal(csv.status, 200);
  const lines = csv.text.trim().split('\n');
  assert.equal(lines[0], 'kind,name,beta,rotation,measured,sigma,model,uncertainty,residual,start,band_lower,band_upper');
  assert.equal(Number(lines[1].split(',')[6]), res.parameters[0].value);
  const c45 = lines.find((l) => l.startsWith('curve,,45,')).split(',');
  assert.deepEqual(c45.slice(10).map(Number), [band.lower[1], band.upper[1]]);
  assert.equal(lines.length, 1 + 1 + 4 + 5);
  const list = await req(d.base, 'GET', '/api/v1/fits');
  assert.ok(list.body.fits.some((f) => f.id === r.body.id && f.state === 'done' && f.result === null));
  const lc = await req(d.base, 'GET', '/api/v1/fits?format=csv');
  assert.match(lc.text, new RegExp(`^fit,state,phase,iteration,evaluations,cost\\n[\\s\\S]*${r.body.id},done,done,`));
  assert.equal((await req(d.base, 'DELETE', path, undefined, JSON_CT)).status, 204);
  assert.equal((await req(d.base, 'GET', path)).status, 404);
});

test("a prior: the fit between it and the data, the prior in the result, chi2 the data's share", { timeout: 240000 * SLOW }, async () => {
  const withSigma = POINTS.map((p) => ({ ...p, sigma: 0.005 }));
  const fit = async (free) => {
    const r = await req(d.base, 'POST', '/api/v1/fits', body({ points: withSigma, free, curve_step: 0 }));
    assert.equal(r.status, 202, r.text);
    const path = `/api/v1/fits/${r.body.id}`;
    const done = await until(async () => {
      const g = await req(d.base, 'GET', path);
      return g.body.state === 'done' && g.body;
    }, 200000 * SLOW, 'the fit');
    assert.equal((await req(d.base, 'DELETE', path, undefined, JSON_CT)).status, 204);
    return done.result;
  };
  const plain = await fit(['e']);
  const p0 = plain.parameters[0];
  assert.equal(p0.prior, null);
  assert.equal(plain.chi2_prior, 0);
  // a prior at the data's own optimum with their standard error: the value
  // stays, and the posterior's error is the data's over the root of 2
  const prior = { mean: p0.value, sd: p0.standard_error };
  const both = await fit([{ name: 'e', prior }]);
  const p1 = both.parameters[0];
  assert.deepEqual(p1.prior, prior);
  assert.ok(Math.abs(p1.value - p0.value) < 0.1 * p0.standard_error, `${p1.value} against ${p0.value}`);
  const ratio = p1.standard_error / (p0.standard_error / Math.SQRT2);
  assert.ok(Math.abs(ratio - 1) < 0.02, `posterior se over se / sqrt 2: ${ratio}`);
  assert.equal(both.chi2_prior, ((p1.value - prior.mean) / prior.sd) ** 2);
  assert.equal(both.starts[both.best_start].chi2, both.chi2);
  // a log-normal prior is echoed with its factor
  const logn = await fit([{ name: 'e', min: 0.001, max: 0.1, prior: { mean: 0.02, factor: 1.5 } }]);
  assert.deepEqual(logn.parameters[0].prior, { mean: 0.02, factor: 1.5 });
  const r = Math.log(logn.parameters[0].value / 0.02) / Math.log(1.5);
  assert.ok(Math.abs(logn.chi2_prior - r * r) < 1e-12 * Math.max(1, r * r), `${logn.chi2_prior} against ${r * r}`);
});

test('DELETE cancels a running fit', { timeout: 120000 * SLOW }, async () => {
  // the default scene and many points: far longer than the test waits
  const pts = [];
  for (let b = 5; b < 180; b += 10) pts.push({ beta: b, rotation: 'cw', v: 0.05 }, { beta: b, rotation: 'ccw', v: -0.05 });
  const r = await req(d.base, 'POST', '/api/v1/fits', { free: ['e', 'mu'], points: pts });
  assert.equal(r.status, 202, r.text);
  const path = `/api/v1/fits/${r.body.id}`;
  await until(async () => (await req(d.base, 'GET', path)).body.evaluations > 0, 60000 * SLOW, 'first evaluations');
  assert.equal((await req(d.base, 'DELETE', path, undefined, JSON_CT)).status, 204);
  assert.equal((await req(d.base, 'GET', path)).status, 404);
  assert.ok(!(await req(d.base, 'GET', '/api/v1/fits')).body.fits.some((f) => f.id === r.body.id));
  // the driver stops after the evaluations already running
  await until(async () => d.stderr().includes(`fit ${r.body.id}: cancelled`), 30000 * SLOW, 'the driver to stop');
});

// Fits persist like sweeps (--data-dir): after a kill -9 and a restart a
// finished fit answers byte for byte as before, a running one runs again
// from its start, and a deleted one leaves no file behind.
test('fits outlive a kill -9: finished ones served as they were, running ones run again', { timeout: 240000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-fits-'));
  const args = ['--data-dir', dir, '--log-level', 'info'];
  let p = await startDaemon(args);
  try {
    const r = await req(p.base, 'POST', '/api/v1/fits', body({ t_end: 1, points: POINTS.slice(0, 2) }));
    assert.equal(r.status, 202, r.text);
    const path = `/api/v1/fits/${r.body.id}`;
    await until(async () => (await req(p.base, 'GET', path)).body.state === 'done', 100000 * SLOW, 'the fit');
    const before = {
      json: (await req(p.base, 'GET', path)).text,
      csv: (await req(p.base, 'GET', `${path}?format=csv`)).text,
      list: (await req(p.base, 'GET', '/api/v1/fits?format=csv')).text,
    };
    // the default scene and many points: still running when killed
    const pts = [];
    for (let b = 5; b < 180; b += 10) pts.push({ beta: b, rotation: 'cw', v: 0.05 });
    const long = await req(p.base, 'POST', '/api/v1/fits', { free: ['e', 'mu'], points: pts });
    assert.equal(long.status, 202, long.text);
    const longPath = `/api/v1/fits/${long.body.id}`;
    await until(async () => (await req(p.base, 'GET', longPath)).body.evaluations > 0, 60000 * SLOW, 'first evaluations');
    assert.ok(existsSync(join(dir, 'fits', `${long.body.id}.bin`)), 'the running fit\'s record');
    p.proc.kill('SIGKILL');
    await p.exited;

    p = await startDaemon(args);
    assert.equal((await req(p.base, 'GET', path)).text, before.json);
    assert.equal((await req(p.base, 'GET', `${path}?format=csv`)).text, before.csv);
    const g = await req(p.base, 'GET', longPath);
    assert.equal(g.status, 200, g.text);
    assert.ok(['queued', 'running'].includes(g.body.state), g.text);
    assert.equal(g.body.result, null);
    await until(async () => (await req(p.base, 'GET', longPath)).body.evaluations > 0, 60000 * SLOW, 'evaluations again');
    // the finished fit's row as it was (the restore's order is the directory's)
    const row = before.list.trim().split('\n')[1];
    assert.ok((await req(p.base, 'GET', '/api/v1/fits?format=csv')).text.split('\n').includes(row), row);
    assert.equal((await req(p.base, 'DELETE', longPath, undefined, JSON_CT)).status, 204);
    await until(async () => !existsSync(join(dir, 'fits', `${long.body.id}.bin`)), 10000 * SLOW, 'the deleted fit\'s record to go');
    // and it stays gone once its driver has stopped
    await until(async () => p.stderr().includes(`fit ${long.body.id}: cancelled`), 30000 * SLOW, 'the driver to stop');
    assert.equal((await p.stop()).code, 0, p.stderr());
    assert.ok(!existsSync(join(dir, 'fits', `${long.body.id}.bin`)));
    assert.ok(existsSync(join(dir, 'fits', `${r.body.id}.bin`)));
  } finally {
    await p.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});
