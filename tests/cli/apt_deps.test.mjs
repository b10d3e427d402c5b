// SPDX-License-Identifier: GPL-3.0-or-later
// tests/apt-deps.sh, the Makefile's installer, run twice at once (as
// `make -j2 deps` does on a fresh machine): the two take turns (apt-get
// refuses to run beside another and the build stopped with "Could not get
// lock"), and the second installs only what the first did not. apt-get here
// is a stand-in on PATH that installs nothing but the files it is told to
// and records whether another was running.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs';

const ROOT = new URL('../..', import.meta.url).pathname;

function run(env) {
  return new Promise((resolve) => {
    const p = spawn('sh', [join(ROOT, 'tests/apt-deps.sh')], { env, stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    p.stdout.on('data', (x) => { out += x; });
    p.stderr.on('data', (x) => { out += x; });
    p.on('exit', (code) => resolve({ code, out }));
  });
}

test('two installers at once take turns, and the second installs only what is still missing', { timeout: 30000 }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-apt-'));
  const bin = join(dir, 'bin');
  const log = join(dir, 'log');
  mkdirSync(bin);
  // the stand-in: "install" makes the files of the packages it is given
  // (FILES_pkg), taking 0.4 s; a second one running meanwhile is an overlap
  writeFileSync(join(bin, 'apt-get'), `#!/bin/sh
case "$*" in *install*) ;; *) exit 0 ;; esac
if [ -e "${dir}/busy" ]; then echo overlap >> "${log}"; fi
touch "${dir}/busy"
for a in "$@"; do case "$a" in pkg-*) echo "install $a" >> "${log}"; touch "${dir}/$a";; esac; done
sleep 0.4
rm -f "${dir}/busy"
`, { mode: 0o755 });
  writeFileSync(join(bin, 'sudo'), '#!/bin/sh\nexec "$@"\n', { mode: 0o755 }); // where not root
  const env = { PATH: `${bin}:/usr/bin:/bin`, TMPDIR: dir };
  const [a, b] = await Promise.all([
    run({ ...env, NEEDS: `${dir}/pkg-a:pkg-a`, WHY: 'first' }),
    run({ ...env, NEEDS: `${dir}/pkg-a:pkg-a ${dir}/pkg-b:pkg-b`, WHY: 'second' }),
  ]);
  assert.equal(a.code, 0, a.out);
  assert.equal(b.code, 0, b.out);
  const lines = readFileSync(log, 'utf8').trim().split('\n');
  assert.ok(!lines.includes('overlap'), `two apt-get installs ran at once: ${lines.join(', ')}`);
  // pkg-a once (whichever ran first installed it), pkg-b once
  assert.equal(lines.filter((l) => l === 'install pkg-a').length, 1, lines.join(', '));
  assert.equal(lines.filter((l) => l === 'install pkg-b').length, 1, lines.join(', '));
  assert.ok(existsSync(join(dir, 'pkg-a')) && existsSync(join(dir, 'pkg-b')));
  // nothing missing: nothing run, nothing said
  const c = await run({ ...env, NEEDS: `${dir}/pkg-a:pkg-a`, WHY: 'third' });
  assert.equal(c.code, 0);
  assert.equal(c.out, '');
});
