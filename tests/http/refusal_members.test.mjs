// SPDX-License-Identifier: GPL-3.0-or-later
// A refusal states what would be taken (docs/api-errors.md), byte for
// byte: a choice outside its choices carries `choices` (a sweep's
// rotations, a fit point's, peak's or CSV row's rotation, scene.feed_model where a
// sweep or this daemon takes fewer than the setting has, integrator.method
// beside a LIGGGHTS bed, a pace no real-time factor can hold), a number
// outside its range `min` and `max` (an identification's operating point
// with its step, a stream's rate; its limit is in strict.test.mjs), and a
// limit no field is at fault for names it in `budget` and `limit` without
// a `field` (413 over --max-body, 431 over the query's parameters).
// Nothing is created.
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
    // a CSV's rotation cell: the csv named, its line in the detail
    [fit({ points: undefined, csv: 'beta,rotation,v\n20,cw,0.07\n\n40, x ,0.06\n60,cw,0.05\n' }),
      problem('out-of-range', '/api/v1/fits', "csv: CSV line 4: rotation must be cw or ccw, got 'x'",
        { field: 'csv', choices: ROTATION })],
    [fit({ points: undefined, csv: 'v,beta,rotation\n0.07,20,CW\n' }),
      problem('out-of-range', '/api/v1/fits', "csv: CSV line 2: rotation must be cw or ccw, got 'CW'",
        { field: 'csv', choices: ROTATION })],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
});

test("an identification's operating point whose step leaves [0, 180] deg: the points the step allows", { timeout: 60000 * SLOW }, async () => {
  const was = await listed();
  const id = (identify) => ({ session: { ...CHEAP, pace: 'max' }, identify: { hold: 0.2, ...identify } });
  const at = (field, min, max, detail) => problem('out-of-range', '/api/v1/experiments', detail, { field, min, max });
  await refused(d.base, '/api/v1/experiments', [
    [id({ beta: 178, step: 4 }), at('identify.beta', 4, 176,
      'identify.beta = 178 deg steps to 182 deg with identify.step = 4 deg, outside beta\'s [0, 180] deg: ' +
      'with this step an operating point lies in [4, 176] deg (or, at 178 deg, a step of 0.1 to 2 deg)')],
    [id({ beta: [60, 1], step: 4 }), at('identify.beta[1]', 4, 176,
      'identify.beta[1] = 1 deg steps to -3 deg with identify.step = 4 deg, outside beta\'s [0, 180] deg: ' +
      'with this step an operating point lies in [4, 176] deg (or, at 1 deg, a step of 0.1 to 1 deg)')],
    [id({ beta: [0], step: 0.3 }), at('identify.beta[0]', 0.3, 179.7,
      'identify.beta[0] = 0 deg steps to -0.3 deg with identify.step = 0.3 deg, outside beta\'s [0, 180] deg: ' +
      'with this step an operating point lies in [0.3, 179.7] deg')],
    [id({ beta: [90, 179.95], step: 0.123456789 }), at('identify.beta[1]', 0.123457, 179.876,
      'identify.beta[1] = 179.95 deg steps to 180.073 deg with identify.step = 0.123457 deg, outside beta\'s ' +
      '[0, 180] deg: with this step an operating point lies in [0.123457, 179.876] deg')],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
  // the ends stated are taken (an experiment is kept, not deleted)
  for (const identify of [{ beta: [0.3, 179.7], step: 0.3 }, { beta: [0.123457, 179.876], step: 0.123456789 }]) {
    const ok = await req(d.base, 'POST', '/api/v1/experiments', id(identify));
    assert.equal(ok.status, 201, ok.text);
    const path = `/api/v1/experiments/${ok.body.id}`;
    await until(async () => !['waiting', 'running'].includes((await req(d.base, 'GET', path)).body.state),
      60000 * SLOW, 'the identification ends');
    assert.equal((await req(d.base, 'GET', path)).body.state, 'done');
    assert.match(ok.body.session, /^[0-9a-f]{16}$/, ok.text);
    // its own session is removed within the daemon's next second once it ended: waited
    // for here, so that the later tests' lists before and after a refusal do not see it go
    await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${ok.body.session}`)).status === 404,
      10000 * SLOW, 'the ended experiment\'s session is removed');
  }
});

test('a body over --max-body is 413 with the limit as budget and limit, no field: declared or chunked', async () => {
  const was = await listed();
  const body = JSON.stringify({ ...CHEAP, pad: 'x'.repeat(5000) });
  const r = await req(d.base, 'POST', '/api/v1/sessions', body);
  assert.equal(r.status, 413, r.text);
  assert.deepEqual(r.body, problem('body-too-large', '/api/v1/sessions',
    `the body has ${body.length} bytes; the limit is 4096 (--max-body)`, { budget: 'body-bytes', limit: 4096 }));
  // chunked: no Content-Length, refused once the body has gone past the limit
  const chunk = (s) => `${Buffer.byteLength(s).toString(16)}\r\n${s}\r\n`;
  const c = await rawRequest(d.port, `POST /api/v1/sessions HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
    'Content-Type: application/json\r\nTransfer-Encoding: chunked', `${chunk(body.slice(0, 3000))}${chunk(body.slice(3000))}0\r\n\r\n`);
  assert.equal(c.status, 413, c.raw.toString('latin1').slice(0, 400));
  assert.deepEqual(JSON.parse(c.body.toString('utf8')), problem('body-too-large', '/api/v1/sessions',
    'the body exceeds the limit of 4096 bytes (--max-body)', { budget: 'body-bytes', limit: 4096 }));
  assert.deepEqual(await listed(), was, 'nothing created');
});

test('a query of more parameters than any route takes is 431 with the limit as budget and limit, no field', async () => {
  const query = (n) => Array.from({ length: n }, (_, i) => `a${i}=${i}`).join('&');
  const r = await rawRequest(d.port, `GET /api/v1/sessions?${query(65)} HTTP/1.1\r\nHost: 127.0.0.1:${d.port}`);
  assert.equal(r.status, 431, r.raw.toString('latin1').slice(0, 400));
  assert.deepEqual(JSON.parse(r.body.toString('utf8')), problem('header-fields-too-large', '/api/v1/sessions',
    'the query has 65 parameters; no route takes more than 64', { budget: 'query-parameters', limit: 64 }));
  // 64 are read, and the first unknown one is named
  const at = await req(d.base, 'GET', `/api/v1/sessions?${query(64)}`);
  assert.equal(at.status, 400, at.text);
  assert.equal(at.body.field, 'a0', at.text);
});

test('scene.feed_model beyond what a sweep takes: the choices it takes, no range', async () => {
  const was = await listed();
  const detail = 'scene.feed_model must be column in sweeps, fits and experiments; liggghts and auto run as a ' +
    'session (POST /api/v1/sessions) or in `convsim run` (docs/dem.md, docs/feed-models.md)';
  await refused(d.base, '/api/v1/sweeps', [[{ beta: [30], scene: { feed_model: 'liggghts' } },
    problem('out-of-range', '/api/v1/sweeps', detail, { field: 'scene.feed_model', choices: ['column'] })]]);
  await refused(d.base, '/api/v1/fits', [[{ free: ['e'], points: [{ beta: 30, rotation: 'cw', v: 0.1 }], scene: { feed_model: 'auto', model_tol: 0.01 } },
    problem('out-of-range', '/api/v1/fits', detail, { field: 'scene.feed_model', choices: ['column'] })]]);
  assert.deepEqual(await listed(), was, 'nothing started');
});

test('a LIGGGHTS session where the daemon has no bed program, or with an adaptive method: the choices it takes', { timeout: 30000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-refusal-'));
  const none = join(dir, 'no-bed');
  const nobed = await startDaemon(['--dem-bed', none]);
  try {
    await refused(nobed.base, '/api/v1/sessions', [[{ scene: { feed_model: 'liggghts', layers: 1 }, pace: 'max', until: 1 },
      problem('out-of-range', '/api/v1/sessions', `scene.feed_model liggghts needs the bed program ${none}, which this ` +
        'daemon does not find (built only where LIGGGHTS is installed: `make deps` then `make`; or --dem-bed PATH); ' +
        'column is offered', { field: 'scene.feed_model', choices: ['column', 'auto'] })]]);
    assert.equal((await req(nobed.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
  } finally {
    assert.equal((await nobed.stop()).code, 0, nobed.stderr());
  }
  // a bed program that is never started: the method is refused before it,
  // with the methods of a fixed step in the setting's order
  const bed = join(dir, 'bed');
  writeFileSync(bed, '#!/bin/sh\nexit 1\n');
  chmodSync(bed, 0o755);
  const dem = await startDaemon(['--dem-bed', bed]);
  try {
    await refused(dem.base, '/api/v1/sessions', [[{ scene: { feed_model: 'liggghts', layers: 1 }, integrator: { method: 'dopri5' }, pace: 'max', until: 1 },
      problem('out-of-range', '/api/v1/sessions', 'feed_model liggghts: the method must take a fixed step (euler, rk4 or dem), not dopri5',
        { field: 'integrator.method', choices: ['rk4', 'euler', 'dem'] })]]);
    assert.equal((await req(dem.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
  } finally {
    assert.equal((await dem.stop()).code, 0, dem.stderr());
  }
});

test('a session no real-time pace can hold: pace\'s one choice, "max", with the budget', { timeout: 30000 * SLOW }, async () => {
  const cores = await startDaemon(['--max-paced-cores', '1']);
  try {
    // 2,500 CPU s a simulated s (bounds.test.mjs): no pace from 0.001 within one core
    const slow = { scene: { ...CHEAP.scene, start: 'rest' }, integrator: { dt: 2e-10 }, sample_rate: 10000, pace: 0.001 };
    const r = await req(cores.base, 'POST', '/api/v1/sessions', slow);
    assert.equal(r.status, 422, r.text);
    const { detail, ...rest } = r.body;
    assert.deepEqual(rest, {
      type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422, instance: '/api/v1/sessions',
      field: 'pace', budget: 'cpu', limit: 1, choices: ['max'],
    }, r.text);
    assert.match(detail, /^this session needs [\d.e+]+ cores? \([\d.e+]+ ms of CPU per simulated s at pace 0\.001\), more than the 1 core for paced sessions \(--max-paced-cores\); nothing was created, no pace from 0\.001 fits: run it at pace "max"$/);
    assert.equal((await req(cores.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
  } finally {
    assert.equal((await cores.stop()).code, 0, cores.stderr());
  }
});

test("a stream's rate outside (0, 100000] is 400 bad-query with that range, its open end as min", async () => {
  const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, scene: { ...CHEAP.scene, feed: false }, pace: 1 });
  assert.equal(s.status, 201, s.text);
  const stream = `/api/v1/sessions/${s.body.id}/stream`;
  for (const rate of ['0', '-1', '100001', '1e6', '0x10', 'x']) {
    const r = await req(d.base, 'GET', `${stream}?rate=${rate}`);
    assert.equal(r.status, 400, `${rate}: ${r.text}`);
    assert.deepEqual(r.body, {
      type: '/api/v1/problems/bad-query', title: 'Bad query parameter', status: 400,
      detail: 'rate must be a number of samples per simulated second in (0, 100000]', instance: stream,
      field: 'rate', min: 0, max: 100000,
    }, rate);
  }
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${s.body.id}`)).status, 204);
});
