// SPDX-License-Identifier: GPL-3.0-or-later
// `convsim sweep` under `mpirun -n N` (cli/spread.h): the ranks
// measure their share of the points, rank 0 gathers them into point order
// and writes the table, the very bytes one process writes (CSV and JSON,
// a study with the mirror reduction, a beta sweep, a Latin hypercube, an
// uneven split over 3 ranks, one thread or two per rank, bands from a
// fit). A usage error and an unwritable --out stop every rank with one
// message, no hang; so do ranks started with other options, and a rank
// that cannot read a file rank 0 reads (its own reason, marked with its
// rank). The plain convsim links neither MPI nor LIGGGHTS and hands a
// launched sweep to convsim-mpi beside it (cli/handover.h), which
// links MPI; without convsim-mpi it says so (exit 1). The build without
// MPI (`make NO_MPI=1`: CONVSIM_NOMPI, else made here) links no MPI and
// writes the same bytes. CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { copyFileSync, existsSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { dirname, join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const ROOT = new URL('../..', import.meta.url).pathname;
const BUILD = process.env.BUILD || 'build';
const CLI = process.env.CONVSIM || `${ROOT}${BUILD}/convsim`;
const NOMPI = process.env.CONVSIM_NOMPI || `${ROOT}${BUILD}/nompi/convsim`;
// (leak detection off under ASan: the MPI stack's own leaks at exit, as in tests/dem/)
const env = {
  ...process.env, ASAN_OPTIONS: [process.env.ASAN_OPTIONS, 'detect_leaks=0'].filter(Boolean).join(':'),
  OMPI_ALLOW_RUN_AS_ROOT: '1', OMPI_ALLOW_RUN_AS_ROOT_CONFIRM: '1',
};
const spawn = (cmd, args) => {
  const r = spawnSync('nice', ['-n', '10', cmd, ...args], { encoding: 'utf8', timeout: 300000, env });
  assert.notEqual(r.signal, 'SIGTERM', `${cmd} ${args.join(' ')}: timed out`);
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const mpirun = (n, args, bin = CLI) => spawn('mpirun', ['-n', String(n), '--oversubscribe', bin, ...args]);
const alone = (args, bin = CLI) => spawn(bin, args);

const STUDY = ['sweep', '--vary', 'mu=0.2:0.6:0.2', '--beta', '0:180:30', '--rotation', 'cw,ccw', '--duration', '0.6'];
const BETA = ['sweep', '--beta', '0:180:10', '--rotation', 'cw,ccw', '--set', 'h=0.02', '--duration', '0.6'];
const LHS = ['sweep', '--vary', 'mu=0.2:1.0:0.1', '--vary', 'beta=10:170:10', '--lhs', '9', '--seed', '7', '--duration', '0.6'];

test('the plain convsim links neither MPI nor LIGGGHTS, convsim-mpi beside it links MPI, the NO_MPI build none', () => {
  // built here (make: up to date, or made again) unless CONVSIM_NOMPI names one
  if (!process.env.CONVSIM_NOMPI || !existsSync(NOMPI)) {
    const b = spawnSync('make', ['-j2', 'NO_MPI=1', `BUILD=${BUILD}/nompi`, `${BUILD}/nompi/convsim`],
      { cwd: ROOT, encoding: 'utf8', timeout: 600000 });
    assert.equal(b.status, 0, b.stderr);
  }
  const ldd = (bin) => { const r = spawnSync('ldd', [bin], { encoding: 'utf8' }); assert.equal(r.status, 0, r.stderr); return r.stdout; };
  assert.match(ldd(CLI), /libc\.so/);
  assert.doesNotMatch(ldd(CLI), /libmpi|liggghts|libopen-|libpmix|libvtk/);
  assert.match(ldd(join(dirname(CLI), 'convsim-mpi')), /libmpi\.so/);
  assert.doesNotMatch(ldd(NOMPI), /libmpi/);
});

// `make run` builds convsim before `make test` installs MPI: the hand-over
// (cli/handover.o, -DCLI_MPI_BUILD) is compiled again once MPI is there
// (it was kept, and the plain convsim then ran every rank alone, each
// writing the whole table).
test('the hand-over is compiled again when MPI arrives after a build without it', () => {
  const b = mkdtempSync(join(tmpdir(), 'convsim-build-'));
  const make = (...args) => spawnSync('make', ['--no-print-directory', `BUILD=${b}`, ...args, `${b}/cli/handover.o`],
    { cwd: ROOT, encoding: 'utf8', timeout: 120000 });
  assert.equal(make('NO_MPI=1').status, 0);
  assert.equal(make('NO_MPI=1', '-q').status, 0, 'up to date without MPI');
  assert.equal(make('-q').status, 1, 'MPI installed since: handover.o is out of date');
  assert.equal(make().status, 0);
  assert.equal(make('-q').status, 0);
  assert.equal(readFileSync(join(b, 'cli/handover.mpi'), 'utf8').trim(), existsSync('/usr/include/liggghts/library.h') ? '3' : '1');
});

test('under mpirun a convsim without convsim-mpi beside it says what it needs and stops (exit 1), no table', () => {
  const lone = join(mkdtempSync(join(tmpdir(), 'convsim-lone-')), 'convsim');
  copyFileSync(CLI, lone);
  const r = mpirun(1, [...BETA, '-q'], lone);
  assert.equal(r.code, 1, r.err);
  assert.match(r.err, /convsim sweep: a sweep started by an MPI launcher needs convsim-mpi .*cannot run '.*convsim-lone-.*\/convsim-mpi': No such file or directory/);
  assert.equal(r.out, '');
  // alone it needs nothing
  const one = alone([...BETA, '-q'], lone);
  assert.equal(one.code, 0, one.err);
});

test('a study (mu x beta, both senses, mirror reduction): mpirun -n 2 writes the one-process CSV and JSON bit for bit', () => {
  for (const fmt of ['csv', 'json']) {
    const one = alone([...STUDY, '-f', fmt, '-q']);
    assert.equal(one.code, 0, one.err);
    const two = mpirun(2, [...STUDY, '-f', fmt, '-q']);
    assert.equal(two.code, 0, two.err);
    assert.equal(two.out, one.out, fmt);
  }
  const s = JSON.parse(alone([...STUDY, '-f', 'json', '-q']).out);
  assert.deepEqual(s.reductions, ['mirror']);
  assert.equal(s.points.length, 42);
  assert.equal(s.points.filter((p) => p.mirrored).length, 21);
  assert.equal(new Set(s.points.map((p) => p.velocity)).size > 30, true, 'the points differ');
});

test('a beta sweep, a Latin hypercube, 3 ranks and one or two threads per rank: the same bytes', () => {
  for (const args of [BETA, LHS]) {
    const one = alone([...args, '-q', '-j', '2']);
    assert.equal(one.code, 0, one.err);
    assert.ok(one.out.split('\n').length > 10);
    for (const [n, j] of [[2, '1'], [3, '2'], [1, '1']]) {
      const r = mpirun(n, [...args, '-q', '-j', j]);
      assert.equal(r.code, 0, r.err);
      assert.equal(r.out, one.out, `${args[1]}: ${n} ranks, ${j} threads`);
    }
  }
});

test('a study with bands from a fit (--band-from): the same bytes over 2 ranks', () => {
  const fit = join(mkdtempSync(join(tmpdir(), 'convsim-mpi-')), 'fit.json');
  writeFileSync(fit, JSON.stringify({
    status: 'converged', dof: 6, standard_errors_from: 'sigma',
    parameters: [{ name: 'e', value: 0.0215, standard_error: 0.0004, min: 0.005, max: 0.04 },
      { name: 'mu', value: 0.41, standard_error: 0.03, min: 0.1, max: 1.5 }],
    correlation: [[1, -0.6], [-0.6, 1]],
  }));
  const args = [...STUDY, '--band-from', fit, '-q', '-f', 'json'];
  const one = alone(args);
  assert.equal(one.code, 0, one.err);
  assert.deepEqual(JSON.parse(one.out).band.varied, ['mu']);
  const two = mpirun(2, args);
  assert.equal(two.code, 0, two.err);
  assert.equal(two.out, one.out);
});

test('the progress comes from rank 0 alone: its share while it runs, then the whole', () => {
  const r = mpirun(2, STUDY);
  assert.equal(r.code, 0, r.err);
  assert.match(r.err, /points of rank 0's share/);
  assert.match(r.err, /sweep: 21\/21 points in [0-9.]+ s on 2 ranks \(11 on rank 0\); 21 more as their mirror images/);
  assert.equal(r.err.match(/on 2 ranks/g).length, 1, 'one closing line');
});

test('errors end every rank with one message: a usage error (exit 2), an unwritable --out (exit 1)', () => {
  const bad = mpirun(2, ['sweep', '--vary', 'nosuch=1:2:1', '-q']);
  assert.equal(bad.code, 2, bad.err);
  assert.equal(bad.err.match(/--vary nosuch=1:2:1: unknown setting 'nosuch'/g).length, 1, bad.err);
  assert.equal(bad.out, '');
  const out = mpirun(2, [...STUDY, '-q', '--out', '/nonexistent/dir/study.csv']);
  assert.equal(out.code, 1, out.err);
  assert.match(out.err, /\/nonexistent\/dir\/study\.csv/);
  assert.equal(out.out, '');
});

test('ranks that differ: other options, or a file only rank 0 can read, stop every rank with the reason (exit 2)', () => {
  const other = spawn('mpirun', ['--oversubscribe', '-n', '1', CLI, ...STUDY, '-q', ':', '-n', '1', CLI, ...BETA, '-q']);
  assert.equal(other.code, 2, other.err);
  assert.match(other.err, /convsim sweep: the 2 ranks were started with different options; every rank must have the same command line/);
  assert.equal(other.out, '');
  // the same command line, run in two directories: fit.json is in rank 0's only
  const [a, b] = [0, 1].map(() => mkdtempSync(join(tmpdir(), 'convsim-mpi-wdir-')));
  writeFileSync(join(a, 'fit.json'), JSON.stringify({
    status: 'converged', dof: 6, standard_errors_from: 'sigma',
    parameters: [{ name: 'e', value: 0.0215, standard_error: 0.0004, min: 0.005, max: 0.04 }], correlation: [[1]],
  }));
  const args = [...BETA, '-q', '--band-from', 'fit.json'];
  const r = spawn('mpirun', ['--oversubscribe', '-n', '1', '-wdir', a, CLI, ...args, ':', '-n', '1', '-wdir', b, CLI, ...args]);
  assert.equal(r.code, 2, r.err);
  assert.match(r.err, /\(rank 1\) convsim sweep: --band-from: cannot read 'fit\.json'/);
  assert.match(r.err, /convsim sweep: another rank could not start the study/);
  assert.equal(r.out, '');
});

test('the build without MPI runs the same study and the same beta sweep, the same bytes', () => {
  for (const args of [STUDY, BETA]) {
    const one = alone([...args, '-q']);
    const plain = alone([...args, '-q'], NOMPI);
    assert.equal(plain.code, 0, plain.err);
    assert.equal(plain.out, one.out);
  }
});
