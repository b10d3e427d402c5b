// SPDX-License-Identifier: GPL-3.0-or-later
// Where convsim's output goes and what becomes of it when it cannot all
// get there: a stdout that cannot be written (a full disk behind `>`,
// a closed stdout) is exit 1 with the reason, never 0 over a table cut
// short. CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { closeSync, existsSync, openSync } from 'node:fs';
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
