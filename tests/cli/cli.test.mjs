// SPDX-License-Identifier: GPL-3.0-or-later
// The command line as a user meets it: help on stdout with exit 0 for
// `help CMD` and `CMD --help`, every option with its default and unit;
// --version; errors on stderr prefixed "convsim CMD:", specific, with a
// suggestion for near-miss names and exit 2; progress as plain lines when
// stderr is not a terminal. CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const run = (...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: 120000 });
  return { code: r.status, out: r.stdout, err: r.stderr };
};

test('help CMD and CMD --help list every option with default and unit on stdout', () => {
  const expect = {
    run: ['--preset', '--set', '--duration', '--out', '--format', '--sample-rate', '--quiet', '--help'],
    sweep: ['--preset', '--set', '--duration', '--out', '--format', '--beta', '--rotation', '--threads', '--quiet', '--help'],
    list: ['--help'],
  };
  for (const [cmd, flags] of Object.entries(expect)) {
    const a = run('help', cmd), b = run(cmd, '--help'), c = run(cmd, '-h');
    for (const r of [a, b, c]) {
      assert.equal(r.code, 0, cmd);
      assert.equal(r.err, '');
      assert.equal(r.out, a.out);
    }
    for (const f of flags) assert.match(a.out, new RegExp(`${f}\\b`), `${cmd} ${f}`);
  }
  const h = run('help', 'sweep').out;
  assert.match(h, /--beta FROM:TO:STEP[\s\S]*unit: deg; default: 0:180:10/);
  assert.match(h, /--duration S[\s\S]*unit: s; default: transient \+ 4/);
  assert.match(h, /--threads N[\s\S]*default: 2/);
  assert.match(run('help', 'run').out, /--sample-rate HZ[\s\S]*unit: Hz; default: 1000/);
  // every preset --preset takes (liggghts-bed4 was left out)
  for (const cmd of ['run', 'sweep', 'fit'])
    assert.match(run('help', cmd).out, /--preset NAME +starting values for every setting \(known: czubak2016, czubak2016-fit, liggghts-bed4\)\n/, cmd);
  for (const args of [['help'], ['--help'], ['-h']]) {
    const r = run(...args);
    assert.equal(r.code, 0);
    assert.match(r.out, /commands:[\s\S]*run[\s\S]*sweep[\s\S]*list/);
  }
  const v = run('--version');
  assert.equal(v.code, 0);
  assert.match(v.out, /^convsim \d+\.\d+\.\d+\n$/);
});

test('errors are prefixed, specific, suggest near misses and exit 2', () => {
  const cases = [
    [['run', '--fromat', 'csv'], /^convsim run: unknown or ambiguous option '--fromat' \(did you mean '--format'\?\)/],
    [['run', '--set', 'bta=30'], /^convsim run: --set bta=30: unknown setting 'bta' \(did you mean 'beta'\?\)/],
    [['run', '--set', 'foo=1'], /^convsim run: --set foo=1: unknown setting 'foo'; 'convsim list' shows every setting/],
    [['run', '--set', 'beta=200'], /^convsim run: --set beta=200: beta must be a finite number in \[0, 180\] deg/],
    [['run', '--duration'], /^convsim run: option --duration needs an argument/],
    [['run', '--duration', 'abc'], /^convsim run: --duration must be a number of seconds in \(0, 100000\], got 'abc'/],
    [['run', '--preset', 'czubak'], /^convsim run: --preset: unknown preset 'czubak' \(did you mean 'czubak2016'\?\)/],
    [['sweep', '--rotation', 'cww'], /^convsim sweep: --rotation takes cw, ccw or cw,ccw; 'cww' is not one \(did you mean 'cw'\?\)/],
    [['sweep', '--beta', '0:200:5'], /^convsim sweep: --beta must be FROM:TO:STEP in degrees/],
    [['sweep', '--threads', '0'], /^convsim sweep: --threads must be a number in \[1, 64\], got '0'/],
    [['rn'], /^convsim: unknown command 'rn' \(did you mean 'run'\?\)/],
    [['help', 'swep'], /^convsim: unknown command 'swep' \(did you mean 'sweep'\?\)/],
    [['list', 'extra'], /^convsim list: unexpected argument 'extra'/],
  ];
  for (const [args, re] of cases) {
    const r = run(...args);
    assert.equal(r.code, 2, args.join(' '));
    assert.equal(r.out, '', args.join(' '));
    assert.match(r.err, re, args.join(' '));
  }
  const r = run('run', '--duration', '0.01', '--out', '/nonexistent/x.csv');
  assert.equal(r.code, 1);
  assert.match(r.err, /^convsim run: --out: cannot write '\/nonexistent\/x.csv': No such file or directory/);
  const none = run();
  assert.equal(none.code, 2);
  assert.match(none.err, /usage: convsim COMMAND/);
});

test('sweep: plain progress lines off a terminal, the table to --out', () => {
  const out = join(mkdtempSync(join(tmpdir(), 'convsim-cli-')), 'v.csv');
  const r = run('sweep', '--beta', '30:60:30', '--rotation', 'cw', '--duration', '0.3',
    '--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '--out', out, '-j', '1');
  assert.equal(r.code, 0, r.err);
  assert.equal(r.out, '');
  assert.doesNotMatch(r.err, /\r/);
  assert.match(r.err, /^sweep: 1\/2 points \(50 %\)/m);
  assert.match(r.err, /^sweep: 2\/2 points in [\d.]+ s$/m);
  const lines = readFileSync(out, 'utf8').trim().split('\n');
  assert.equal(lines[0], 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
  // the preset's 2-layer bed is in the DEM map: its model error, checked
  assert.match(lines[1], /^30,cw,0\.\d+,\d\.\d+(e-\d+)?,(true|false),done,\d\.\d+(e-\d+)?,\d+,\d\.\d+(e-\d+)?,(true|false),0\.\d+,0\.\d+,true$/);
  const q = run('sweep', '--beta', '30', '--rotation', 'cw', '--duration', '0.3', '-q',
    '--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '-f', 'json');
  assert.equal(q.err, '');
  assert.equal(JSON.parse(q.out).points[0].state, 'done');
});

test('run takes --beta DEG and --rotation cw|ccw as sweep does, the same as --set', () => {
  const args = ['run', '--duration', '0.5', '-q', '--set', 'feed=false'];
  const summary = (...more) => {
    const r = run(...args, ...more);
    assert.equal(r.code, 0, r.err);
    return JSON.parse(r.out);
  };
  const byOption = summary('--beta', '30', '--rotation', 'ccw');
  const bySet = summary('--set', 'beta=30', '--set', 'rotation=ccw');
  assert.equal(byOption.rotor_speed, bySet.rotor_speed);
  assert.ok(byOption.rotor_speed < -100, `ccw turns the rotor backwards: ${byOption.rotor_speed}`);
  assert.ok(summary('-b', '30').rotor_speed > 100, 'the preset is clockwise');
  assert.equal(summary('-b', '30').transport_velocity, summary('--set', 'beta=30').transport_velocity);
  /* as given: 30, not 29.999999999999996 (the degrees a radian came from) */
  assert.match(run(...args, '--beta', '30').out, /"beta": 30,/);
  let r = run('run', '--beta', '181');
  assert.equal(r.code, 2);
  assert.match(r.err, /^convsim run: --beta 181: beta must be a finite number in \[0, 180\] deg/);
  r = run('run', '--rotation', 'up');
  assert.equal(r.code, 2);
  assert.match(r.err, /^convsim run: --rotation up: rotation must be one of cw\|ccw/);
});
