// SPDX-License-Identifier: GPL-3.0-or-later
// `convsim sweep --vary NAME=V1,V2,...` with a value listed twice would run
// the same point twice: refused (exit 2) by the study's own rule
// (core/study.c sim_study_repeat), the one the API's 422 keeps.
// CONVSIM names the binary.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import '../tether.mjs'; // nothing started here outlives the test

const CLI = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;

test('a --vary list with a value twice is refused naming it', () => {
  const r = spawnSync(CLI, ['sweep', '--vary', 'mu=0.3,0.5,0.3', '--duration', '0.5'],
    { encoding: 'utf8', timeout: 60000 });
  assert.equal(r.status, 2, r.stderr);
  assert.equal(r.stdout, '');
  assert.match(r.stderr, /^convsim sweep: --vary mu=0\.3,0\.5,0\.3: mu: 0\.3 is listed twice: each point runs once; list each value once/);
});
