// SPDX-License-Identifier: GPL-3.0-or-later
// Nothing a test starts outlives it (tests/tether.mjs, core/tether.c): a
// node process that started a daemon is killed with SIGKILL, and the
// daemon must be gone within a second, whether node started it directly,
// through a shell, or node is the runner of a test file that started it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync, existsSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { BIN, SLOW, sleep } from './lib.mjs';

const LIB = new URL('./lib.mjs', import.meta.url).href;

// Is pid gone (or a zombie left for its new parent to reap)?
function gone(pid) {
  try {
    const stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
    return stat.slice(stat.lastIndexOf(')') + 2, stat.lastIndexOf(')') + 3) === 'Z';
  } catch {
    return true;
  }
}

// The daemon's pid, once the node process under test wrote it to file.
async function pidFrom(file, child, log) {
  const end = Date.now() + 20000 * SLOW;
  while (!existsSync(file) || !readFileSync(file, 'utf8').endsWith('\n')) {
    if (child.exitCode !== null) throw new Error(`the node process ended: ${log()}`);
    if (Date.now() > end) throw new Error(`no daemon pid: ${log()}`);
    await sleep(20);
  }
  return Number(readFileSync(file, 'utf8'));
}

// What the node process runs: start a daemon (through `wrap`), write its
// pid, wait for ever.
const script = (pidFile, wrap) => `
import { startDaemon } from ${JSON.stringify(LIB)};
import { readFileSync, writeFileSync } from 'node:fs';
const d = await startDaemon([], ${wrap ? `{ wrap: ['sh', '-c', '"$@"; exit $?', 'sh', ${JSON.stringify(BIN)}] }` : '{}'});
const pid = ${wrap ? "Number(readFileSync(`/proc/${d.proc.pid}/task/${d.proc.pid}/children`, 'utf8').trim())" : 'd.proc.pid'};
writeFileSync(${JSON.stringify(pidFile)}, pid + '\\n');
setInterval(() => {}, 1000);
`;

const CASES = [
  ['node started the daemon', (dir) => ['node', ['--input-type=module', '-e', script(join(dir, 'pid'), false)]]],
  ['node started it through a shell', (dir) => ['node', ['--input-type=module', '-e', script(join(dir, 'pid'), true)]]],
  ['node --test runs a file that started it', (dir) => {
    const file = join(dir, 'holder.test.mjs');
    writeFileSync(file, `import { test } from 'node:test';\n${script(join(dir, 'pid'), false).replace('setInterval(() => {}, 1000);',
      "test('holds', { timeout: 600000 }, () => new Promise(() => {}));")}`);
    return ['node', ['--test', file]];
  }],
];

for (const [what, command] of CASES) {
  test(`SIGKILL of node ends the daemon within a second: ${what}`, { timeout: 60000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsim-tether-'));
    const [cmd, args] = command(dir);
    // a fresh tether for the node under test: it sets its own
    const env = { ...process.env };
    delete env.CONVSIM_TETHER;
    delete env.NODE_TEST_CONTEXT; // a runner of its own, not a sub-run of this one
    const child = spawn(cmd, args, { env, stdio: ['ignore', 'pipe', 'pipe'] });
    let out = '';
    child.stdout.on('data', (b) => { out += b; });
    child.stderr.on('data', (b) => { out += b; });
    const exited = new Promise((r) => child.on('exit', r));
    let pid = 0;
    try {
      pid = await pidFrom(join(dir, 'pid'), child, () => out);
      assert.ok(!gone(pid), 'the daemon runs');
      if (what.includes('shell')) {
        const ppid = Number(readFileSync(`/proc/${pid}/stat`, 'utf8').split(') ')[1].split(' ')[1]);
        assert.notEqual(ppid, child.pid, 'the shell is between node and the daemon');
      }
      child.kill('SIGKILL');
      await exited;
      const t0 = Date.now();
      while (!gone(pid) && Date.now() - t0 < 1000) await sleep(10);
      assert.ok(gone(pid), `the daemon ${pid} still runs 1 s after node was killed`);
    } finally {
      if (pid && !gone(pid)) process.kill(pid, 'SIGKILL');
      if (child.exitCode === null && child.signalCode === null) child.kill('SIGKILL');
      rmSync(dir, { recursive: true, force: true });
    }
  });
}

test('CONVSIM_TETHER naming a process that has ended: the program ends at once', { timeout: 30000 * SLOW }, async () => {
  // a process id that is surely free: one that just ended and was reaped
  const done = spawn('true');
  await new Promise((r) => done.on('exit', r));
  const d = spawn(BIN, ['--port', '0'], { env: { ...process.env, CONVSIM_TETHER: String(done.pid) }, stdio: 'ignore' });
  const [code, sig] = await new Promise((r) => d.on('exit', (c, s) => r([c, s])));
  assert.deepEqual([code, sig], [null, 'SIGKILL']);
});
