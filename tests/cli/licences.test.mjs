// SPDX-License-Identifier: GPL-3.0-or-later
// Licences that cannot drift: docs/third-party.md's table of shared
// libraries names every Debian package `ldd` shows for each built program,
// with that program, and no package none of them loads; every file the
// project wrote says its licence in an SPDX line near its top.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync, readFileSync, realpathSync } from 'node:fs';
import { join } from 'node:path';

const ROOT = new URL('../..', import.meta.url).pathname;
const BUILD = join(ROOT, process.env.BUILD || 'build');
const PROGRAMS = ['convsim', 'convsim-mpi', 'convsimd', 'convsim-dem', 'convsim-bed'];

// The table between <!-- ldd: packages --> and <!-- /ldd -->: package ->
// the programs its row names.
function lddTable(md) {
  const from = md.indexOf('<!-- ldd: packages -->'), to = md.indexOf('<!-- /ldd -->');
  assert.ok(from >= 0 && to > from, 'docs/third-party.md has its ldd table');
  const rows = new Map();
  for (const line of md.slice(from, to).split('\n')) {
    const m = line.match(/^\| `([^`]+)` \|[^|]*\| ([^|]*) \|/);
    if (m) rows.set(m[1], new Set(m[2].split(',').map((s) => s.trim()).filter(Boolean)));
  }
  return rows;
}

// The shared libraries a program loads: each as ldd names it and as its
// real path (Debian may own either).
function librariesOf(bin) {
  const ldd = spawnSync('ldd', [bin], { encoding: 'utf8' });
  assert.equal(ldd.status, 0, ldd.stderr);
  return [...ldd.stdout.matchAll(/=> (\/\S+)/g)].map((m) => [m[1], realpathSync(m[1])]);
}

// The Debian package owning each of the files, in one dpkg -S for them all
// (one a library took 0.4 s each, 30 s for the five programs).
function owners(files) {
  const q = spawnSync('dpkg', ['-S', ...new Set(files)], { encoding: 'utf8', maxBuffer: 1 << 24 });
  const own = new Map();
  for (const line of q.stdout.split('\n')) {
    const at = line.lastIndexOf(': /'); // "pkg:arch[, pkg2:arch]: /path"
    if (at > 0) own.set(line.slice(at + 2), line.slice(0, at).split(',')[0].split(':')[0].trim());
  }
  return own;
}

// The Debian package of each shared library a program loads.
function packagesOf(bin, own) {
  const pkgs = new Set();
  for (const [path, real] of librariesOf(bin)) {
    const p = own.get(path) || own.get(real);
    assert.ok(p, `${bin}: no Debian package provides ${path}`);
    pkgs.add(p);
  }
  return pkgs;
}

const hasDpkg = spawnSync('sh', ['-c', 'command -v dpkg && command -v ldd']).status === 0;
// `make check`'s build loads the sanitizers' runtimes and what they need
// (libasan, libubsan, libgcc_s): not what is shipped, which `make test` checks
const sanitized = hasDpkg && /libasan|libubsan/.test(spawnSync('ldd', [join(BUILD, 'convsim')], { encoding: 'utf8' }).stdout || '');

test('docs/third-party.md lists every shared library of every built program', { skip: (!hasDpkg && 'no dpkg or ldd') || (sanitized && 'a sanitizer build') }, () => {
  const rows = lddTable(readFileSync(join(ROOT, 'docs/third-party.md'), 'utf8'));
  const seen = new Set();
  let built = 0;
  const bins = PROGRAMS.map((prog) => [prog, join(BUILD, prog)]).filter(([, bin]) => existsSync(bin));
  const own = owners(bins.flatMap(([, bin]) => librariesOf(bin).flat()));
  for (const [prog, bin] of bins) {
    built++;
    for (const p of packagesOf(bin, own)) {
      seen.add(p);
      assert.ok(rows.has(p), `docs/third-party.md: no row for \`${p}\` (ldd ${prog})`);
      assert.ok(rows.get(p).has(prog), `docs/third-party.md: \`${p}\`'s row does not name ${prog}`);
    }
  }
  assert.ok(built >= 2, 'convsim and convsimd are built');
  // with every program built, no row for a package none loads
  if (built === PROGRAMS.length)
    for (const p of rows.keys()) assert.ok(seen.has(p), `docs/third-party.md: \`${p}\` is loaded by no program`);
});

// Files that cannot carry a comment, or are not the project's text.
const NO_SPDX = [
  [/^LICENSE$/, 'the licence itself'],
  [/^web\/vendor\//, 'vendored: its own LICENSE beside it'],
  [/\.(json|png|bin|ndjson|csv)$/, 'JSON and data: no comment syntax'],
  [/^tests\/fuzz\/corpus\//, 'fuzz inputs: a comment would change them'],
  [/^tests\/fixtures\//, 'data directories written by older builds, as they wrote them'],
  [/^tests\/bench\/results\//, 'benchmark output, as the benchmarks wrote it'],
  [/^tests\/bench\/zoo\/ref\.tsv$/, 'a reference table its readers parse whole'],
  [/^tests\/bench\/zoo\/chaos_ref\.tsv$/, 'the chaotic feed\'s reference table (tests/bench/chaos.sh), parsed whole like ref.tsv'],
];

test('every file the project wrote carries an SPDX line near its top', () => {
  const ls = spawnSync('git', ['ls-files'], { cwd: ROOT, encoding: 'utf8' });
  if (ls.status !== 0) return; // not a git checkout (a release tarball)
  const missing = [];
  let checked = 0;
  for (const f of ls.stdout.split('\n').filter(Boolean)) {
    if (NO_SPDX.some(([re]) => re.test(f)) || !existsSync(join(ROOT, f))) continue;
    checked++;
    const head = readFileSync(join(ROOT, f), 'utf8').split('\n').slice(0, 5).join('\n');
    if (!/SPDX-License-Identifier: GPL-3\.0-or-later/.test(head)) missing.push(f);
  }
  assert.deepEqual(missing, []);
  assert.ok(checked > 100, `${checked} files checked`);
});
