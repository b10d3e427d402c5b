// SPDX-License-Identifier: GPL-3.0-or-later
// DELETE of a job with ?only=running (docs/api-jobs.md "Stopping a job"):
// a sweep, a fit or an experiment that still runs is stopped and
// forgotten (204), as a plain DELETE does; one that has ended is kept
// whole and said (409 conflict naming `only`), so that a client's Stop
// that comes just after the end cannot forget the result it did not
// see; another value of `only` is 400 naming it. The look and the stop
// are one step in the daemon, under the job's lock.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, CHEAP, NO_FEED, SLOW } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(['--pool-threads', '1']); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const POINTS = [
  { beta: 20, rotation: 'cw', v: 0.07 },
  { beta: 60, rotation: 'cw', v: 0.06 },
  { beta: 100, rotation: 'cw', v: -0.03 },
];
// each kind: a job that ends within a second or two, and one that runs
// far longer than the test (its first answer already says it runs)
const KINDS = {
  sweeps: {
    short: { ...NO_FEED, beta: [30], rotations: ['cw'], t_end: 0.5 },
    // 8 points of 600 s with the feed: several CPU seconds on one pool thread
    long: { ...CHEAP, beta: [10, 20, 30, 40, 50, 60, 70, 80], rotations: ['cw'], t_end: 600 },
    ended: (b) => b.state === 'done',
  },
  fits: {
    short: { ...CHEAP, t_end: 0.5, free: ['e'], points: POINTS, curve_step: 90 },
    long: { free: ['e', 'mu'], points: Array.from({ length: 17 }, (_, i) => ({ beta: 5 + 10 * i, rotation: 'cw', v: 0.05 })) },
    ended: (b) => b.state === 'done',
  },
  experiments: {
    short: { session: { ...CHEAP, pace: 'max' }, schedule: [{ beta: 40, until: 0.2 }] },
    long: { session: { ...CHEAP, pace: 1 }, schedule: [{ beta: 40, until: 600 }] },
    ended: (b) => b.state === 'done',
  },
};

for (const [plural, k] of Object.entries(KINDS)) {
  test(`${plural}: DELETE ?only=running stops a running one (204) and keeps an ended one (409 naming only)`, { timeout: 120000 * SLOW }, async () => {
    const short = await req(d.base, 'POST', `/api/v1/${plural}`, k.short);
    assert.ok([201, 202].includes(short.status), short.text);
    const spath = `/api/v1/${plural}/${short.body.id}`;
    const done = await until(async () => {
      const g = (await req(d.base, 'GET', spath)).body;
      return k.ended(g) && g;
    }, 60000 * SLOW, `the short ${plural} to end`);
    const r = await req(d.base, 'DELETE', `${spath}?only=running`);
    assert.equal(r.status, 409, r.text);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.body.type, '/api/v1/problems/conflict');
    assert.equal(r.body.field, 'only');
    assert.equal(r.body.detail, `the ${plural.slice(0, -1)} has ended already; nothing was stopped or deleted (only=running)`);
    const kept = await req(d.base, 'GET', spath);
    assert.equal(kept.status, 200, 'kept');
    assert.deepEqual(kept.body, done, 'kept whole');

    const bad = await req(d.base, 'DELETE', `${spath}?only=done`);
    assert.equal(bad.status, 400, bad.text);
    assert.equal(bad.body.field, 'only');
    assert.equal((await req(d.base, 'GET', spath)).status, 200);

    const long = await req(d.base, 'POST', `/api/v1/${plural}`, k.long);
    assert.ok([201, 202].includes(long.status), long.text);
    const lpath = `/api/v1/${plural}/${long.body.id}`;
    assert.equal(k.ended((await req(d.base, 'GET', lpath)).body), false);
    const stop = await req(d.base, 'DELETE', `${lpath}?only=running`);
    assert.equal(stop.status, 204, stop.text);
    assert.equal((await req(d.base, 'GET', lpath)).status, 404);
    // a plain DELETE still forgets an ended job
    assert.equal((await req(d.base, 'DELETE', spath)).status, 204);
    assert.equal((await req(d.base, 'GET', spath)).status, 404);
  });
}
