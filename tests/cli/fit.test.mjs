// SPDX-License-Identifier: GPL-3.0-or-later
// `convsim fit` as a user meets it: bad input refused before anything runs
// (exit 2, a message naming the option and the problem, nothing on stdout),
// and a small fit on a cheap scene whose result carries the values, their
// standard errors, the residuals and the curves in JSON and CSV, the same
// for the same data. CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const SLOW = Number(process.env.CONVSIM_TEST_SLOW || (process.env.BUILD === 'build-san' ? 4 : 1));
const run = (...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: 200000 * SLOW });
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const dir = mkdtempSync(join(tmpdir(), 'convsim-fit-'));
const file = (name, text) => { const p = join(dir, name); writeFileSync(p, text); return p; };
const CHEAP = ['--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '--duration', '2'];

test('bad input: exit 2 with a message naming the problem, nothing on stdout', () => {
  const good = file('good.csv', 'beta,rotation,v\n30,cw,0.1\n60,cw,0.05\n120,cw,-0.07\n');
  const cases = [
    // a point out of range is named by the file and its line, as a row that does not parse
    // (nan is no number there: tests/cli/numbers.test.mjs)
    [['--data', file('nan.csv', 'beta,rotation,v\nnan,cw,0.1\n60,cw,0.05\n'), '--free', 'e'],
     /^convsim fit: --data \S*nan\.csv: CSV line 2: beta must be a number, got 'nan'$/m],
    [['--data', file('far.csv', 'beta,rotation,v\n30,cw,0.1\n190,cw,0.05\n'), '--free', 'e'],
     /^convsim fit: --data \S*far\.csv: CSV line 3: beta must be a finite number in \[0, 180\] deg$/m],
    [['--data', file('fast.csv', 'beta,rotation,v\n# rig 2\n\n30,cw,0.1\n\n60,cw,150\n'), '--free', 'e'],
     /^convsim fit: --data \S*fast\.csv: CSV line 6: v must be a finite number in \[-100, 100\] m\/s$/m],
    [['--data', file('gap.csv', 'beta,rotation,v\n30,cw,0.1\n\n\n60,cw,abc\n'), '--free', 'e'],
     /^convsim fit: --data \S*gap\.csv: CSV line 5: v must be a number, got 'abc'$/m],
    [['--data', file('rot.csv', 'beta,rotation,v\n30,cw,0.1\n60, x ,0.05\n'), '--free', 'e'],
     /^convsim fit: --data \S*rot\.csv: CSV line 3: rotation must be cw or ccw, got 'x'$/m],
    [['--data', good, '--free', 'ee'], /--free: unknown parameter 'ee' \(did you mean 'e'\?\)/],
    [['--data', good, '--free', 'rotation'], /--free: 'rotation' cannot be fitted/],
    [['--data', good, '--free', 'beta'], /--free: 'beta' cannot be fitted/],
    [['--data', good, '--free', 'layers'], /--free: 'layers' cannot be fitted/],
    [['--data', file('one.csv', 'beta,rotation,v\n30,cw,0.1\n'), '--free', 'e,mu'],
     /1 data for 2 free parameters/],
    [['--data', file('dup.csv', 'beta,rotation,v\n30,cw,0.1\n\n30,cw,0.11\n'), '--free', 'e'],
     /^convsim fit: --data \S*dup\.csv: CSV line 4 duplicates CSV line 2 \(beta 30 deg, cw\)$/m],
    [['--data', file('col.csv', 'beta,v\n30,0.1\n60,0.05\n'), '--free', 'e'],
     /CSV line 1: column 'rotation' is missing/],
    [['--data', join(dir, 'absent.csv'), '--free', 'e'], /cannot read .*absent\.csv/],
    [['--data', good], /--free is required/],
    [['--free', 'e'], /give --data FILE \(points\) or --peaks/],
    [['--peaks', 'cw:38,up:128', '--free', 'e'], /--peaks takes .* got 'up:128'/],
    [['--data', good, '--free', 'e:0.1:0.01'], /bounds of 'e' must satisfy/],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02:0.002'],
      /--prior: a prior \(on 'e'\) needs the data's sigma, to weigh the two against each other: give sigma with every point$/m],
    [['--data', good, '--free', 'e', '--prior', 'mu:0.3:0.1'],
      /--prior: a prior on 'mu', which is not a free parameter: name it in free first$/m],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02'], /--prior takes NAME:MEAN:SD \(normal\) or NAME:MEAN:xFACTOR \(log-normal\).* got 'e:0.02'$/m],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02:x0.5'], /--prior: the prior's factor of 'e' must be in \(1, 1e6\]$/m],
    [['--data', good, '--free', 'e', '--prior', 'e:-1:x2'], /--prior: the prior's mean of 'e' must lie within its bounds \[0, 0.5\] m and be positive$/m],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02:0.002,e:0.02:0.002'], /--prior: 'e' has a prior already$/m],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02:x2'], /--prior: a log-normal prior on 'e' needs a positive lower bound: free it as e:MIN:MAX with MIN > 0$/m],
  ];
  for (const [args, re] of cases) {
    const r = run('fit', ...args, '-q');
    assert.equal(r.code, 2, `${args.join(' ')}: ${r.err}`);
    assert.equal(r.out, '', args.join(' '));
    assert.match(r.err, /^convsim fit: /);
    assert.match(r.err, re);
  }
});

test('a one-parameter fit: values, errors, residuals and curves in JSON and CSV', { timeout: 300000 * SLOW }, () => {
  // data from the model itself at e = 0.018: the fit from e = 0.0215 goes back there
  const made = run('sweep', ...CHEAP, '--set', 'e=0.018', '--beta', '20:140:40', '--rotation', 'cw', '-q');
  assert.equal(made.code, 0, made.err);
  const rows = made.out.trim().split('\n').slice(1).map((l) => l.split(','));
  const csv = 'beta,rotation,v\n' + rows.map((c) => `${c[0]},${c[1]},${c[2]}`).join('\n') + '\n';
  const data = file('made.csv', csv);
  const r = run('fit', ...CHEAP, '--data', data, '--free', 'e', '--curve-step', '60', '-q');
  assert.equal(r.code, 0, r.err);
  const res = JSON.parse(r.out);
  assert.equal(res.status, 'converged');
  assert.equal(res.standard_errors_from, 'residual variance');
  const e = res.parameters[0];
  assert.equal(e.name, 'e');
  assert.equal(e.start, 0.0215);
  assert.ok(Math.abs(e.value - 0.018) < 3e-4, `e = ${e.value}`);
  assert.ok(e.standard_error > 0 && e.standard_error < 3e-4, `se = ${e.standard_error}`);
  assert.equal(res.points.length, 4);
  for (const p of res.points) assert.ok(Math.abs(p.residual) < 0.003, JSON.stringify(p));
  assert.deepEqual(res.curve.beta, [0, 60, 120, 180]);
  assert.equal(res.curve.cw.fit.length, 4);
  // the original curve is the faster one (v grows with e)
  assert.ok(res.curve.cw.start[1] > res.curve.cw.fit[1]);
  const c = run('fit', ...CHEAP, '--data', data, '--free', 'e', '--curve-step', '60', '-q', '--format', 'csv');
  assert.equal(c.code, 0, c.err);
  const lines = c.out.trim().split('\n');
  assert.equal(lines[0], 'kind,name,beta,rotation,measured,sigma,model,uncertainty,residual,start,band_lower,band_upper');
  const par = lines[1].split(',');
  assert.deepEqual(par.slice(0, 6), ['parameter', 'e', '', '', '', '']);
  assert.equal(Number(par[6]), e.value);
  assert.equal(Number(par[7]), e.standard_error);
  assert.equal(Number(par[9]), 0.0215);
  assert.equal(lines.filter((l) => l.startsWith('point,')).length, 4);
  assert.equal(lines.filter((l) => l.startsWith('curve,')).length, 4);
});

test('the peaks fit that used to stop at a peak outside its scan converges', { timeout: 600000 * SLOW }, () => {
  // e and mu to the paper's clockwise peaks: a trial step used to move the peak at 128 deg
  // out of its +-10 deg scan and end the fit with the start values and standard errors 0
  const r = run('fit', '--peaks', 'cw:38,cw:128', '--free', 'e:0.005:0.04,mu:0.1:1.5', '--curve-step', '0', '-q');
  assert.equal(r.code, 0, r.err);
  const res = JSON.parse(r.out);
  assert.equal(res.status, 'converged', res.error);
  assert.equal(res.error, null);
  assert.ok(res.iterations > 1, `${res.iterations} iterations`);
  for (const p of res.peaks) assert.ok(Math.abs(p.residual) < 1.5, JSON.stringify(p));
  // two peaks, two parameters: no residual variance, so no standard errors (null, never 0)
  for (const p of res.parameters) {
    assert.equal(p.standard_error, null);
    assert.notEqual(p.value, p.start);
  }
  assert.deepEqual(res.starts.map((s) => s.status), ['converged']);
});

test('a prior: a tight one pins the value, a broad one changes nothing, between them the linearised posterior', { timeout: 300000 * SLOW }, () => {
  const made = run('sweep', ...CHEAP, '--set', 'e=0.018', '--beta', '20:140:40', '--rotation', 'cw', '-q');
  assert.equal(made.code, 0, made.err);
  const rows = made.out.trim().split('\n').slice(1).map((l) => l.split(','));
  const data = file('sigma.csv', 'beta,rotation,v,sigma\n' + rows.map((c) => `${c[0]},${c[1]},${c[2]},0.001`).join('\n') + '\n');
  const fit = (...prior) => {
    const r = run('fit', ...CHEAP, '--data', data, '--free', 'e', '--curve-step', '0', '-q', ...prior);
    assert.equal(r.code, 0, r.err);
    const res = JSON.parse(r.out);
    assert.equal(res.status, 'converged', res.error);
    return res;
  };
  const none = fit();
  const x0 = none.parameters[0].value, se0 = none.parameters[0].standard_error;
  assert.equal(none.standard_errors_from, 'sigma');
  // a prior a thousand times tighter than the data: the value is its mean, the error its sd
  const tight = fit('--prior', 'e:0.02:1e-7');
  assert.ok(Math.abs(tight.parameters[0].value - 0.02) < 2e-7, String(tight.parameters[0].value));
  assert.ok(Math.abs(tight.parameters[0].standard_error / 1e-7 - 1) < 0.01, String(tight.parameters[0].standard_error));
  assert.deepEqual(tight.parameters[0].prior, { mean: 0.02, sd: 1e-7 });
  // a prior far broader than the data: nothing moves
  const broad = fit('--prior', 'e:0.02:1');
  assert.ok(Math.abs(broad.parameters[0].value - x0) < 0.01 * se0);
  assert.ok(Math.abs(broad.parameters[0].standard_error / se0 - 1) < 1e-3);
  // in between: the precision-weighted mean and 1/se^2 = 1/se0^2 + 1/sd^2,
  // as the model is linear in e over a few standard errors
  const sd = 5e-4;
  const mid = fit('--prior', `e:0.02:${sd}`);
  const w0 = 1 / se0 ** 2, w1 = 1 / sd ** 2;
  const se = 1 / Math.sqrt(w0 + w1);
  assert.ok(Math.abs(mid.parameters[0].value - (w0 * x0 + w1 * 0.02) / (w0 + w1)) < 0.3 * se,
    `${mid.parameters[0].value} against ${(w0 * x0 + w1 * 0.02) / (w0 + w1)}`);
  assert.ok(Math.abs(mid.parameters[0].standard_error / se - 1) < 0.02, `${mid.parameters[0].standard_error} against ${se}`);
  assert.equal(mid.chi2_prior, ((mid.parameters[0].value - 0.02) / sd) ** 2);
  assert.ok(mid.chi2 > none.chi2, 'the prior pulls away from the data');
});
