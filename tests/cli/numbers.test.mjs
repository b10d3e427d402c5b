// SPDX-License-Identifier: GPL-3.0-or-later
// A number given as text is a plain decimal number (core/decimal.h:
// sign, digits, point, exponent), wherever convsim reads one: an option's
// value, a --set, a --beta or --vary range, --free, --prior and --peaks,
// and a cell of a --data CSV file. What strtod would also have read
// (0x10 as 16, 0x1p4, spaces, inf) exits 2 with the option's or the
// line's usual message, nothing on stdout. CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const run = (...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: 120000 });
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const dir = mkdtempSync(join(tmpdir(), 'convsim-numbers-'));
const file = (name, text) => { const p = join(dir, name); writeFileSync(p, text); return p; };
const CHEAP = ['--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2'];

test('an option, a --set and a range take a plain decimal number only: exit 2, the usual message', () => {
  const beta = (v) => `convsim run: --set beta=${v}: beta must be a finite number in [0, 180] deg; ` +
    "'convsim list' shows every setting\n";
  const sweepBeta = (v) => 'convsim sweep: --beta must be FROM:TO:STEP in degrees with 0 <= FROM ' +
    `<= TO <= 180 and STEP > 0 (or one angle), got '${v}'\n`;
  const cases = [
    [['run', '--duration', '0x10'], "convsim run: --duration must be a number of seconds in (0, 100000], got '0x10'\n"],
    [['run', '--duration', '0x1p4'], "convsim run: --duration must be a number of seconds in (0, 100000], got '0x1p4'\n"],
    [['run', '--duration', ' 5'], "convsim run: --duration must be a number of seconds in (0, 100000], got ' 5'\n"],
    [['run', '--duration', '5 '], "convsim run: --duration must be a number of seconds in (0, 100000], got '5 '\n"],
    [['run', '--duration', '1e'], "convsim run: --duration must be a number of seconds in (0, 100000], got '1e'\n"],
    [['run', '--sample-rate', 'infinity'], "convsim run: --sample-rate must be a number of Hz in (0, 1e+06], got 'infinity'\n"],
    [['sweep', '--threads', '0x2'], "convsim sweep: --threads must be a number in [1, 64], got '0x2'\n"],
    [['run', '--set', 'beta=0x1e'], beta('0x1e')],
    [['run', '--set', 'beta= 30'], beta(' 30')],
    [['run', '--set', 'beta=30 '], beta('30 ')],
    [['run', '--set', 'beta=0x1p4'], beta('0x1p4')],
    [['run', '--beta', '0x1e'], "convsim run: --beta 0x1e: beta must be a finite number in [0, 180] deg; 'convsim list' shows every setting\n"],
    [['sweep', '--beta', '0x10'], sweepBeta('0x10')],
    [['sweep', '--beta', '0:0x5a:10'], sweepBeta('0:0x5a:10')],
    [['sweep', '--beta', '0: 90:10'], sweepBeta('0: 90:10')],
    [['sweep', '--vary', 'mu=0x1,0.2'], "convsim sweep: --vary mu=0x1,0.2: a list is numbers separated by commas; 'convsim list' shows every setting\n"],
    [['sweep', '--vary', 'mu=0:1:0x1'], "convsim sweep: --vary mu=0:1:0x1: a range is FROM:TO:STEP, three numbers; 'convsim list' shows every setting\n"],
  ];
  for (const [args, message] of cases) {
    const r = run(...args);
    assert.equal(r.code, 2, `${args.join(' ')}: ${r.err}`);
    assert.equal(r.out, '', args.join(' '));
    assert.equal(r.err, message, args.join(' '));
  }
});

test('fit: --free, --prior, --peaks and the --data CSV take plain decimal numbers only', () => {
  const good = file('good.csv', 'beta,rotation,v\n30,cw,0.1\n60,cw,0.05\n120,cw,-0.07\n');
  const data = (name, text) => ['--data', file(name, text)];
  const prior = (v) => "convsim fit: --prior takes NAME:MEAN:SD (normal) or NAME:MEAN:xFACTOR " +
    `(log-normal), e.g. R:0.5:0.1,k_c:3000:x3; got '${v}'\n`;
  const csv = (name, line, what) => `convsim fit: --data ${join(dir, name)}: CSV line ${line}: ${what}\n`;
  const cases = [
    [[...data('hex.csv', 'beta,rotation,v\n30,cw,0.1\n60,cw,0x10\n'), '--free', 'e'],
      csv('hex.csv', 3, "v must be a number, got '0x10'")],
    [[...data('hexfloat.csv', 'beta,rotation,v\n0x1p4,cw,0.1\n60,cw,0.05\n'), '--free', 'e'],
      csv('hexfloat.csv', 2, "beta must be a number, got '0x1p4'")],
    [[...data('inf.csv', 'beta,rotation,v,sigma\n30,cw,0.1,0.01\n60,cw,0.05,inf\n'), '--free', 'e'],
      csv('inf.csv', 3, "sigma must be a number, got 'inf'")],
    [['--data', good, '--free', 'e:0x0:0.5'], "convsim fit: --free takes NAME or NAME:MIN:MAX, got 'e:0x0:0.5'\n"],
    [['--data', good, '--free', 'e', '--prior', 'e:0x1:0.1'], prior('e:0x1:0.1')],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02:x0x3'], prior('e:0.02:x0x3')],
    [['--data', good, '--free', 'e', '--prior', 'e:0.02: 0.1'], prior('e:0.02: 0.1')],
    [['--peaks', 'cw:0x26', '--free', 'e'],
      "convsim fit: --peaks takes up to 8 of ROT:DEG[:SIGMA] (cw or ccw, deg, deg), e.g. cw:38,cw:128; got 'cw:0x26'\n"],
  ];
  for (const [args, message] of cases) {
    const r = run('fit', ...args, '-q');
    assert.equal(r.code, 2, `${args.join(' ')}: ${r.err}`);
    assert.equal(r.out, '', args.join(' '));
    assert.equal(r.err, message, args.join(' '));
  }
});

test('a leading + and, in a CSV cell, spaces around the number are fine', () => {
  const r = run('run', '--duration', '+0.1', '--set', 'beta=+30', '-q', ...CHEAP);
  assert.equal(r.code, 0, r.err);
  assert.equal(JSON.parse(r.out).duration, 0.1);
  const spaced = file('spaced.csv', 'beta, rotation, v\r\n 30 , cw , 0.1 \r\n60, cw, +0.05\r\n');
  const f = run('fit', '--data', spaced, '--free', 'e', '-q', '--duration', '0.5', ...CHEAP);
  assert.equal(f.code, 0, f.err);
  assert.deepEqual(JSON.parse(f.out).points.map((p) => [p.beta, p.v]), [[30, 0.1], [60, 0.05]]);
});
