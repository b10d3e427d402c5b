// SPDX-License-Identifier: GPL-3.0-or-later
// The PI loop closed from the user's own code (docs/examples/remote_pi.py,
// docs/control-remote.md "The loop closed from your own code") against the real
// daemon with a token: the branch it picks is the CLI's v(beta) curve between
// its peaks, every setpoint segment settles with a steady error within 2 %,
// the latency figures are positive, finite and ordered, the session is gone
// afterwards; a setpoint the branch cannot reach is refused before any
// session is made, naming the reachable range.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFile, execFileSync } from 'node:child_process';
import { fileURLToPath } from 'node:url';
import { promisify } from 'node:util';
import { startDaemon, tokenFile, req, SLOW, CLI } from './lib.mjs';

const SCRIPT = fileURLToPath(new URL('../../docs/examples/remote_pi.py', import.meta.url));
const TOKEN = 'remote-loop-token-0123456789abcdef';
const AUTH = { Authorization: `Bearer ${TOKEN}` };
const run = promisify(execFile);

let d;
before(async () => { d = await startDaemon(['--token-file', tokenFile(TOKEN)]); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const loop = (...args) => run('python3', [SCRIPT, ...args],
  { env: { ...process.env, CONVSIM_URL: d.base, CONVSIM_TOKEN: TOKEN }, timeout: 120000 * SLOW });

// The clockwise v(beta) of the CLI on the script's grid, between its peaks
function cliBranch() {
  const csv = execFileSync(CLI, ['sweep', '--beta', '10:170:5', '--rotation', 'cw', '-q'], { encoding: 'utf8' });
  const pts = csv.trim().split('\n').slice(1).map((l) => l.split(',')).map(([b, , v]) => [Number(b), Number(v)]);
  const vs = pts.map((p) => p[1]);
  return pts.slice(vs.indexOf(Math.max(...vs)), vs.indexOf(Math.min(...vs)) + 1);
}

const sign = (x) => (x >= 0 ? '+' : '') + x.toFixed(3);

test('the remote PI settles every segment, measures its latency and leaves no session', { timeout: 180000 * SLOW }, async () => {
  const { stdout } = await loop('--pace', '2', '--setpoints', '0.10:3,-0.08:3');
  const lines = stdout.trim().split('\n');
  const b = cliBranch();
  assert.equal(lines[0], `monotonic branch of v(beta): beta ${b[0][0]}..${b[b.length - 1][0]} deg, `
    + `v ${sign(b[0][1])}..${sign(b[b.length - 1][1])} m/s`);
  assert.match(lines[1], /^session \S+: pace 2, [1-9]\d* commands, 0 ms added before each$/);
  assert.equal(lines[2], 'segment  setpoint  settling  overshoot     IAE    steady error');
  const rows = lines.slice(3, 5).map((l) => l.match(/^ +(\d) +([+-]\d\.\d{3}) +(\S+) s +(\S+) % +(\S+) m +(\S+) %$/));
  assert.ok(rows.every(Boolean), stdout);
  assert.deepEqual(rows.map((m) => [Number(m[1]), Number(m[2])]), [[1, 0.1], [2, -0.08]]);
  for (const [, , , settle, over, iae, steady] of rows) {
    assert.ok(Number(settle) > 0 && Number(settle) < 3, `settles within its segment: ${stdout}`);
    assert.ok(Number(over) >= 0 && Number(over) < 50, stdout);
    assert.ok(Number(iae) > 0, stdout);
    assert.ok(Math.abs(Number(steady)) <= 2, `steady error within 2 % of the setpoint: ${stdout}`);
  }
  const wall = lines[5].match(/^latency, sample received -> PATCH acknowledged: p50 (\S+) ms, p90 (\S+) ms, p99 (\S+) ms, max (\S+) ms$/);
  assert.ok(wall, stdout);
  const w = wall.slice(1).map(Number);
  assert.ok(w.every((x) => Number.isFinite(x) && x > 0), stdout);
  assert.deepEqual([...w].sort((x, y) => x - y), w, 'p50 <= p90 <= p99 <= max');
  const sim = lines[6].match(/^the same in simulated time \(sample t -> t_effective\): p50 (\S+) ms, max (\S+) ms$/);
  assert.ok(sim && Number(sim[1]) >= 0 && Number(sim[2]) >= Number(sim[1]) && Number.isFinite(Number(sim[2])), stdout);
  assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions', undefined, AUTH)).body.sessions ?? [], []);
});

test('a setpoint beyond the branch is refused, naming the range, before any session', { timeout: 60000 * SLOW }, async () => {
  const e = await loop('--setpoints', '0.10:1,0.2:1').then(() => null, (x) => x);
  assert.ok(e, 'exits non-zero');
  assert.equal(e.code, 1);
  const b = cliBranch();
  assert.equal(e.stderr.trim(), `setpoint +0.2 m/s: the branch reaches ${sign(b[b.length - 1][1])}..${sign(b[0][1])} m/s`);
  assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions', undefined, AUTH)).body.sessions ?? [], []);
});
