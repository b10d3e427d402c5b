// SPDX-License-Identifier: GPL-3.0-or-later
// A fit's value outside its range is refused as a session's is
// (docs/api-errors.md): 422 out-of-range naming the field with the range
// as `min` and `max` (an open end given as its limit), and nothing
// started.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, CHEAP } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const POINTS = [
  { beta: 20, rotation: 'cw', v: 0.07 },
  { beta: 60, rotation: 'cw', v: 0.06 },
];
const fit = (extra = {}) => ({ ...CHEAP, t_end: 2, free: ['e'], points: POINTS, curve_step: 45, ...extra });
const SIGMA = POINTS.map((p) => ({ ...p, sigma: 0.01 }));

test('every range refusal of a fit carries min and max', async () => {
  const before = (await req(d.base, 'GET', '/api/v1/fits')).text;
  const cases = [
    [{ t_end: 700 }, 't_end', 0, 600],
    [{ scene: { ...CHEAP.scene, transient: 1 }, t_end: 1 }, 't_end', 1, 600],
    [{ points: [{ ...POINTS[0], beta: 200 }, POINTS[1]] }, 'points[0].beta', 0, 180],
    [{ points: [POINTS[0], { ...POINTS[1], v: 101 }] }, 'points[1].v', -100, 100],
    [{ points: [SIGMA[0], { ...SIGMA[1], sigma: 0 }] }, 'points[1].sigma', 0, 100],
    [{ points: undefined, peaks: [{ rotation: 'cw', beta: 38, sigma: 200 }] }, 'peaks[0].sigma', 0, 180],
    [{ points: undefined, peaks: [{ rotation: 'cw', beta: -1 }] }, 'peaks[0].beta', 0, 180],
    [{ fd_step: 0.6 }, 'fd_step', 0, 0.5],
    [{ max_iter: 0 }, 'max_iter', 1, 1000],
    [{ max_iter: 2.5 }, 'max_iter', 1, 1000],
    [{ curve_step: 100 }, 'curve_step', 0, 90],
    [{ starts: 33 }, 'starts', 1, 32],
    [{ starts: 1.5 }, 'starts', 1, 32],
    [{ free: [{ name: 'e', min: -1 }] }, 'free[0].min', 0, 0.5],
    [{ free: [{ name: 'e', max: 2 }] }, 'free[0].max', 0, 0.5],
    [{ free: [{ name: 'e', min: 0.1, max: 0.01 }] }, 'free[0].max', 0.1, 0.5],
    [{ free: ['mu', { name: 'e', min: 0.01, max: 0.04, start: 0.05 }] }, 'free[1].start', 0.01, 0.04],
    [{ points: SIGMA, free: [{ name: 'e', max: 0.05, prior: { mean: 0.06, sd: 0.002 } }] }, 'free[0].prior.mean', 0, 0.05],
    [{ points: SIGMA, free: [{ name: 'e', prior: { mean: 0.02, sd: 0 } }] }, 'free[0].prior.sd', 0, 5],
    [{ points: SIGMA, free: [{ name: 'e', min: 0.001, prior: { mean: 0.02, factor: 1 } }] }, 'free[0].prior.factor', 1, 1e6],
  ];
  for (const [extra, field, min, max] of cases) {
    const r = await req(d.base, 'POST', '/api/v1/fits', fit(extra));
    const at = `${JSON.stringify(extra)}: ${r.text}`;
    assert.equal(r.status, 422, at);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.equal(r.body.type, '/api/v1/problems/out-of-range', at);
    assert.equal(r.body.field, field, at);
    assert.equal(r.body.min, min, at);
    assert.equal(r.body.max, max, at);
  }
  assert.equal((await req(d.base, 'GET', '/api/v1/fits')).text, before, 'nothing started');
});
