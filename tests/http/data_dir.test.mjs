// The data directory as an operator leaves it (docs/hardening.md): junk
// beside the stored records is ignored with one log line each and never
// listed; a read-only or full data directory is reported, never taken for
// success.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdirSync, mkdtempSync, rmSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, CHEAP, SLOW } from './lib.mjs';

test('junk in the data directory is ignored with one log line each, the real records restored', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-junk-'));
  const args = ['--data-dir', dir, '--log-level', 'warn'];
  let d = await startDaemon(args);
  let id;
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    id = s.body.id;
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  const junk = [
    ['sessions', 'garbagefile', () => writeFileSync(join(dir, 'sessions', 'garbagefile'), 'x')],
    ['sessions', 'zzzz-not-an-id', () => mkdirSync(join(dir, 'sessions', 'zzzz-not-an-id'))],
    ['sessions', '0123456789abcdeg', () => mkdirSync(join(dir, 'sessions', '0123456789abcdeg'))],
    ['sessions', 'fedcba9876543210', () => symlinkSync('/tmp', join(dir, 'sessions', 'fedcba9876543210'))],
    ['sweeps', 'notes.txt', () => writeFileSync(join(dir, 'sweeps', 'notes.txt'), 'x')],
    ['sweeps', '0123456789abcdef.bin', () => mkdirSync(join(dir, 'sweeps', '0123456789abcdef.bin'))],
    ['experiments', 'zzzz-not-an-id.bin', () => writeFileSync(join(dir, 'experiments', 'zzzz-not-an-id.bin'), 'x')],
  ];
  for (const [sub, , make] of junk) {
    mkdirSync(join(dir, sub), { recursive: true });
    make();
  }
  d = await startDaemon(args);
  try {
    const list = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
    assert.deepEqual(list.map((x) => x.id), [id], 'only the real session is listed');
    assert.equal(list[0].state, 'running');
    assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length, 0);
    assert.equal((await req(d.base, 'GET', '/api/v1/experiments')).body.experiments.length, 0);
    for (const [sub, name] of junk) {
      const lines = d.stderr().split('\n').filter((l) => l.includes(`ignored ${sub}/${name}:`));
      assert.equal(lines.length, 1, `one log line for ${sub}/${name}: ${d.stderr()}`);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
