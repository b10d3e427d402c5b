// SPDX-License-Identifier: GPL-3.0-or-later
// A count outside its limit is refused as a number outside its range is
// (docs/api-errors.md): 422 out-of-range naming the member, with the
// counts allowed as `min` and `max` and the detail saying the same: a
// fit's points, peaks, free parameters and CSV rows; a sweep's beta list
// and grid (beta.step: the step's own range), rotations, vary's settings
// and each one's values, the study's points, band_from_fit's characters;
// an experiment's schedule, operating points, setpoints, disturbances, a
// disturbance's set and a session id's characters. Nothing is started.
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

// nine settings, each with a value it takes
const SETTINGS = [['mu', 0.5], ['e', 0.01], ['R', 0.5], ['k_c', 1e5], ['m_n', 0.01], ['b_s1', 10], ['k_s1', 1e4],
  ['m1', 1], ['m2', 1]];
const vary = (n) => Object.fromEntries(SETTINGS.slice(0, n).map(([s, v]) => [s, [v]]));

test('a sweep: the beta list and grid, rotations, vary and its values, the study\'s points, band_from_fit', async () => {
  const was = await listed();
  const sweep = (extra) => ({ ...CHEAP, t_end: 0.3, ...extra });
  await refused('/api/v1/sweeps', [
    [sweep({ beta: times(1001, (i) => i * 0.1) }), 'beta', 1, 1000, 'beta has 1001 angles; a sweep takes 1 to 1000'],
    [sweep({ beta: [] }), 'beta', 1, 1000, 'beta has 0 angles; a sweep takes 1 to 1000'],
    [sweep({ beta: { from: 0, to: 180, step: 0 } }), 'beta.step', 0, 180, 'beta.step must lie in (0, 180] deg'],
    [sweep({ beta: { from: 0, to: 180, step: 200 } }), 'beta.step', 0, 180, 'beta.step must lie in (0, 180] deg'],
    [sweep({ beta: { from: 90, to: 30, step: 10 } }), 'beta.to', 90, 180,
      'beta.to must lie in [90, 180] deg, not below beta.from'],
    [sweep({ beta: { from: 0, to: 180, step: 0.1 } }), 'beta.step', 0.180181, 180,
      'beta.step 0.1 gives 1801 angles from 0 to 180 deg; a sweep takes 1 to 1000: beta.step must lie in ' +
      '[0.180181, 180] deg'],
    [sweep({ rotations: [] }), 'rotations', 1, 2, 'rotations has 0 entries; a sweep takes 1 to 2 ("cw", "ccw")'],
    [sweep({ rotations: ['cw', 'ccw', 'cw'] }), 'rotations', 1, 2,
      'rotations has 3 entries; a sweep takes 1 to 2 ("cw", "ccw")'],
    [sweep({ vary: { mu: times(2001, (i) => i * 0.001) } }), 'vary.mu', 1, 2000,
      'vary.mu has 2001 values; a sweep takes 1 to 2000'],
    [sweep({ vary: { mu: [] } }), 'vary.mu', 1, 2000, 'vary.mu has 0 values; a sweep takes 1 to 2000'],
    [sweep({ vary: { mu: { from: 0, to: 2, step: 0.001 } } }), 'vary.mu', 1, 2000,
      'vary.mu: 0:2:0.001 gives 2001 values; a sweep takes 1 to 2000'],
    [sweep({ vary: vary(9) }), 'vary', 1, 8, 'vary has 9 settings; a sweep varies 1 to 8'],
    [sweep({ beta: [30, 60], vary: vary(8) }), 'vary', 1, 7, 'vary has 8 settings; a sweep varies 1 to 7 besides beta'],
    [sweep({ vary: {} }), 'vary', 1, 8, 'vary has 0 settings; a sweep varies 1 to 8'],
    [sweep({ vary: { mu: { from: 0, to: 2, step: 0.01 }, e: { from: 0.01, to: 0.05, step: 0.01 } } }), 'vary', 1, 2000,
      'the study has 2010 points (1005 per rotation sense); a sweep takes 1 to 2000'],
    [sweep({ vary: { mu: { from: 0, to: 2, step: 0.1 } }, lhs: 1500 }), 'lhs', 1, 1000,
      'the study has 3000 points (1500 per rotation sense); a sweep takes 1 to 2000: lhs 1 to 1000 with 2 rotation senses'],
    [sweep({ band_from_fit: 'f'.repeat(24) }), 'band_from_fit', 1, 23,
      'band_from_fit has 24 bytes; a fit\'s id has 1 to 23'],
    [sweep({ band_from_fit: '' }), 'band_from_fit', 1, 23, 'band_from_fit has 0 bytes; a fit\'s id has 1 to 23'],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
  // the ends stated are taken: the grid's least step, a list of 1000 angles
  for (const [beta, n] of [[{ from: 0, to: 180, step: 0.180181 }, 999], [times(1000, (i) => i * 0.1), 1000]]) {
    const ok = await req(d.base, 'POST', '/api/v1/sweeps', sweep({ beta, rotations: ['cw'] }));
    assert.equal(ok.status, 202, ok.text);
    assert.equal(ok.body.total, n, ok.text);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sweeps/${ok.body.id}`)).status, 204);
  }
});

test('an experiment: its schedule, operating points, setpoints, disturbances, a set\'s and an id\'s length', async () => {
  const was = await listed();
  const seg = (i) => ({ beta: 30, until: i + 1 });
  const sp = (i) => ({ v: 0.1, until: i + 1 });
  const loop = (extra) => ({ control: { setpoint: [sp(0), sp(1)] }, ...extra });
  const long = { ['a'.repeat(250)]: 1 };
  await refused('/api/v1/experiments', [
    [{ schedule: times(33, seg) }, 'schedule', 1, 32, 'schedule has 33 segments; an experiment takes 1 to 32'],
    [{ schedule: [] }, 'schedule', 1, 32, 'schedule has 0 segments; an experiment takes 1 to 32'],
    [{ identify: { beta: [30, 50, 70, 90, 110] } }, 'identify.beta', 1, 4,
      'identify.beta has 5 operating points; an identification takes 1 to 4'],
    [{ identify: { beta: [] } }, 'identify.beta', 1, 4, 'identify.beta has 0 operating points; an identification takes 1 to 4'],
    [{ control: { setpoint: times(33, sp) } }, 'control.setpoint', 1, 32,
      'control.setpoint has 33 setpoints; a closed loop takes 1 to 32'],
    [{ control: { setpoint: [] } }, 'control.setpoint', 1, 32, 'control.setpoint has 0 setpoints; a closed loop takes 1 to 32'],
    [loop({ disturbances: times(9, () => ({ at: 1, set: { omega_ss: 150 } })) }), 'disturbances', 0, 8,
      'disturbances has 9 entries; a closed loop takes 0 to 8'],
    [loop({ disturbances: [{ at: 1, set: long }] }), 'disturbances[0].set', 2, 199,
      'disturbances[0].set is 256 bytes as JSON; a disturbance\'s set takes 2 to 199'],
    [{ session: 's'.repeat(24), schedule: [seg(0)] }, 'session', 1, 23,
      'session has 24 bytes; a session\'s id has 1 to 23'],
    [{ session: '', schedule: [seg(0)] }, 'session', 1, 23, 'session has 0 bytes; a session\'s id has 1 to 23'],
  ]);
  assert.deepEqual(await listed(), was, 'nothing started');
});
