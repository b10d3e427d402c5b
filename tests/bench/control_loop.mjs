// SPDX-License-Identifier: GPL-3.0-or-later
// The conveyor as a control system on the czubak2016 preset
// (docs/control.md), against issue 40's targets: the identification's gain
// against the slope of v(beta) from a sweep; setpoint steps +0.10 -> -0.08
// -> +0.05 m/s under the feedforward alone and under PI controllers, each
// setpoint's 2 % settling time against the open-loop reversal time of the
// same beta change (a schedule of the feedforward's betas); disturbances
// of omega_ss, the feed's load and its friction under a setpoint of +0.10
// m/s. Markdown tables on stdout.
// One daemon on loopback, pace "max", about half a minute.
//
//   CONVSIMD=build/convsimd node tests/bench/control_loop.mjs
import { startDaemon, req, until } from '../http/lib.mjs';

const HOLD = Number(process.env.HOLD || 3);
const d = await startDaemon();
const post = async (body) => {
  const r = await req(d.base, 'POST', '/api/v1/experiments', body);
  if (r.status !== 201) throw new Error(r.text);
  return r.body;
};
const done = (id) => until(async () => {
  const g = await req(d.base, 'GET', `/api/v1/experiments/${id}`);
  return ['done', 'aborted', 'error'].includes(g.body.state) && g.body;
}, 300000, id);
const f = (x, n = 3) => (x === null || x === undefined ? '–' : Number(x).toPrecision(n));

try {
  // identification at two operating points, one on each side of v = 0
  const id = await done((await post({ identify: { beta: [60, 110], step: 4, hold: 1.5 } })).id);
  const sw = (await req(d.base, 'POST', '/api/v1/sweeps', { beta: [56, 64, 106, 114], rotations: ['cw'] })).body;
  const pts = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/sweeps/${sw.id}`);
    return g.body.state === 'done' && g.body.points;
  }, 60000, 'sweep');
  const v = Object.fromEntries(pts.map((p) => [p.beta, p.velocity]));
  console.log('Identification (steps of ±4° held 1.5 s; the slope from a sweep at β0 ± 4°):\n');
  console.log('| β0 (°) | gain (m/s per °) | v(β) slope | abs(gain − slope) / SE | T (s) | L (s) | residual (m/s) |');
  console.log('|---|---|---|---|---|---|---|');
  for (const m of id.identify.models) {
    const slope = (v[m.beta0 + 4] - v[m.beta0 - 4]) / 8;
    console.log(`| ${m.beta0} | ${f(m.gain)} ± ${f(m.gain_se, 2)} | ${f(slope)} | ${f(Math.abs(m.gain - slope) / m.gain_se, 2)} | ` +
      `${f(m.time_constant, 2)} ± ${f(m.time_constant_se, 2)} | ${f(m.dead_time, 2)} ± ${f(m.dead_time_se, 2)} | ${f(m.rms, 2)} |`);
  }

  // setpoint steps: the open-loop reversal times of the same beta changes
  const setpoint = [0.10, -0.08, 0.05].map((x, i) => ({ v: x, until: HOLD * (i + 1) }));
  const ff = await done((await post({ control: { setpoint, controller: { kp: 1e-4, ki: 0 } } })).id);
  const betas = ff.segments.map((s) => s.beta);
  const open = await done((await post({ schedule: betas.map((b, i) => ({ beta: b, until: HOLD * (i + 1) })) })).id);
  const runs = [['feedforward alone', ff]];
  for (const [name, controller, extra] of [['PI kp 2, ki 800', { kp: 2, ki: 800 }, {}],
    ['auto (SIMC, τc = 3 L)', 'auto', {}], ['auto (SIMC, τc = L)', 'auto', { tau_c: 'L' }]]) {
    let c = { setpoint, controller, ...extra };
    if (extra.tau_c === 'L') {
      const probe = runs.find(([n]) => n.startsWith('auto'))[1];
      c = { setpoint, controller, tau_c: probe.control.controller.identification.dead_time };
    }
    runs.push([name, await done((await post({ control: c })).id)]);
  }
  console.log(`\nSetpoint steps, ${HOLD} s each (the open-loop reversal time: 90 % of the new steady velocity ` +
    'after the same β change; the target: settling within 2 % in at most 1.5 times it, steady error at most 1 %):\n');
  console.log('| controller | kp, ki | setpoint (m/s) | β (°) | settling (s) | open-loop reversal (s) | ratio | overshoot | steady error |');
  console.log('|---|---|---|---|---|---|---|---|---|');
  for (const [name, e] of runs) {
    e.control.setpoints.forEach((s, i) => {
      const rev = i ? open.segments[i].reversal_time : null;
      const g = e.control.controller;
      console.log(`| ${name} | ${f(g.kp)}, ${f(g.ki)} | ${s.v} | ${f(betas[i])} | ${f(s.settling_time)} | ${f(rev)} | ` +
        `${rev && s.settling_time ? f(s.settling_time / rev, 2) : '–'} | ${f(s.overshoot, 2)} | ${f(100 * s.steady_error, 2)} % |`);
    });
  }

  // disturbances: omega_ss steps under +0.10 m/s
  console.log('\nDisturbances under a setpoint of +0.10 m/s (PI kp 2, ki 800; at 3 s of 8; recovery: until v stays within 2 %):\n');
  console.log('| disturbance | largest deviation (m/s) | recovery (s) | steady error after |');
  console.log('|---|---|---|---|');
  for (const [name, set] of [['omega_ss −4.5 % (150 rad/s)', { omega_ss: 150 }],
    ['omega_ss −10 % (141.4 rad/s)', { omega_ss: 141.4 }], ['omega_ss +5 % (165 rad/s)', { omega_ss: 165 }],
    ['load m_n +50 % (0.75 kg)', { m_n: 0.75 }], ['friction mu −20 % (0.32)', { mu: 0.32 }]]) {
    const e = await done((await post({
      control: { setpoint: [{ v: 0.10, until: 8 }], controller: { kp: 2, ki: 800 } },
      disturbances: [{ at: 3, set }],
    })).id);
    const [dist] = e.control.disturbances;
    console.log(`| ${name} | ${f(dist.max_deviation)} | ${f(dist.recovery_time)} | ${f(100 * e.control.setpoints[0].steady_error, 2)} % |`);
  }

  // "auto" under steps of omega_ss: the gains re-tuned from the new curve's
  // slope, against the request's gains kept (given: what a build before
  // the re-tuning did)
  console.log('\n"auto" under steps of omega_ss at 3 s of 8, setpoint +0.10 m/s: the gains re-tuned by SIMC from the new curve\'s slope at ' +
    'the operating point, against the request\'s gains kept (recovery: until v stays within 2 %):\n');
  console.log('| disturbance | gains | kp, ki at the request | curve slope (m/s per °) | kp, ki after | largest deviation (m/s) | recovery (s) | IAE (mm) |');
  console.log('|---|---|---|---|---|---|---|---|');
  for (const [set, name] of [[{ omega_ss: 150 }, 'omega_ss −4.5 %'], [{ omega_ss: 141.4 }, 'omega_ss −10 %'], [{ omega_ss: 165 }, 'omega_ss +5 %']]) {
    let first = null;
    for (const how of ['re-tuned', 'kept']) {
      const controller = how === 'kept' ? { kp: first.kp, ki: first.ki } : 'auto';
      const e = await done((await post({ control: { setpoint: [{ v: 0.10, until: 8 }], controller }, disturbances: [{ at: 3, set }] })).id);
      const g = e.control.controller, [c] = e.control.curves;
      first = first || g;
      const [dist] = e.control.disturbances;
      console.log(`| ${name} | ${how} | ${f(first.kp)}, ${f(first.ki)} | ${f(c.slope)} | ${f(c.kp)}, ${f(c.ki)} | ` +
        `${f(dist.max_deviation)} | ${f(dist.recovery_time)} | ${f(1000 * e.control.setpoints[0].iae)} |`);
    }
  }
} finally {
  await d.stop();
}
