// SPDX-License-Identifier: GPL-3.0-or-later
// convsim run's summary says when the column model lies outside the domain
// checked against LIGGGHTS beds (docs/dem.md, sim_feed_validated): the
// preset's 8 layers of soft contacts are outside, 2 layers inside.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import '../tether.mjs'; // nothing started here outlives the test

const CONVSIM = process.env.CONVSIM || new URL('../../build/convsim', import.meta.url).pathname;
const summary = (...set) => JSON.parse(execFileSync(CONVSIM, ['run', '-q', '-d', '0.2',
  ...set.flatMap((s) => ['--set', s])], { encoding: 'utf8' }));

test('feed_warning: outside at 8 layers of the preset, null at 2 layers and without feed', () => {
  const w = summary().feed_warning;
  assert.equal(typeof w, 'string');
  assert.match(w, /8 layers/);
  assert.match(w, /feed_model=liggghts/);
  assert.equal(summary('layers=2').feed_warning, null);
  assert.equal(summary('feed=false').feed_warning, null);
});
