// SPDX-License-Identifier: GPL-3.0-or-later
// Where convsim's output goes and what becomes of it when it cannot all
// get there: a stdout that cannot be written (a full disk behind `>`,
// a closed stdout) is exit 1 with the reason, never 0 over a table cut
// short; Ctrl-C (SIGINT) or SIGTERM during a sweep writes the points
// measured and marks the others cancelled, exit 128 + the signal.
// CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { closeSync, existsSync, mkdtempSync, openSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;

// args with stdout on fd (stderr read back)
const runTo = (fd, ...args) => {
  const r = spawnSync(CLI, args, { encoding: 'utf8', timeout: 120000, stdio: ['ignore', fd, 'pipe'] });
  return { code: r.status, signal: r.signal, err: r.stderr };
};

test('a stdout that cannot be written is exit 1 with the reason', { skip: !existsSync('/dev/full') }, () => {
  const full = openSync('/dev/full', 'w');
  try {
    const cases = [
      [['sweep', '--beta', '0:180:90', '--rotation', 'cw', '-d', '0.5', '-q'], 'convsim sweep'],
      [['run', '-d', '0.2', '-q'], 'convsim run'],
      [['list'], 'convsim list'],
      [['help', 'sweep'], 'convsim'],
    ];
    for (const [args, who] of cases) {
      const r = runTo(full, ...args);
      assert.equal(r.signal, null, args.join(' '));
      assert.equal(r.code, 1, args.join(' '));
      assert.match(r.err, new RegExp(`^${who}: writing to stdout failed: No space left on device\\n$`, 'm'),
        args.join(' '));
    }
  } finally {
    closeSync(full);
  }
});

// A sweep of 181 points on one thread (several seconds), sent signal once
// its first progress line is out: its exit code, signal and stderr.
function interrupt(signal, args) {
  return new Promise((resolve, reject) => {
    const p = spawn(CLI, ['sweep', '--beta', '0:180:1', '--rotation', 'cw', '-d', '20', '-j', '1', ...args],
      { stdio: ['ignore', 'pipe', 'pipe'] });
    let err = '', out = '', sent = false;
    const timer = setTimeout(() => { p.kill('SIGKILL'); reject(new Error('no progress in 60 s')); }, 60000);
    p.stdout.on('data', (d) => { out += d; });
    p.stderr.on('data', (d) => {
      err += d;
      if (!sent && /^sweep: \d+\/181 points/m.test(err)) {
        sent = true;
        p.kill(signal);
      }
    });
    p.on('close', (code, sig) => { clearTimeout(timer); resolve({ code, signal: sig, out, err }); });
  });
}

test('Ctrl-C during a sweep: the points measured are written, the others marked cancelled, exit 130', async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-int-'));
  const file = join(dir, 'v.csv');
  writeFileSync(file, 'an earlier table\n');
  const r = await interrupt('SIGINT', ['--out', file]);
  assert.equal(r.signal, null);
  assert.equal(r.code, 130);
  assert.match(r.err, /^convsim sweep: interrupted \(SIGINT, Ctrl-C\): the table has the points measured before it, the others with state cancelled$/m);
  assert.match(r.err, /^sweep: \d+\/181 points in [\d.]+ s; interrupted: \d+ points not measured, written as cancelled$/m);
  const lines = readFileSync(file, 'utf8').trim().split('\n');
  assert.equal(lines[0], 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
  assert.equal(lines.length, 1 + 181); // every point, in order
  const rows = lines.slice(1).map((l) => l.split(','));
  rows.forEach((c, k) => assert.equal(Number(c[0]), k));
  const done = rows.filter((c) => c[5] === 'done'), cancelled = rows.filter((c) => c[5] === 'cancelled');
  assert.ok(done.length >= 1 && cancelled.length >= 1, `${done.length} done, ${cancelled.length} cancelled`);
  assert.equal(done.length + cancelled.length, 181);
  for (const c of done) assert.ok(Number.isFinite(Number(c[2])) && c[2] !== '');
  for (const c of cancelled) assert.deepEqual([c[2], c[3], c[4]], ['', '', 'false']);
});

test('SIGTERM during a JSON sweep: a whole JSON table with cancelled points, exit 143', async () => {
  const r = await interrupt('SIGTERM', ['--format', 'json']);
  assert.equal(r.signal, null);
  assert.equal(r.code, 143);
  assert.match(r.err, /^convsim sweep: interrupted \(SIGTERM\)/m);
  const t = JSON.parse(r.out);
  assert.equal(t.points.length, 181);
  const cancelled = t.points.filter((p) => p.state === 'cancelled');
  assert.ok(cancelled.length >= 1);
  for (const p of cancelled) assert.deepEqual([p.velocity, p.uncertainty, p.steady], [null, null, false]);
  assert.ok(t.points.some((p) => p.state === 'done' && Number.isFinite(p.velocity)));
});

// --out is written whole or not at all: FILE.partial, renamed over FILE at
// the end; a command killed on its way (SIGKILL: nothing of it runs again)
// leaves an earlier FILE as it was. spawn args, kill once FILE.partial
// exists and stderr matches ready: the exit.
function killWhile(args, partial, ready) {
  return new Promise((resolve, reject) => {
    const p = spawn(CLI, args, { stdio: ['ignore', 'ignore', 'pipe'] });
    let err = '', sent = false;
    const timer = setTimeout(() => { p.kill('SIGKILL'); reject(new Error(`not ready in 60 s: ${err}`)); }, 60000);
    p.stderr.on('data', (d) => {
      err += d;
      if (!sent && ready.test(err) && existsSync(partial)) {
        sent = true;
        p.kill('SIGKILL');
      }
    });
    p.on('close', (code, sig) => { clearTimeout(timer); resolve({ code, signal: sig, err }); });
  });
}

test('a command killed on its way leaves an earlier --out file as it was', async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-out-'));
  const cases = [
    ['run.csv', ['run', '-d', '600', '--sample-rate', '100'], /^run: /m],
    ['sweep.csv', ['sweep', '--beta', '0:180:1', '--rotation', 'cw', '-d', '20', '-j', '1'], /^sweep: \d+\/181 points/m],
    ['fit.json', ['fit', '--data', 'FIT', '--free', 'e', '-j', '1'], /^fit: /m],
  ];
  const data = join(dir, 'points.csv');
  writeFileSync(data, 'beta,rotation,v\n30,cw,0.15\n60,cw,0.08\n120,cw,-0.09\n');
  for (const [name, args, ready] of cases) {
    const file = join(dir, name);
    writeFileSync(file, 'an earlier table\n');
    const r = await killWhile([...args.map((a) => (a === 'FIT' ? data : a)), '--out', file], `${file}.partial`, ready);
    assert.equal(r.signal, 'SIGKILL', `${name}: ${r.err}`);
    assert.equal(readFileSync(file, 'utf8'), 'an earlier table\n', name);
    assert.ok(existsSync(`${file}.partial`), `${name}: what it wrote is in ${name}.partial`);
  }
});

test('--out whole: a finished command replaces the file and leaves no .partial; a failed write keeps the old one', () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-out-'));
  const file = join(dir, 'traj.csv');
  writeFileSync(file, 'an earlier table\n');
  let r = spawnSync(CLI, ['run', '-d', '0.1', '--sample-rate', '100', '-q', '--out', file], { encoding: 'utf8' });
  assert.equal(r.status, 0, r.stderr);
  const lines = readFileSync(file, 'utf8').trim().split('\n');
  assert.equal(lines.length, 1 + 11); // header, t = 0 to 0.1 every 0.01
  assert.equal(existsSync(`${file}.partial`), false);
  // a device is written in place: /dev/full fails the write, exit 1
  if (existsSync('/dev/full')) {
    r = spawnSync(CLI, ['run', '-d', '0.1', '-q', '--out', '/dev/full'], { encoding: 'utf8' });
    assert.equal(r.status, 1);
    assert.match(r.stderr, /^convsim run: --out: writing '\/dev\/full' failed$/m);
  }
  // a directory that cannot be written: the reason names the file asked for
  r = spawnSync(CLI, ['run', '-d', '0.1', '-q', '--out', '/nonexistent/x.csv'], { encoding: 'utf8' });
  assert.equal(r.status, 1);
  assert.match(r.stderr, /^convsim run: --out: cannot write '\/nonexistent\/x.csv': No such file or directory$/m);
});
