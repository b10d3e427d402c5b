// SPDX-License-Identifier: GPL-3.0-or-later
// `make run` always runs the daemon with a token: it makes TOKEN once (mode
// 0600, 64 hex digits), keeps it across runs, and prints the dashboard's
// address with the token in the fragment; the API refuses requests without
// it. The make and its daemon run in their own process group, stopped with
// SIGINT as a user's Ctrl-C would.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, statSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // nothing started here outlives the test

const ROOT = new URL('../..', import.meta.url).pathname;

// make run into dir; resolves {url, dashboard, stop()} once it printed the address.
function makeRun(dir) {
  const p = spawn('make', ['-s', '--no-print-directory', 'run', 'PORT=0', `TOKEN=${dir}/token`,
    `DATA=${dir}/data`, `BUILD=${process.env.BUILD || 'build'}`, 'DAEMON_FLAGS=--log-level warn'],
  { cwd: ROOT, detached: true, stdio: ['ignore', 'pipe', 'pipe'] });
  const exited = new Promise((r) => p.on('exit', (code, sig) => r({ code, sig })));
  let out = '';
  return new Promise((resolve, reject) => {
    const timer = setTimeout(() => { process.kill(-p.pid, 'SIGKILL'); reject(new Error(`no dashboard line:\n${out}`)); }, 120000);
    const scan = (d) => {
      out += d;
      const m = /^listening on (\S+)\ndashboard: (\S+)$/m.exec(out);
      if (m) {
        clearTimeout(timer);
        resolve({ url: m[1], dashboard: m[2], out: () => out,
          stop: async () => { process.kill(-p.pid, 'SIGINT'); return exited; } });
      }
    };
    p.stdout.on('data', scan);
    p.stderr.on('data', scan);
    exited.then(({ code }) => { clearTimeout(timer); reject(new Error(`make run exited ${code}:\n${out}`)); });
  });
}

test('make run makes a token, prints the dashboard URL carrying it, and the daemon asks for it', { timeout: 300000 }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-run-'));
  let r = await makeRun(dir);
  let token;
  try {
    token = readFileSync(join(dir, 'token'), 'utf8');
    assert.match(token, /^[0-9a-f]{64}$/);
    assert.equal(statSync(join(dir, 'token')).mode & 0o777, 0o600);
    assert.equal(r.dashboard, `${r.url}/#token=${token}`);
    assert.match(r.out(), /made a token in \S+token \(mode 0600\)/);
    assert.equal((await fetch(`${r.url}/api/v1/sessions`)).status, 401);
    const ok = await fetch(`${r.url}/api/v1/sessions`, { headers: { Authorization: `Bearer ${token}` } });
    assert.equal(ok.status, 200);
    assert.equal((await fetch(`${r.url}/`)).status, 200, 'the dashboard page itself is open');
  } finally {
    await r.stop();
  }
  // a second run keeps the token
  r = await makeRun(dir);
  try {
    assert.equal(readFileSync(join(dir, 'token'), 'utf8'), token);
    assert.equal(r.dashboard, `${r.url}/#token=${token}`);
    assert.doesNotMatch(r.out(), /made a token/);
  } finally {
    await r.stop();
  }
});
