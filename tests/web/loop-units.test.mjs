// SPDX-License-Identifier: GPL-3.0-or-later
// Unit tests of the closed-loop and identification panel's pure parts
// (web/js/api-loop.js, fmtPm in format.js): the request bodies from the
// form's text, the answer's members, the per-period velocity from a
// trajectory and the fitted response, against analytic values.
import test from 'node:test';
import assert from 'node:assert/strict';
import * as api from '../../web/js/api.js';
import { fmtPm } from '../../web/js/format.js';

const close = (a, b, tol = 1e-12) => assert.ok(Math.abs(a - b) <= tol, `${a} != ${b}`);
const form = { preset: 'czubak2016', beta: 38, rotation: 'cw', columns: 5, layers: 2, feed: false, drive: 'ideal',
	start: 'steady', method: 'rk4', pace: 1, rate: 500 };
const session = { preset: 'czubak2016', params: { beta: 38, rotation: 'cw' },
	scene: { columns: 5, layers: 2, feed: true, drive: 'ideal', start: 'steady' }, integrator: { method: 'rk4' }, sample_rate: 500 };

test('a closed loop\'s body: setpoints, gains or "auto", disturbances; the feed on, pace max', () => {
	assert.deepEqual(api.loopRequest({ ...form, kind: 'control', setpoints: '0.10:2, -0.08:4', controller: 'pi', kp: 2, ki: 800,
		disturbances: '3: omega_ss=150; 3.5: m_n=0.75, mu=0.3' }), {
		session, keep_session: true,
		control: { setpoint: [{ v: 0.1, until: 2 }, { v: -0.08, until: 4 }], controller: { kp: 2, ki: 800 } },
		disturbances: [{ at: 3, set: { omega_ss: 150 } }, { at: 3.5, set: { m_n: 0.75, mu: 0.3 } }],
	});
	const b = api.loopRequest({ ...form, kind: 'control', setpoints: '0.1:2; x:3', controller: 'auto', disturbances: ' ' });
	assert.deepEqual(b.control.controller, 'auto');
	assert.equal(b.disturbances, undefined);
	/* what is not a number goes as NaN (JSON null), for the daemon to refuse naming it */
	assert.equal(JSON.stringify(b.control.setpoint), '[{"v":0.1,"until":2},{"v":null,"until":3}]');
});

test('an identification\'s body: one point as a number, several as a list, blank step and hold left out', () => {
	assert.deepEqual(api.loopRequest({ ...form, kind: 'identify', points: '60', step: 4, hold: 0.6 }),
		{ session, keep_session: true, identify: { beta: 60, step: 4, hold: 0.6 } });
	assert.deepEqual(api.loopRequest({ ...form, kind: 'identify', points: '60, 110', step: NaN, hold: NaN }).identify,
		{ beta: [60, 110] });
});

test('the answer\'s control and identify members', () => {
	const c = api.normalizeLoop({ kind: 'control', control: {
		controller: { tuning: 'simc', kp: 25, ki: 838, tau_c: 0.4, identification: { gain: -0.003, gain_se: 1e-4 } }, period: 0.04,
		setpoints: [{ v: 0.1, settling_time: null, overshoot: 0, iae: 0.01, steady_error: 0.002 }],
		disturbances: [{ at: 3, set: { omega_ss: 150 }, t_applied: 3.0005, recovery_time: 1.2, max_deviation: 0.04 }],
		curve_changes: 2, curves: [{ t: 3.004, rotation: 'cw', omega_ss: 150, beta0: 97.4, slope: -0.00274, retuned: true, kp: 9.92, ki: 696 },
			{ t: 5, rotation: 'ccw', omega_ss: 150, beta0: 80, slope: null, retuned: false, kp: 2, ki: 800 }] } });
	assert.equal(c.kind, 'control');
	assert.deepEqual(c.control.setpoints, [{ v: 0.1, settlingTime: NaN, overshoot: 0, iae: 0.01, steadyError: 0.002 }]);
	assert.equal(c.control.tuning, 'simc');
	assert.equal(c.control.tauC, 0.4);
	assert.equal(c.control.identification.gainSe, 1e-4);
	assert.deepEqual(c.control.disturbances[0], { at: 3, set: { omega_ss: 150 }, tApplied: 3.0005, recoveryTime: 1.2, maxDeviation: 0.04 });
	assert.equal(c.control.curveChanges, 2);
	assert.deepEqual(c.control.curves, [
		{ t: 3.004, rotation: 'cw', omegaSs: 150, beta0: 97.4, slope: -0.00274, retuned: true, kp: 9.92, ki: 696 },
		{ t: 5, rotation: 'ccw', omegaSs: 150, beta0: 80, slope: NaN, retuned: false, kp: 2, ki: 800 }]);
	assert.deepEqual(api.normalizeLoop({ kind: 'control', control: {} }).control.curves, []);
	const i = api.normalizeLoop({ kind: 'identify', identify: { step: 4, hold: 1.5, models: [{ beta0: 60, gain: -0.0033, gain_se: 7e-5,
		time_constant: 0.013, time_constant_se: 0.01, dead_time: 0.13, dead_time_se: 0.0096, t_from: 0.75 }] } });
	assert.equal(i.identify.models[0].deadTimeSe, 0.0096);
	assert.equal(i.identify.models[0].tFrom, 0.75);
	assert.equal(api.normalizeLoop({ state: 'done' }).kind, 'schedule');
});

test('per-period velocity: a drift with a vibration of the period on it gives the drift', () => {
	/* x = 0.1 t + 1 mm sin(2 pi t / P), P = 2 pi / 157.08 s, rows every
	 * P / 4.3 (not a divisor: the period's start is interpolated) */
	const w = 157.08, P = 2 * Math.PI / w, n = 200;
	const t = Array.from({ length: n }, (_, k) => k * P / 4.3);
	const traj = { t, rotor_speed: t.map(() => w), feed_displacement: t.map(x => 0.1 * x + 1e-3 * Math.sin(2 * Math.PI * x / P)) };
	const v = api.periodVelocity(traj);
	assert.ok(v.slice(0, 4).every(Number.isNaN), 'nothing before one period');
	/* linear interpolation of the sine between rows 1/4.3 period apart:
	 * an error of at most A (pi/4.3)^2 / 2 / P */
	for (const x of v.slice(5)) close(x, 0.1, 1e-3 * (Math.PI / 4.3) ** 2 / 2 / P);
	/* rows on the period's divisors: exact */
	const t4 = Array.from({ length: 40 }, (_, k) => k * P / 4);
	const v4 = api.periodVelocity({ t: t4, rotor_speed: t4.map(() => -w), feed_displacement: t4.map(x => -0.05 * x + 1e-3 * Math.cos(w * x)) });
	for (const x of v4.slice(4)) close(x, -0.05, 1e-12);
});

test('the fitted response: v0, then K d (1 - exp(-(t - t1 - L) / T)) after each step', () => {
	const m = { v0: 0.08, gain: -0.003, timeConstant: 0.1, deadTime: 0.2 };
	const steps = [{ t: 1, d: 4 }, { t: 2, d: -4 }];
	assert.equal(api.fopdtAt(m, steps, 1.2), 0.08);
	close(api.fopdtAt(m, steps, 1.3), 0.08 - 0.012 * (1 - Math.exp(-1)));
	close(api.fopdtAt(m, steps, 2.2), 0.08 - 0.012 * (1 - Math.exp(-10)));
	close(api.fopdtAt(m, steps, 2.3), 0.08 - 0.012 * (1 - Math.exp(-11)) + 0.012 * (1 - Math.exp(-1)));
});

test('a value ± its standard error: the error at two significant digits, the value to its decimal place', () => {
	assert.equal(fmtPm(-0.003845360819728769, 0.00019952184966408323), '-0.00385 ± 0.00020');
	assert.equal(fmtPm(0.024488592355515867, 0.015357795310252942), '0.024 ± 0.015');
	assert.equal(fmtPm(0.1095733700285293, 0.009037791275209511, 's'), '0.1096 ± 0.0090 s');
	assert.equal(fmtPm(123.4, 5.6), '123.4 ± 5.6');
	assert.equal(fmtPm(1234.5, 56), '1235 ± 56');
	assert.equal(fmtPm(0.0123, NaN), '0.0123');
	assert.equal(fmtPm(NaN, 0.1), '–');
});
