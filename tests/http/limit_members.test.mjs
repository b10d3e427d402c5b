// SPDX-License-Identifier: GPL-3.0-or-later
// A 429 limit-reached names the limit it met, byte for byte, as every
// budget's refusal does (docs/api-errors.md): `budget` the thing counted
// ("sessions", "streams", "experiments", "sweeps", "fits") and `limit`
// its flag's value, no `field` (no member of the request is at fault),
// Retry-After: 1. Kept jobs meet their limit only when none of them has
// finished (a finished one would be evicted to make room). Nothing is
// created by a refusal.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, CHEAP, NO_FEED, SLOW } from './lib.mjs';

let d;
before(async () => {
  d = await startDaemon(['--max-sessions', '2', '--max-streams', '1', '--max-experiments', '1',
    '--max-sweeps', '1', '--max-fits', '1']);
});
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const limited = (instance, detail, budget, limit) => ({
  type: '/api/v1/problems/limit-reached', title: 'Limit reached', status: 429, detail, instance, budget, limit,
});
// the ids of everything kept (what runs changes its text meanwhile)
const listed = async () => Promise.all(['fits', 'sweeps', 'experiments', 'sessions']
  .map(async (k) => (await req(d.base, 'GET', `/api/v1/${k}`)).body[k].map((x) => x.id).sort()));

function refused(r, expected) {
  assert.equal(r.status, 429, r.text);
  assert.equal(r.headers.get('content-type'), 'application/problem+json', r.text);
  assert.equal(r.headers.get('retry-after'), '1', r.text);
  assert.deepEqual(r.body, expected, r.text);
}

test('--max-sessions and --max-streams: budget "sessions" and "streams" with their limits', { timeout: 30000 * SLOW }, async () => {
  const ids = [];
  for (let i = 0; i < 2; i++) {
    const r = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1, until: 600 });
    assert.equal(r.status, 201, r.text);
    ids.push(r.body.id);
  }
  const ac = new AbortController();
  try {
    const was = await listed();
    refused(await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED }), limited('/api/v1/sessions',
      '2 sessions exist, the limit (--max-sessions); delete one first', 'sessions', 2));
    assert.deepEqual(await listed(), was, 'nothing created');
    const path = `/api/v1/sessions/${ids[0]}/stream`;
    const open = await fetch(d.base + path, { signal: ac.signal });
    assert.equal(open.status, 200);
    refused(await req(d.base, 'GET', path), limited(path,
      '1 stream client is connected, the limit (--max-streams)', 'streams', 1));
  } finally {
    ac.abort();
    for (const id of ids) assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${id}`)).status, 204);
  }
});

// Each kind: a job that runs far longer than the test waits, then the
// refused one; then the first ends (a running experiment with its
// session's deletion, a sweep or a fit with its own).
const KEPT = [
  ['experiments', { session: { ...NO_FEED, pace: 1 }, schedule: [{ beta: 38, until: 600 }] },
    'experiment is running or held by a session; wait for one to end'],
  ['sweeps', { ...CHEAP, beta: [10, 30, 50, 70, 90, 110, 130, 150], rotations: ['cw'], t_end: 600 },
    'sweep is running or kept; delete one'],
  ['fits', { ...CHEAP, t_end: 600, free: ['e', 'mu'], curve_step: 45,
    points: [20, 40, 60, 80, 100, 120].map((beta) => ({ beta, rotation: 'cw', v: 0.05 })) },
  'fit is running or kept; delete one'],
];

for (const [kind, body, words] of KEPT) {
  test(`--max-${kind} with none finished: budget "${kind}" with its limit`, { timeout: 30000 * SLOW }, async () => {
    const first = await req(d.base, 'POST', `/api/v1/${kind}`, body);
    assert.ok(first.status === 201 || first.status === 202, first.text);
    try {
      const was = await listed();
      refused(await req(d.base, 'POST', `/api/v1/${kind}`, body),
        limited(`/api/v1/${kind}`, `1 ${words}`, kind, 1));
      assert.deepEqual(await listed(), was, 'nothing created');
    } finally {
      const end = kind === 'experiments' ? `/api/v1/sessions/${first.body.session}` : `/api/v1/${kind}/${first.body.id}`;
      assert.equal((await req(d.base, 'DELETE', end)).status, 204);
    }
  });
}
