// SPDX-License-Identifier: GPL-3.0-or-later
// A count outside its limit is refused as a number outside its range is
// (docs/api-errors.md): 422 out-of-range naming the member, with the
// counts allowed as `min` and `max` and the detail saying the same: a
// fit's points, peaks, free parameters and CSV rows. Nothing is started.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, CHEAP } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const range = (instance, field, min, max, detail) => ({
  type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422, detail, instance, field, min, max,
});
const times = (n, f) => Array.from({ length: n }, (_, i) => f(i));
const listed = async () => Promise.all(['fits', 'sweeps', 'experiments', 'sessions']
  .map(async (k) => (await req(d.base, 'GET', `/api/v1/${k}`)).text));

async function refused(path, cases) {
  for (const [body, field, min, max, detail] of cases) {
    const r = await req(d.base, 'POST', path, body);
    const at = `${JSON.stringify(body).slice(0, 200)}: ${r.text}`;
    assert.equal(r.status, 422, at);
    assert.equal(r.headers.get('content-type'), 'application/problem+json', at);
    assert.deepEqual(r.body, range(path, field, min, max, detail), at);
  }
}

const POINTS = [{ beta: 20, rotation: 'cw', v: 0.07 }, { beta: 60, rotation: 'cw', v: 0.06 }];
const PEAK = { rotation: 'cw', beta: 38 };
const fit = (extra = {}) => ({ ...CHEAP, t_end: 2, free: ['e'], points: POINTS, curve_step: 45, ...extra });
const many = (n) => times(n, (i) => ({ beta: i * 0.1, rotation: 'cw', v: 0.05 }));
const csv = (n) => `beta,rotation,v\n${times(n, (i) => `${i * 0.1},cw,0.05`).join('\n')}\n`;

test('a fit: points, peaks, free parameters and CSV rows are counts with their range', async () => {
  const was = await listed();
  await refused('/api/v1/fits', [
    [fit({ points: many(1001) }), 'points', 1, 1000, 'points has 1001 entries; a fit of 1 free parameter takes 1 to 1000'],
    [fit({ free: ['e', 'mu'], points: many(1001) }), 'points', 2, 1000,
      'points has 1001 entries; a fit of 2 free parameters takes 2 to 1000'],
    [fit({ free: ['e', 'mu'], points: POINTS.slice(0, 1) }), 'points', 2, 1000,
      '1 data for 2 free parameters: a fit needs at least as many data as free parameters (2 to 1000 points)'],
    [fit({ points: undefined, peaks: times(9, (i) => ({ rotation: 'cw', beta: 10 + 15 * i })) }), 'peaks', 1, 8,
      'peaks has 9 entries; a fit of 1 free parameter takes 1 to 8'],
    [fit({ free: ['e', 'mu'], points: undefined, peaks: [PEAK] }), 'peaks', 2, 8,
      '1 data for 2 free parameters: a fit needs at least as many data as free parameters (2 to 8 peaks)'],
    [fit({ free: ['e', 'mu', 'R', 'k_c', 'm_n', 'b_s1', 'k_s1', 'm1', 'm2'] }), 'free', 1, 8,
      'free has 9 entries; a fit takes 1 to 8 free parameters'],
    [fit({ free: [] }), 'free', 1, 8, 'free has 0 entries; a fit takes 1 to 8 free parameters'],
    [fit({ points: undefined, csv: csv(1001) }), 'csv', 1, 1000,
      'csv: CSV line 1002: more than 1000 points; a fit of 1 free parameter takes 1 to 1000'],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
});
