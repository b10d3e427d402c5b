// SPDX-License-Identifier: GPL-3.0-or-later
// The conveyor as a control system (docs/control.md): an identification's
// gain against the slope of v(beta) from a sweep, a closed loop's results
// and a disturbance applied through the PATCH controls, and the 422s that
// name the field (a setpoint out of reach with the range, gains that make
// no sense, a disturbance outside a setting's range), and the 400s of a
// kind or an entry that is not an object. On the czubak2016 preset at
// pace "max", a few simulated seconds each.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, SLOW } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const done = (id) => until(async () => {
  const g = await req(d.base, 'GET', `/api/v1/experiments/${id}`);
  return ['done', 'aborted', 'error'].includes(g.body.state) && g.body;
}, 60000 * SLOW, `experiment ${id}`);

test('identification: the gain is the slope of v(beta) within its standard error', { timeout: 120000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/experiments',
    { identify: { beta: [60, 110], step: 4, hold: 1.5 } });
  assert.equal(r.status, 201, r.text);
  assert.equal(r.body.kind, 'identify');
  // five segments a point: settle, +4, back, -4, back
  assert.deepEqual(r.body.segments.map((s) => s.beta), [60, 64, 60, 56, 60, 110, 114, 110, 106, 110]);
  assert.deepEqual(r.body.segments.map((s) => s.until), [1.5, 3, 4.5, 6, 7.5, 9, 10.5, 12, 13.5, 15]);
  const e = await done(r.body.id);
  assert.equal(e.state, 'done', e.error);
  const sw = await req(d.base, 'POST', '/api/v1/sweeps', { beta: [56, 64, 106, 114], rotations: ['cw'] });
  assert.equal(sw.status, 202, sw.text);
  const points = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/sweeps/${sw.body.id}`);
    return g.body.state === 'done' && g.body.points;
  }, 60000 * SLOW, 'the sweep');
  const v = Object.fromEntries(points.map((p) => [p.beta, p.velocity]));
  const slopes = [(v[64] - v[56]) / 8, (v[114] - v[106]) / 8];
  e.identify.models.forEach((m, i) => {
    assert.ok(m.gain < 0, `the branch between the peaks: v falls as beta rises (${m.gain})`);
    assert.ok(m.gain_se > 0 && m.gain_se < 0.1 * Math.abs(m.gain), `gain ${m.gain} +- ${m.gain_se}`);
    assert.ok(Math.abs(m.gain - slopes[i]) <= m.gain_se,
      `point ${m.beta0}: gain ${m.gain} +- ${m.gain_se}, v(beta) slope ${slopes[i]}`);
    // the server's own secant (2-s windows) is the sweep's (4-s windows)
    assert.ok(Math.abs(m.slope - slopes[i]) < 0.02 * Math.abs(slopes[i]), `${m.slope} vs ${slopes[i]}`);
    assert.ok(m.time_constant > 0 && m.dead_time >= 0 && m.samples > 100, JSON.stringify(m));
  });
  const csv = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}?format=csv`);
  const lines = csv.text.trim().split('\n');
  assert.match(lines[0], /,operating_point,gain,gain_se,time_constant,time_constant_se,dead_time,dead_time_se$/);
  assert.equal(lines.length, 11);
  const col = lines[0].split(',');
  assert.equal(Number(lines[6].split(',')[col.indexOf('operating_point')]), 110);
  assert.equal(Number(lines[6].split(',')[col.indexOf('gain')]), e.identify.models[1].gain);
});

test('closed loop: setpoints held with a small steady error, a disturbance applied', { timeout: 120000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/experiments', {
    control: {
      setpoint: [{ v: -0.08, until: 2.5 }, { v: 0.10, until: 10 }],
      controller: { kp: 2, ki: 800 },
    },
    // the feed's load (a control of the PATCH table like any other) after the supply
    disturbances: [{ at: 4.5, set: { omega_ss: 150 } }, { at: 7.5, set: { m_n: 0.75 } }],
    keep_session: true,
  });
  assert.equal(r.status, 201, r.text);
  assert.equal(r.body.kind, 'control');
  const c0 = r.body.control;
  assert.deepEqual(c0.controller, { tuning: 'given', kp: 2, ki: 800 });
  assert.ok(c0.reachable.v_min < -0.14 && c0.reachable.v_max > 0.15, JSON.stringify(c0.reachable));
  assert.equal(c0.reachable.beta_max, 137.5);
  // each setpoint's beta is the feedforward's: inside the branch, v falling with beta
  const [b1, b2] = r.body.segments.map((s) => s.beta);
  assert.ok(c0.reachable.beta_min < b2 && b2 < b1 && b1 < c0.reachable.beta_max, `${b1} ${b2}`);
  const e = await done(r.body.id);
  assert.equal(e.state, 'done', e.error);
  // the loop's per-period beta leaves the segment's transport estimate
  // running: the next segment starts from a measured velocity, and the
  // overshoot is a fraction of the step from there
  const [s1, s2] = e.segments;
  assert.ok(Math.abs(s2.start_velocity + 0.08) < 0.004, `start velocity ${s2.start_velocity}`);
  assert.ok(Number.isFinite(s1.mean_velocity) && Number.isFinite(s2.uncertainty), JSON.stringify(s2));
  assert.ok(e.control.setpoints[1].overshoot > 0.01, JSON.stringify(e.control.setpoints[1]));
  // given gains stay given across the curve change (omega_ss at 4.5 s)
  assert.deepEqual(e.control.curves.map((c) => [c.omega_ss, c.retuned, c.kp, c.ki]), [[150, false, 2, 800]]);
  for (const [i, sp] of e.control.setpoints.entries()) {
    assert.ok(sp.steady_error < 0.01, `setpoint ${i}: steady error ${sp.steady_error}`);
    assert.ok(sp.settling_time > 0 && sp.settling_time < 2.5, `setpoint ${i}: settling ${sp.settling_time}`);
    assert.ok(sp.iae > 0, `iae ${sp.iae}`);
  }
  const [dist, load] = e.control.disturbances;
  assert.deepEqual(dist.set, { omega_ss: 150 });
  // applied at the end of the integrator's step at or after 4.5 s
  assert.ok(dist.t_applied >= e.t_start + 4.5 && dist.t_applied < e.t_start + 4.51, `${dist.t_applied}`);
  // -4.5 % omega_ss knocks v down by a third of the setpoint; the loop brings it back
  assert.ok(dist.max_deviation > 0.02, JSON.stringify(dist));
  assert.ok(dist.recovery_time > 0 && dist.recovery_time < 2.5, JSON.stringify(dist));
  // +50 % load: a smaller knock, recovered before the end
  assert.deepEqual(load.set, { m_n: 0.75 });
  assert.ok(load.t_applied >= e.t_start + 7.5 && load.t_applied < e.t_start + 7.51, `${load.t_applied}`);
  assert.ok(load.max_deviation > 0.002 && load.recovery_time > 0, JSON.stringify(load));
  // through the session's control path: its status has the new omega_ss
  const s = await req(d.base, 'GET', `/api/v1/sessions/${e.session}`);
  assert.equal(s.body.status.omega_ss, 150);
  const csv = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}?format=csv`);
  const lines = csv.text.trim().split('\n');
  assert.match(lines[0], /,setpoint,settling_time,overshoot,iae,steady_error,kp,ki$/);
  const col = lines[0].split(',');
  assert.equal(Number(lines[1].split(',')[col.indexOf('setpoint')]), -0.08);
  assert.equal(Number(lines[2].split(',')[col.indexOf('steady_error')]), e.control.setpoints[1].steady_error);
  await req(d.base, 'DELETE', `/api/v1/sessions/${e.session}`);
});

test('a change of omega_ss mid-run: the controller takes up the new scene\'s v(beta) curve', { timeout: 120000 * SLOW }, async () => {
  // the feedforward alone (a proportional term of 1e-4 deg per m/s) so that
  // the beta commanded is the curve's inverse at the setpoint
  const control = { setpoint: [{ v: 0.10, until: 1.5 }, { v: 0.06, until: 3 }], controller: { kp: 0.0001, ki: 0 } };
  const r = await req(d.base, 'POST', '/api/v1/experiments',
    { control, disturbances: [{ at: 1, set: { omega_ss: 141.4 } }], keep_session: true });
  assert.equal(r.status, 201, r.text);
  const e = await done(r.body.id);
  assert.equal(e.state, 'done', e.error);
  assert.equal(e.control.curve_changes, 1);
  // the same setpoints on that session now, at 141.4 rad/s: its curve from the start
  const r2 = await req(d.base, 'POST', '/api/v1/experiments', { session: e.session, control });
  assert.equal(r2.status, 201, r2.text);
  const e2 = await done(r2.body.id);
  assert.equal(e2.state, 'done', e2.error);
  assert.equal(e2.control.curve_changes, 0);
  assert.deepEqual(e.control.reachable, e2.control.reachable, 'the curve in use at the end is the new scene\'s');
  const [b0, b1] = e.segments.map((s) => s.beta);
  const [n0, n1] = e2.segments.map((s) => s.beta);
  // -10 % omega_ss: the feedforward at 0.10 m/s moves by degrees
  assert.ok(Math.abs(b0 - n0) > 2, `0.10 m/s: ${b0} deg at 157 rad/s, ${n0} at 141.4`);
  // the setpoint after the change started from the new curve's feedforward
  assert.ok(Math.abs(b1 - n1) < 1e-9, `0.06 m/s: ${b1} vs ${n1}`);
  // and the controller's last command is the new curve's inverse at 0.06 m/s
  const s = await req(d.base, 'GET', `/api/v1/sessions/${e.session}`);
  assert.equal(s.body.status.omega_ss, 141.4);
  assert.ok(Math.abs(s.body.status.beta_target - n1) < 0.01, `${s.body.status.beta_target} vs ${n1}`);
  // which holds the setpoint on the new scene with the feedforward alone
  assert.ok(e.control.setpoints[1].steady_error < 0.02, JSON.stringify(e.control.setpoints[1]));
  await req(d.base, 'DELETE', `/api/v1/sessions/${e.session}`);
});

// "auto" gains follow the plant: after -10 % omega_ss the v(beta) curve is
// flatter at the operating point, and SIMC's gains are tuned again from
// its slope there with the identification's T and L (docs/control.md).
test('"auto" gains re-tuned from the new curve\'s slope after a change of omega_ss', { timeout: 120000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/experiments', {
    control: { setpoint: [{ v: 0.10, until: 2 }, { v: 0.08, until: 4 }] },
    disturbances: [{ at: 1, set: { omega_ss: 141.4 } }], keep_session: true,
  });
  assert.equal(r.status, 201, r.text);
  assert.deepEqual(r.body.control.curves, []);
  const e = await done(r.body.id);
  assert.equal(e.state, 'done', e.error);
  const { controller: g, curves } = e.control;
  assert.equal(e.control.curve_changes, 1);
  assert.equal(curves.length, 1);
  const [c] = curves;
  assert.equal(c.rotation, 'cw');
  assert.equal(c.omega_ss, 141.4);
  assert.ok(c.t >= 1 && c.t < 1.1, `taken up at the first sample after the change: ${c.t}`);
  assert.equal(c.retuned, true);
  // SIMC on the new slope with the identification's T and L and the same tau_c
  const { time_constant: T, dead_time: L } = g.identification;
  const kp = T / (Math.abs(c.slope) * (g.tau_c + L));
  assert.ok(Math.abs(c.kp - kp) < 1e-9 * kp, `kp ${c.kp} vs ${kp}`);
  assert.ok(Math.abs(c.ki - kp / Math.min(T, 4 * (g.tau_c + L))) < 1e-9 * c.ki, `ki ${c.ki}`);
  // the flatter curve asks for larger gains than the request's
  assert.ok(c.kp > 1.3 * g.kp && c.ki > 1.3 * g.ki, `${c.kp} ${c.ki} vs ${g.kp} ${g.ki}`);
  // the operating point: the running setpoint's feedforward on the new curve
  assert.ok(Math.abs(e.segments[1].beta - c.beta0) > 1, 'the next setpoint has its own feedforward');
  // the slope is the new scene's: an identification's secant over beta0 -+ 4 deg there
  const id = await req(d.base, 'POST', '/api/v1/experiments',
    { session: e.session, identify: { beta: c.beta0, step: 4, hold: 0.2 } });
  assert.equal(id.status, 201, id.text);
  const slope = id.body.identify.models[0].slope;
  assert.ok(Math.abs(c.slope - slope) < 0.05 * Math.abs(slope), `${c.slope} vs ${slope} at ${c.beta0} deg`);
  assert.equal((await done(id.body.id)).state, 'done');
  // the CSV: the gains in use at each segment's end
  const csv = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}?format=csv`);
  const lines = csv.text.trim().split('\n');
  const col = lines[0].split(',');
  assert.equal(Number(lines[2].split(',')[col.indexOf('kp')]), c.kp);
  assert.equal(Number(lines[2].split(',')[col.indexOf('ki')]), c.ki);
  await req(d.base, 'DELETE', `/api/v1/sessions/${e.session}`);
});

test('a PATCH of omega_ss while a closed loop runs: its curve, measured aside, taken up', { timeout: 120000 * SLOW }, async () => {
  const control = { setpoint: [{ v: 0.06, until: 30 }], controller: { kp: 0.0001, ki: 0 } };
  // at pace 1 (real time), so that the PATCH lands mid-run; 141.9 rad/s: a
  // scene no other test measured (not in the daemon's cache)
  const r = await req(d.base, 'POST', '/api/v1/experiments', { session: { pace: 1 }, control, keep_session: true });
  assert.equal(r.status, 201, r.text);
  await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`)).body.t - r.body.t_start > 1,
    20000 * SLOW, 'a simulated second');
  const p = await req(d.base, 'PATCH', `/api/v1/sessions/${r.body.session}`, { omega_ss: 141.9 });
  assert.equal(p.status, 200, p.text);
  // the new curve is measured aside (about a CPU second, far more under the
  // sanitizers); once the loop has taken it up, the rest runs flat out
  await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`)).body.control.curve_changes === 1,
    25000, 'the new curve taken up');
  assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${r.body.session}`, { pace: 'max' })).status, 200);
  const e = await done(r.body.id);
  assert.equal(e.state, 'done', e.error);
  assert.equal(e.control.curve_changes, 1);
  // the loop's last command: the session keeps it after the end
  const s = await req(d.base, 'GET', `/api/v1/sessions/${e.session}`);
  assert.equal(s.body.status.omega_ss, 141.9);
  // the same setpoint on that session now: the new scene's curve from the start
  const r2 = await req(d.base, 'POST', '/api/v1/experiments',
    { session: e.session, control: { ...control, setpoint: [{ v: 0.06, until: 0.5 }] } });
  assert.equal(r2.status, 201, r2.text);
  assert.equal(r2.body.control.curve_changes, 0);
  assert.deepEqual(e.control.reachable, r2.body.control.reachable);
  const n0 = r2.body.segments[0].beta;
  // -9.6 % omega_ss moves the feedforward at 0.06 m/s by about a degree
  assert.ok(Math.abs(e.segments[0].beta - n0) > 0.5, `${e.segments[0].beta} vs ${n0}`);
  // the command after the PATCH is the new curve's inverse at 0.06 m/s
  assert.ok(Math.abs(s.body.status.beta_target - n0) < 0.01, `${s.body.status.beta_target} vs ${n0}`);
  assert.equal((await done(r2.body.id)).state, 'done');
  await req(d.base, 'DELETE', `/api/v1/sessions/${e.session}`);
});

const post = (body) => req(d.base, 'POST', '/api/v1/experiments', body);
const problem = (type, title, detail, field, extra = {}) => ({
  type: `/api/v1/problems/${type}`, title, status: 422, detail,
  instance: '/api/v1/experiments', field, ...extra,
});

test('422: a setpoint out of the machine\'s reach names it and the range', { timeout: 60000 * SLOW }, async () => {
  const r = await post({ control: { setpoint: [{ v: 0.1, until: 1 }, { v: 0.5, until: 2 }] } });
  assert.equal(r.status, 422);
  assert.equal(r.headers.get('content-type'), 'application/problem+json');
  const { min, max } = r.body;
  assert.ok(min < -0.14 && max > 0.15, `${min} ${max}`);
  // the range as the detail prints it (4 digits), rounded inward: its ends are taken
  for (const x of [min, max]) assert.equal(x, Number(x.toPrecision(4)), `${x} has more than 4 digits`);
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    `control.setpoint[1].v = 0.5 m/s is outside the machine's reachable range [${min}, ${max}] m/s: ` +
    'the v(beta) curve between its minimum at 137.5 deg and its maximum at 30 deg',
    'control.setpoint[1].v', { min, max }));
  const ok = await post({ control: { setpoint: [{ v: max, until: 0.5 }, { v: min, until: 1 }] } });
  assert.equal(ok.status, 201, ok.text);
  await req(d.base, 'DELETE', `/api/v1/sessions/${ok.body.session}`);
});

test('422: gains that make no sense', async () => {
  let r = await post({ control: { setpoint: [{ v: 0.1, until: 1 }], controller: { kp: -1, ki: 3 } } });
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    'control.controller.kp must lie within [0, 10000] deg per m/s', 'control.controller.kp', { min: 0, max: 10000 }));
  r = await post('{"control": {"setpoint": [{"v": 0.1, "until": 1}], "controller": {"kp": 1, "ki": 1e999}}}');
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    'control.controller.ki must lie within [0, 100000] deg per m', 'control.controller.ki', { min: 0, max: 100000 }));
  r = await post({ control: { setpoint: [{ v: 0.1, until: 1 }], controller: { kp: 0, ki: 0 } } });
  assert.deepEqual(r.body, problem('invalid-value', 'Invalid value',
    'control.controller: kp = ki = 0 leaves only the feedforward; give a positive kp or ki, or "auto"',
    'control.controller'));
  r = await post({ control: { setpoint: [{ v: 0.1, until: 1 }], controller: { kp: 1 } } });
  assert.deepEqual(r.body, problem('invalid-value', 'Invalid value',
    'control.controller.ki is required (deg per m)', 'control.controller.ki'));
});

test('422: a disturbance outside a setting\'s range, or not a machine control', async () => {
  const ctl = { setpoint: [{ v: 0.1, until: 2 }] };
  const before = (await req(d.base, 'GET', '/api/v1/experiments')).body.experiments.length;
  let r = await post({ control: ctl, disturbances: [{ at: 1, set: { omega_ss: 5000 } }] });
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    'disturbances[0].set: omega_ss must be a finite number in [1, 1000] rad/s',
    'disturbances[0].set.omega_ss', { min: 1, max: 1000 }));
  r = await post({ control: ctl, disturbances: [{ at: 1, set: { m_n: 0 } }] });
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    'disturbances[0].set: m_n must be a finite number in [0.0001, 100] kg',
    'disturbances[0].set.m_n', { min: 0.0001, max: 100 }));
  r = await post({ control: ctl, disturbances: [{ at: 1, set: { beta: 50 } }] });
  assert.deepEqual(r.body, problem('invalid-value', 'Invalid value',
    'disturbances[0].set.beta: a disturbance changes the machine, not beta (the controller\'s) nor the session\'s run',
    'disturbances[0].set.beta'));
  // an empty set names the set itself, not a member after a dot
  r = await post({ control: ctl, disturbances: [{ at: 1, set: {} }] });
  assert.equal(r.status, 422, r.text);
  assert.equal(r.body.field, 'disturbances[0].set');
  assert.match(r.body.detail, /^disturbances\[0\]\.set: no change given/);
  r = await post({ control: ctl, disturbances: [{ at: 3, set: { omega_ss: 150 } }] });
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    'disturbances[0].at must lie within [0, 2] s (within the experiment)', 'disturbances[0].at', { min: 0, max: 2 }));
  r = await post({ schedule: [{ beta: 30, until: 1 }], disturbances: [] });
  assert.deepEqual(r.body, problem('invalid-value', 'Invalid value',
    'disturbances belong to a closed-loop experiment ("control")', 'disturbances'));
  r = await post({ session: { scene: { feed: false } }, identify: { beta: 60 } });
  assert.deepEqual(r.body, problem('invalid-value', 'Invalid value',
    'identify needs a session whose feed is the engine\'s own (scene.feed true, not a LIGGGHTS bed)', 'session'));
  r = await post({ identify: { beta: 178 } });
  assert.deepEqual(r.body, problem('out-of-range', 'Value out of range',
    'identify.beta = 178 deg steps to 182 deg with identify.step = 4 deg, outside beta\'s [0, 180] deg: ' +
    'with this step an operating point lies in [4, 176] deg (or, at 178 deg, a step of 0.1 to 2 deg)',
    'identify.beta', { min: 4, max: 176 }));
  // nothing was created
  assert.equal((await req(d.base, 'GET', '/api/v1/experiments')).body.experiments.length, before);
});

test('400: a kind, or an entry of one, that is not an object names it and the shape it takes', async () => {
  const wrong = (detail, field) => problem('wrong-type', 'Wrong type', detail, field, { status: 400 });
  const sp = [{ v: 0.1, until: 1 }];
  const cases = [
    [{ identify: 5 }, 'identify must be an object {"beta": DEG or [DEG, ...], "step": DEG, "hold": S}', 'identify'],
    [{ control: [] }, 'control must be an object {"setpoint": [{"v": M_S, "until": S}, ...], "controller": "auto" or {"kp", "ki"}}', 'control'],
    [{ control: { setpoint: sp, controller: 7 } }, 'control.controller must be "auto" or {"kp": DEG_PER_M_S, "ki": DEG_PER_M}', 'control.controller'],
    [{ control: { setpoint: [...sp, 3] } }, 'control.setpoint[1] must be an object {"v": M_S, "until": S}', 'control.setpoint[1].'],
    [{ control: { setpoint: sp }, disturbances: [{ at: 0.5, set: { omega_ss: 150 } }, 'x'] },
      'disturbances[1] must be an object {"at": S, "set": {CONTROL: VALUE}}', 'disturbances[1].'],
    [{ schedule: [{ beta: 30, until: 1 }, []] }, 'schedule[1] must be an object {"beta": DEG, "until": S}', 'schedule[1].'],
  ];
  for (const [body, detail, field] of cases)
    assert.deepEqual((await post(body)).body, wrong(detail, field), JSON.stringify(body));
});

test('a closed loop killed mid-run resumes from its checkpoint and ends; an identification is served again', { timeout: 120000 * SLOW }, async () => {
  const { mkdtempSync, rmSync } = await import('node:fs');
  const { tmpdir } = await import('node:os');
  const { join } = await import('node:path');
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-control-'));
  const args = ['--data-dir', dir, '--checkpoint-interval', '0.5'];
  let k = await startDaemon(args);
  try {
    const id = (await req(k.base, 'POST', '/api/v1/experiments', { identify: { beta: 60, hold: 0.5 } })).body;
    const idDone = await until(async () => {
      const g = await req(k.base, 'GET', `/api/v1/experiments/${id.id}`);
      return g.body.state === 'done' && g;
    }, 30000 * SLOW, 'identification');
    const r = await req(k.base, 'POST', '/api/v1/experiments', {
      session: { pace: 1 },
      control: { setpoint: [{ v: 0.1, until: 1.5 }, { v: -0.05, until: 4 }], controller: { kp: 2, ki: 800 } },
    });
    assert.equal(r.status, 201, r.text);
    await until(async () => (await req(k.base, 'GET', `/api/v1/experiments/${r.body.id}`)).body.t - r.body.t_start > 2,
      20000, 'two simulated seconds');
    k.proc.kill('SIGKILL');
    await k.exited;
    k = await startDaemon(args);
    const again = await req(k.base, 'GET', `/api/v1/experiments/${id.id}`);
    assert.equal(again.text, idDone.text, 'a finished identification is served byte for byte');
    const e = await until(async () => {
      const g = await req(k.base, 'GET', `/api/v1/experiments/${r.body.id}`);
      return g.status === 200 && g.body.state !== 'running' && g.body;
    }, 30000 * SLOW, 'the resumed closed loop');
    assert.equal(e.state, 'done', e.error);
    assert.equal(e.kind, 'control');
    assert.deepEqual(e.control.controller, { tuning: 'given', kp: 2, ki: 800 });
    for (const sp of e.control.setpoints) assert.ok(sp.steady_error < 0.01, JSON.stringify(sp));
  } finally {
    await k.stop();
    rmSync(dir, { recursive: true, force: true });
  }
});
