// SPDX-License-Identifier: GPL-3.0-or-later
// `make install PREFIX=...` into a temporary prefix: the binaries, the
// dashboard, the docs and the systemd unit land where docs/operations.md says; the
// unit passes `systemd-analyze verify` (which the install rule runs when it
// exists); the installed daemon finds its dashboard by itself.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn, spawnSync } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const ROOT = new URL('../..', import.meta.url).pathname;

test('make install PREFIX=... installs a working daemon and a verified, hardened unit', { timeout: 300000 }, async () => {
  const prefix = mkdtempSync(join(tmpdir(), 'convsim-prefix-'));
  const r = spawnSync('make', ['--no-print-directory', 'install', `PREFIX=${prefix}`, `BUILD=${process.env.BUILD || 'build'}`],
    { cwd: ROOT, encoding: 'utf8', timeout: 280000 });
  assert.equal(r.status, 0, r.stdout + r.stderr);
  for (const f of ['bin/convsim', 'bin/convsimd', 'share/convsim/web/index.html', 'share/doc/convsim/README.md',
    'share/doc/convsim/docs/MODEL.md', 'share/doc/convsim/docs/api.md', 'share/doc/convsim/docs/examples/remote_pi.py', 'share/doc/convsim/LICENSE', 'lib/systemd/system/convsimd.service']) assert.ok(existsSync(join(prefix, f)), f);
  const unit = readFileSync(join(prefix, 'lib/systemd/system/convsimd.service'), 'utf8');
  assert.ok(unit.includes(`ExecStart=${prefix}/bin/convsimd `), 'the unit names the installed binary');
  assert.ok(unit.includes(`--web-root ${prefix}/share/convsim/web`));
  for (const k of ['DynamicUser=yes', 'NoNewPrivileges=yes', 'ProtectSystem=strict', 'CapabilityBoundingSet=',
    'SystemCallFilter=@system-service', 'StateDirectory=convsim']) assert.ok(unit.includes(k), k);
  if (spawnSync('sh', ['-c', 'command -v systemd-analyze']).status === 0) {
    assert.match(r.stdout, /systemd-analyze verify /);
    const v = spawnSync('systemd-analyze', ['verify', join(prefix, 'lib/systemd/system/convsimd.service')], { encoding: 'utf8' });
    assert.equal(v.status, 0, v.stderr);
  }
  // the installed daemon, started from elsewhere, serves the dashboard
  const d = spawn(join(prefix, 'bin/convsimd'), ['--port', '0'], { cwd: '/', stdio: ['ignore', 'pipe', 'pipe'] });
  try {
    const port = await new Promise((resolve, reject) => {
      let out = '';
      d.stdout.on('data', (x) => { out += x; const m = out.match(/listening on http:\/\/127\.0\.0\.1:(\d+)/); if (m) resolve(m[1]); });
      d.on('exit', (c) => reject(new Error(`exited ${c}`)));
    });
    const page = await fetch(`http://127.0.0.1:${port}/`);
    assert.equal(page.status, 200);
    assert.match(await page.text(), /<script type="module"/);
  } finally { d.kill('SIGTERM'); }
  assert.match(spawnSync(join(prefix, 'bin/convsim'), ['--version'], { encoding: 'utf8' }).stdout, /^convsim /);
  // convsim-mpi beside it where it was built (Open MPI installed): the hand-over finds it
  if (existsSync(join(ROOT, process.env.BUILD || 'build', 'convsim-mpi'))) {
    assert.ok(existsSync(join(prefix, 'bin/convsim-mpi')), 'bin/convsim-mpi');
    assert.match(spawnSync(join(prefix, 'bin/convsim-mpi'), ['--version'], { encoding: 'utf8' }).stdout, /^convsim /);
  }
});
