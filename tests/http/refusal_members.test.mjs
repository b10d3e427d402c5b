// SPDX-License-Identifier: GPL-3.0-or-later
// A refusal states what would be taken (docs/api-errors.md), byte for
// byte: a choice outside its choices carries `choices` (a sweep's
// rotations, a fit point's or peak's rotation, scene.feed_model where a
// sweep or this daemon takes fewer than the setting has, integrator.method
// beside a LIGGGHTS bed, a pace no real-time factor can hold), a number
// outside its range `min` and `max` (an identification's operating point
// with its step), and a limit no field is at fault for names it in
// `budget` and `limit` without a `field` (413 over --max-body, 431 over
// the query's parameters). Nothing is created.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { chmodSync, mkdtempSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, rawRequest, until, CHEAP, SLOW } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(['--max-body', '4096']); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const TITLES = {
  'out-of-range': 'Value out of range', 'wrong-type': 'Wrong type', 'body-too-large': 'Request body too large',
  'header-fields-too-large': 'Request header fields too large',
};
const STATUS = { 'out-of-range': 422, 'wrong-type': 400, 'body-too-large': 413, 'header-fields-too-large': 431 };
const problem = (slug, instance, detail, members) => ({
  type: `/api/v1/problems/${slug}`, title: TITLES[slug], status: STATUS[slug], detail, instance, ...members,
});
const ROTATION = ['cw', 'ccw'];
const listed = async (base = d.base) => Promise.all(['fits', 'sweeps', 'experiments', 'sessions']
  .map(async (k) => (await req(base, 'GET', `/api/v1/${k}`)).text));

async function refused(base, path, cases) {
  for (const [body, expected] of cases) {
    const r = await req(base, 'POST', path, body);
    const at = `${JSON.stringify(body).slice(0, 200)}: ${r.text}`;
    assert.equal(r.status, expected.status, at);
    assert.equal(r.headers.get('content-type'), 'application/problem+json', at);
    assert.deepEqual(r.body, expected, at);
  }
}

test("a sweep's rotations entry that is no sense: its choices, the entry named", async () => {
  const was = await listed();
  const sweep = (rotations) => ({ ...CHEAP, t_end: 0.3, beta: [30], rotations });
  await refused(d.base, '/api/v1/sweeps', [
    [sweep(['x']), problem('out-of-range', '/api/v1/sweeps', 'rotations[0] must be "cw" or "ccw"',
      { field: 'rotations[0]', choices: ROTATION })],
    [sweep(['cw', 'up']), problem('out-of-range', '/api/v1/sweeps', 'rotations[1] must be "cw" or "ccw"',
      { field: 'rotations[1]', choices: ROTATION })],
    [sweep(['ccw', 1]), problem('wrong-type', '/api/v1/sweeps', 'rotations[1] must be "cw" or "ccw"',
      { field: 'rotations[1]', choices: ROTATION })],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
});

test("a fit point's or peak's rotation that is no sense: its choices, the point named", async () => {
  const was = await listed();
  const P = [{ beta: 20, rotation: 'cw', v: 0.07 }, { beta: 40, rotation: 'cw', v: 0.06 }, { beta: 60, rotation: 'cw', v: 0.05 }];
  const fit = (extra) => ({ ...CHEAP, t_end: 2, free: ['e'], curve_step: 45, points: P, ...extra });
  await refused(d.base, '/api/v1/fits', [
    [fit({ points: [P[0], P[1], { ...P[2], rotation: 'x' }] }),
      problem('out-of-range', '/api/v1/fits', 'points[2].rotation must be "cw" or "ccw"',
        { field: 'points[2].rotation', choices: ROTATION })],
    [fit({ points: [P[0], { ...P[1], rotation: 2 }, P[2]] }),
      problem('wrong-type', '/api/v1/fits', 'points[1].rotation must be "cw" or "ccw"',
        { field: 'points[1].rotation', choices: ROTATION })],
    [fit({ points: undefined, peaks: [{ rotation: 'cw', beta: 38 }, { rotation: 'both', beta: 140 }] }),
      problem('out-of-range', '/api/v1/fits', 'peaks[1].rotation must be "cw" or "ccw"',
        { field: 'peaks[1].rotation', choices: ROTATION })],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
});
