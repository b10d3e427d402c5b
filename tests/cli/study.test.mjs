// SPDX-License-Identifier: GPL-3.0-or-later
// Studies over any setting (`convsim sweep --vary`, `--lhs`): a 2-D
// study's points equal single runs at those settings bit for bit; the
// columns are the varied settings by name; the mirror reduction pairs
// points that differ in sense and beta alone, on a symmetric machine;
// the Latin hypercube is seeded, repeatable and puts one point in each
// stratum of each range; a setting that does not exist or a value out of
// its range is refused with exit 2 before anything runs. CONVSIM names
// the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const run = (...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: 300000 });
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const FAST = ['--duration', '0.4', '-q'];
const MEASURED = ['velocity', 'uncertainty', 'steady', 'dt', 'substeps', 'step_error', 'tol_met'];

test('a 2-D study (mu x beta): every point equals a single run at its settings, bit for bit', () => {
  const r = run('sweep', '--vary', 'mu=0.2,0.9', '--vary', 'beta=30:150:120', '--rotation', 'cw',
    '-f', 'json', ...FAST);
  assert.equal(r.code, 0, r.err);
  const study = JSON.parse(r.out);
  assert.deepEqual(study.vary.map((a) => a.name), ['mu', 'beta']);
  assert.deepEqual(study.vary[0].values, [0.2, 0.9]);
  assert.deepEqual(study.points.map((p) => [p.mu, p.beta]), [[0.2, 30], [0.2, 150], [0.9, 30], [0.9, 150]]);
  const vs = new Set(study.points.map((p) => p.velocity));
  assert.equal(vs.size, 4, 'four settings, four different velocities');
  let ran = 0;
  for (const p of study.points) {
    const alone = run('sweep', '--vary', `mu=${p.mu}`, '--beta', `${p.beta}`, '--rotation', 'cw',
      '-f', 'json', ...FAST);
    assert.equal(alone.code, 0, alone.err);
    const q = JSON.parse(alone.out).points[0];
    for (const k of MEASURED) assert.equal(q[k], p[k], `mu ${p.mu} beta ${p.beta}: ${k}`);
    // `run` is one simulation at the scene's steps: the same where the
    // study's measurement did not refine them
    const single = run('run', '--set', `mu=${p.mu}`, '--beta', `${p.beta}`, '--rotation', 'cw', ...FAST);
    assert.equal(single.code, 0, single.err);
    const s = JSON.parse(single.out);
    if (s.integrator.dt !== p.dt) continue;
    ran++;
    assert.equal(s.transport_velocity, p.velocity, `run at mu ${p.mu} beta ${p.beta}`);
    assert.equal(s.transport_velocity_uncertainty, p.uncertainty);
  }
  assert.ok(ran >= 2, `${ran} points at the scene's steps`);
});

test('the CSV: the varied settings by name, then rotation and the point columns, one row per point', () => {
  const r = run('sweep', '--vary', 'e=0.01,0.02', '--vary', 'k_c=1e5:2e5:1e5', '--beta', '60',
    '--rotation', 'ccw', '--set', 'feed=false', ...FAST);
  assert.equal(r.code, 0, r.err);
  const lines = r.out.trim().split('\n');
  // --beta is --vary beta=... in its place
  assert.equal(lines[0], 'e,k_c,beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
  assert.deepEqual(lines.slice(1).map((l) => l.split(',').slice(0, 4).join(',')),
    ['0.01,100000,60,ccw', '0.01,200000,60,ccw', '0.02,100000,60,ccw', '0.02,200000,60,ccw']);
  // a range's values are the decimals a user means
  const d = run('sweep', '--vary', 'mu=0.2:0.6:0.2', '--beta', '30', '--set', 'feed=false', '--rotation', 'cw', ...FAST);
  assert.deepEqual(d.out.trim().split('\n').slice(1).map((l) => l.split(',')[0]), ['0.2', '0.4', '0.6']);
});

test('the mirror reduction pairs (cw, beta) with (ccw, 180 - beta) at the same other settings, only where the machine is symmetric', () => {
  const r = run('sweep', '--vary', 'h=0,0.05', '--vary', 'beta=30,150', '-f', 'json', ...FAST);
  assert.equal(r.code, 0, r.err);
  const s = JSON.parse(r.out);
  assert.deepEqual(s.reductions, ['mirror']);
  const at = (h, beta, rot) => s.points.find((p) => p.h === h && p.beta === beta && p.rotation === rot);
  assert.equal(s.points.length, 8);
  for (const beta of [30, 150]) {
    const img = at(0, beta, 'ccw'), src = at(0, 180 - beta, 'cw');
    assert.equal(img.mirrored, true);
    assert.equal(img.velocity, -src.velocity);
    assert.equal(at(0.05, beta, 'ccw').mirrored, false, 'h = 0.05 breaks the symmetry');
  }
  assert.equal(s.points.filter((p) => p.mirrored).length, 2);
});

test('--lhs N: a seeded Latin hypercube over the --vary ranges, one point in each stratum', () => {
  const args = ['sweep', '--vary', 'mu=0.2:1.2:0.1', '--vary', 'beta=10:170:10', '--lhs', '6',
    '--rotation', 'cw', '--set', 'feed=false', '-f', 'json', ...FAST];
  const a = run(...args, '--seed', '11'), b = run(...args, '--seed', '11'), c = run(...args, '--seed', '12');
  assert.equal(a.code, 0, a.err);
  assert.equal(a.out, b.out, 'the same seed, the same study');
  const pa = JSON.parse(a.out), pc = JSON.parse(c.out);
  assert.equal(pa.lhs, 6);
  assert.equal(pa.seed, 11);
  assert.equal(pa.points.length, 6);
  assert.notDeepEqual(pa.points.map((p) => p.mu), pc.points.map((p) => p.mu), 'another seed, another sample');
  for (const [name, from, to] of [['mu', 0.2, 1.2], ['beta', 10, 170]]) {
    const strata = pa.points.map((p) => Math.floor((p[name] - from) / (to - from) * 6)).sort();
    assert.deepEqual(strata, [0, 1, 2, 3, 4, 5], `${name}: one point per stratum`);
  }
});

test('a setting that does not exist, or a value out of its range: exit 2 naming it, nothing run', () => {
  for (const [args, re] of [
    [['--vary', 'muu=0:1:0.5'], /^convsim sweep: --vary muu=0:1:0\.5: unknown setting 'muu' \(did you mean 'mu'\?\)/],
    [['--vary', 'mu=0:3:1'], /^convsim sweep: --vary mu=0:3:1: mu must be a finite number in \[0, 2\]/],
    [['--vary', 'e=0.01,0.7'], /^convsim sweep: --vary e=0\.01,0\.7: e must be a finite number in \[0, 0\.5\] m/],
    [['--vary', 'columns=1,2.5'], /columns must be an integer in \[1, 64\]/],
    [['--vary', 'rotation=0,1'], /rotation is not varied as a setting/],
    [['--vary', 'drive=0,1'], /drive is a choice, not a number/],
    [['--vary', 'mu=1:0:0.1'], /mu: a range needs FROM <= TO and STEP > 0/],
    [['--vary', 'mu=0.1,x'], /a list is numbers separated by commas/],
    [['--beta', '10', '--vary', 'beta=20,30'], /beta is varied twice/],
    [['--vary', 'mu=0.1,0.2', '--lhs', '3'], /mu: a Latin-hypercube sample needs a range/],
    [['--vary', 'mu=0:2:0.01', '--vary', 'beta=0:180:1'], /the study has 36381 points; at most 10000/],
    [['--vary', 'transient=0,10', '--duration', '4'], /^convsim sweep: --duration \(4 s\) must exceed the largest transient the study varies \(10 s\)/],
  ]) {
    const r = run('sweep', ...args);
    assert.equal(r.code, 2, `${args.join(' ')}: ${r.err}`);
    assert.equal(r.out, '');
    assert.match(r.err, re);
    assert.doesNotMatch(r.err, /^sweep: /m, 'nothing ran');
  }
});

test('help sweep lists --vary, --lhs and --seed', () => {
  const h = run('help', 'sweep').out;
  assert.match(h, /--vary NAME=FROM:TO:STEP\|NAME=V1,V2,\.\.\./);
  assert.match(h, /--lhs N[\s\S]*default: the full grid/);
  assert.match(h, /--seed S[\s\S]*default: 1/);
});
