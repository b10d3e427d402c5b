// README's Python example, taken from README.md itself (the block after
// <!-- test:python-example -->, so the two cannot drift), run with the
// system python3 (standard library only) against the real daemon, which
// runs with a token as `make run` starts it.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFile } from 'node:child_process';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { promisify } from 'node:util';
import { startDaemon, tokenFile, SLOW } from './lib.mjs';

const README = new URL('../../docs/api.md', import.meta.url);
const TOKEN = 'readme-example-token-0123456789';
let d;
before(async () => { d = await startDaemon(['--token-file', tokenFile(TOKEN)]); });
after(async () => { await d?.stop(); });

export function pythonExample(text) {
  const m = text.match(/## From Python[\s\S]*?```python\n([\s\S]*?)\n```/);
  assert.ok(m, 'README has a python block after <!-- test:python-example -->');
  return m[1];
}

test('README\'s Python example runs against the daemon and prints v and the sweep', { timeout: 120000 * SLOW }, async () => {
  const code = pythonExample(readFileSync(README, 'utf8'));
  assert.doesNotMatch(code, /^\s*(import|from)\s+(requests|numpy|pandas)/m, 'standard library only');
  const file = join(mkdtempSync(join(tmpdir(), 'convsim-py-')), 'example.py');
  writeFileSync(file, code);
  const { stdout } = await promisify(execFile)('python3', [file], {
    env: { ...process.env, CONVSIM_URL: d.base, CONVSIM_TOKEN: TOKEN }, timeout: 110000 * SLOW });
  const lines = stdout.trim().split('\n');
  const m = lines[0].match(/^v = (\S+) \+- (\S+) m\/s, steady: (True|False)$/);
  assert.ok(m, lines[0]);
  assert.ok(Math.abs(Number(m[1]) - 0.1525) < 0.003, `v at 30 deg cw: ${m[1]}`);
  assert.equal(m[3], 'True');
  const rows = lines.slice(1);
  assert.equal(rows.length, 14);
  const peak = rows.find((l) => /^\s*cw\s+30 deg/.test(l));
  assert.ok(peak && /v = \+0\.15/.test(peak), peak);
});
