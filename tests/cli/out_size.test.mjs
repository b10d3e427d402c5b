// SPDX-License-Identifier: GPL-3.0-or-later
// `convsim run --out` states what it would write before it starts: rows
// (duration x sample rate, and the row at t = 0) of the trajectory's
// columns, each value at most 24 bytes and a separator, 3 bytes more a
// row and 4096 for the header and the end (docs/cli.md "The trajectory
// file"). Above --max-output (default 1e9 bytes) it starts nothing: exit
// 2, the estimate, the limit and the --max-output that allows it, no file
// written. At the limit it runs, and what it writes is within the
// estimate. CONVSIM names the binary.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
// (a run that is not refused is ended after `ms`: a huge one would fill the disk)
const runFor = (ms, ...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: ms });
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const run = (...args) => runFor(120000, ...args);
const dir = mkdtempSync(join(tmpdir(), 'convsim-out-size-'));
after(() => rmSync(dir, { recursive: true, force: true }));
const CHEAP = ['--set', 'drive=ideal', '--set', 'columns=3', '--set', 'layers=2', '-q'];
const NAMED = 20; // t ... e_residual (core/table.h), before column_1 ... column_K
const bound = (rows, width) => rows * (width * 25 + 3) + 4096;
const human = (b) => {
  for (const [unit, size] of [['TB', 1e12], ['GB', 1e9], ['MB', 1e6], ['kB', 1e3]]) {
    if (b >= size) return `${Number((b / size).toPrecision(3))} ${unit}`;
  }
  return `${b} bytes`;
};
const refusal = (rows, width, bytes, limit) =>
  `convsim run: --out would write ${rows} rows of ${width} values, up to ${bytes} bytes (${human(bytes)}), ` +
  `more than --max-output ${limit} bytes (${human(limit)}); give --max-output ${bytes} to write it, ` +
  'or a shorter --duration or a lower --sample-rate\n';

test('a run whose trajectory could pass --max-output starts nothing: exit 2, the estimate and the way to allow it', () => {
  // the preset (czubak2016: 5 columns) at 1 MHz for 100 s: 1e8 rows, some 44 GB written before
  const out = join(dir, 'huge.csv');
  const rows = 100e6 + 1, bytes = bound(rows, NAMED + 5);
  const r = runFor(10000, 'run', '--sample-rate', '1e6', '-d', '100', '--out', out);
  assert.equal(r.code, 2, r.err);
  assert.equal(r.out, '');
  assert.equal(r.err, refusal(rows, NAMED + 5, bytes, 1e9));
  assert.equal(bytes, 62800004724); // 100000001 rows of 628 bytes and 4096
  assert.ok(!existsSync(out) && !existsSync(`${out}.partial`), 'no file');
  // the same with --max-output below the default, and for JSON
  const r2 = run('run', '-d', '10', '--out', join(dir, 'j.json'), '--max-output', '1e6', ...CHEAP);
  assert.equal(r2.code, 2, r2.err);
  assert.equal(r2.err, refusal(10001, NAMED + 3, bound(10001, NAMED + 3), 1e6));
  // not a number of bytes: the usual message
  const r3 = run('run', '--out', join(dir, 'x.csv'), '--max-output', '0x10');
  assert.equal(r3.code, 2);
  assert.equal(r3.err, "convsim run: --max-output must be a number of bytes in (0, 1e+18], got '0x10'\n");
});

test('at the limit it runs, and writes no more than the estimate; one byte less is refused', () => {
  for (const name of ['at.csv', 'at.json']) {
    const out = join(dir, name);
    const rows = 2 * 500 + 1, width = NAMED + 3, bytes = bound(rows, width);
    const under = run('run', '-d', '2', '--sample-rate', '500', '--out', out, '--max-output', String(bytes - 1), ...CHEAP);
    assert.equal(under.code, 2, under.err);
    assert.equal(under.err, refusal(rows, width, bytes, bytes - 1));
    assert.ok(!existsSync(out), 'no file');
    const at = run('run', '-d', '2', '--sample-rate', '500', '--out', out, '--max-output', String(bytes), ...CHEAP);
    assert.equal(at.code, 0, at.err);
    assert.equal(JSON.parse(at.out).duration, 2);
    const text = readFileSync(out, 'utf8');
    const written = name.endsWith('.json') ? JSON.parse(text).rows.length : text.trim().split('\n').length - 1;
    assert.equal(written, rows, name);
    assert.ok(statSync(out).size <= bytes, `${name}: ${statSync(out).size} bytes written, estimate ${bytes}`);
  }
  // without --out nothing is written and nothing is refused
  assert.equal(run('run', '-d', '1', '--sample-rate', '1e6', '--max-output', '1', ...CHEAP).code, 0);
});
