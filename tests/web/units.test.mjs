// SPDX-License-Identifier: GPL-3.0-or-later
// Unit tests of the dashboard's pure modules (no browser, no daemon):
// the API field mapping, the sample buffers and velocity fit, number
// formatting and the schematic's geometry.
import test from 'node:test';
import assert from 'node:assert/strict';
import * as api from '../../web/js/api.js';
import { Trace, slope, recentVelocity } from '../../web/js/series.js';
import { fmt, fmtGiven, fmtVelocity, fmtVelocityPm, steadyLabel, direction, wrapBeta, parsePace, problemText, fitChi2Text, fitProgressText, tickText, priorText } from '../../web/js/format.js';
import { vibrationDirection, guideDirection, guideEnds, columnPositions, toSvg, VIEW } from '../../web/js/schematic.js';

const close = (a, b, tol = 1e-12) => assert.ok(Math.abs(a - b) <= tol, `${a} != ${b}`);

test('session document maps to the page model', () => {
	const s = api.normalizeSession({
		id: 'a7', state: 'paused', preset: 'czubak2016', pace: 'max', columns: 5, layers: 8,
		spec: { scene: { start: 'steady' } },
		status: { t: 2.5, beta: 38, beta_target: 128, rotation: 'cw', rotor_speed: 157.08,
			transport_velocity: 0.12, transport_velocity_uncertainty: 0.002, steady: true,
			rotor_speed_mean: 156.9, rtf: 4.5, steps_per_s: 2e5, reductions: ['symmetric', 'ideal_drive'] },
	});
	assert.equal(s.id, 'a7');
	assert.equal(s.t, 2.5);
	assert.equal(s.beta, 38);
	assert.equal(s.betaTarget, 128);
	assert.equal(s.rotation, 'cw');
	assert.equal(s.rotorSpeed, 157.08);
	assert.equal(s.transportVelocity, 0.12);
	assert.equal(s.transportUncertainty, 0.002);
	assert.equal(s.steady, true);
	assert.equal(s.rotorSpeedMean, 156.9);
	assert.equal(s.start, 'steady');
	assert.equal(s.running, false);
	assert.equal(s.pace, 'max');
	assert.equal(s.realTimeFactor, 4.5);
	assert.equal(s.columns, 5);
	assert.deepEqual(s.reductions.map(r => r.name), ['symmetric', 'ideal_drive']);
});

test('a fit whose record could not be written ends the wait, failed with its reason', () => {
	const f = api.normalizeFit({ id: 'f', state: 'error', error: 'cannot write fits/f.bin: No space left on device',
		phase: 'fitting', iteration: 1, max_iter: 30, result: null });
	assert.equal(f.done, true);
	assert.equal(f.failed, true);
	assert.equal(f.error, 'cannot write fits/f.bin: No space left on device');
	const running = api.normalizeFit({ id: 'f', state: 'running', iteration: 1, max_iter: 30 });
	assert.equal(running.done, false);
	assert.equal(running.error, null);
});

test('a session without status yet gives NaN, not zeros', () => {
	const s = api.normalizeSession({ id: 'b', state: 'running', status: null });
	assert.ok(Number.isNaN(s.t));
	assert.ok(Number.isNaN(s.beta));
	assert.ok(Number.isNaN(s.transportUncertainty));
	assert.equal(s.steady, undefined);
	assert.equal(s.running, true);
});

test('stream sample maps flat members to vectors; null becomes NaN', () => {
	const s = api.normalizeSample({ t: 1.25, beta: 40, x: 1e-3, y: -2e-3, alpha: 0, deck_x: 3e-3, deck_y: 4e-3,
		rotor_speed: 150, s1: 0.004, s2: null, columns: [0.1, 0.2, 0.3], feed_velocity: 0.2,
		transport_velocity_uncertainty: null, steady: false }, '17');
	assert.equal(s.index, 17);
	assert.deepEqual(s.deck, [3e-3, 4e-3]);
	assert.deepEqual(s.trough, [1e-3, -2e-3, 0]);
	assert.equal(s.strokes[0], 0.004);
	assert.ok(Number.isNaN(s.strokes[1]));
	close(s.feedMean, 0.2, 1e-15);   /* mean of the columns when feed_displacement is absent */
	assert.equal(s.feedVelocity, 0.2);
	assert.ok(Number.isNaN(s.transportUncertainty));
	assert.equal(s.steady, false);
	const bare = api.normalizeSample({ t: 0 });
	assert.deepEqual(bare.deck, []);
	assert.deepEqual(bare.columns, []);
});

test('control event and PATCH answer give beta and effective time', () => {
	const ev = api.normalizeControl({ beta: 128, t_effective: 3.1 });
	assert.equal(ev.beta, 128);
	assert.equal(ev.t, 3.1);
	const answer = api.normalizeControl({ id: 'x', status: { t: 9 }, applied: { rotation: 'ccw' }, t_effective: 3.2 });
	assert.equal(answer.rotation, 'ccw');
	assert.equal(answer.t, 3.2);
});

test('sweep points from a list, and from per-rotation columns', () => {
	const j = api.normalizeSweep({ id: 'w1', state: 'running', total: 4, done: 2, progress: 0.5, points: [
		{ beta: 30, rotation: 'cw', state: 'done', velocity: 0.1, uncertainty: 0.002, steady: true },
		{ beta: 30, rotation: 'ccw', state: 'done', velocity: -0.02 },
		{ beta: 60, rotation: 'cw', state: 'pending', velocity: null }] });
	assert.equal(j.progress, 0.5);
	assert.equal(j.done, false);
	assert.equal(j.points.length, 3);
	assert.ok(Number.isNaN(j.points[2].v));
	assert.equal(j.points[0].u, 0.002);
	assert.equal(j.points[0].steady, true);
	assert.equal(j.points[1].u, undefined);
	const k = api.sweepPoints({ cw: { beta: [0, 10], v: [0.01, 0.05] } });
	assert.deepEqual(k, [{ beta: 0, rotation: 'cw', v: 0.01 }, { beta: 10, rotation: 'cw', v: 0.05 }]);
	assert.equal(api.normalizeSweep({ state: 'done' }).done, true);
	assert.equal(api.normalizeSweep({ state: 'cancelled' }).failed, true);
});

test('a job that ended early ends the page\'s wait as a failure; one that runs does not', () => {
	// the daemon's end states (api/schemas.json): an experiment aborted
	// (its session deleted or failed), interrupted (a restart), damaged
	// (its record unreadable), a sweep damaged
	for (const state of ['aborted', 'interrupted', 'damaged', 'error']) {
		const e = api.normalizeExperiment({ id: 'e', state, error: 'the session was deleted or the daemon stopped' });
		assert.equal(e.done, true, state);
		assert.equal(e.failed, true, state);
	}
	for (const state of ['damaged', 'error', 'cancelled']) {
		assert.deepEqual([api.normalizeSweep({ state }).done, api.normalizeSweep({ state }).failed], [true, true], state);
	}
	for (const state of ['waiting', 'running', 'queued']) {
		assert.equal(api.normalizeExperiment({ state }).done, false, state);
		assert.equal(api.normalizeSweep({ state }).done, false, state);
	}
	const done = api.normalizeExperiment({ state: 'done' });
	assert.deepEqual([done.done, done.failed], [true, false]);
});

test('experiment segments carry steady velocity and reversal time', () => {
	const e = api.normalizeExperiment({ id: 'e1', session: 's9', state: 'done', progress: 1, t: 6, segments: [
		{ beta: 38, until: 3, state: 'done', t_command: 0, t_end: 3, steady_velocity: 0.15, reversal_time: null },
		{ beta: 128, until: 6, state: 'done', t_command: 3, t_end: 6, steady_velocity: -0.14, reversal_time: 0.42,
			mean_velocity: -0.11, uncertainty: 0.03, steady: false }] });
	assert.equal(e.sessionId, 's9');
	assert.equal(e.done, true);
	assert.equal(e.segments[1].v, -0.14);
	assert.equal(e.segments[1].reversalTime, 0.42);
	assert.equal(e.segments[1].tStart, 3);
	assert.ok(Number.isNaN(e.segments[0].reversalTime));
	assert.equal(e.segments[1].meanVelocity, -0.11);
	assert.equal(e.segments[1].uncertainty, 0.03);
	assert.equal(e.segments[1].steady, false);
	assert.equal(e.segments[0].steady, undefined);
});

test('request bodies follow the API request shapes', () => {
	const form = { preset: 'czubak2016', beta: 38, rotation: 'cw', columns: 5, layers: 8, feed: true,
		drive: 'ideal', method: 'rk4', dt: NaN, pace: 'max', rate: 500, betaRate: NaN };
	assert.deepEqual(api.sessionRequest(form), {
		preset: 'czubak2016', params: { beta: 38, rotation: 'cw' },
		scene: { columns: 5, layers: 8, feed: true, drive: 'ideal' },
		integrator: { method: 'rk4' }, pace: 'max', sample_rate: 500 });
	assert.deepEqual(api.sessionRequest({ ...form, start: 'rest' }).scene,
		{ columns: 5, layers: 8, feed: true, drive: 'ideal', start: 'rest' });
	assert.equal(api.experimentRequest({ ...form, start: 'rest', beta1: 38, beta2: 128, tSwitch: 3, tEnd: 6 }).session.scene.start, 'rest');
	const sw = api.sweepRequest({ ...form, from: 0, to: 180, step: 10, tEnd: 3 });
	assert.deepEqual(sw.beta, { from: 0, to: 180, step: 10 });
	assert.deepEqual(sw.rotations, ['cw', 'ccw']);
	assert.equal(sw.pace, undefined);
	const ex = api.experimentRequest({ ...form, beta1: 38, beta2: 128, tSwitch: 3, tEnd: 6 });
	assert.deepEqual(ex.schedule, [{ beta: 38, until: 3 }, { beta: 128, until: 6 }]);
	assert.equal(ex.session.params.beta, 38);
	assert.equal(ex.session.pace, undefined);
	assert.equal(ex.keep_session, true, 'the page plots the session after the end');
	assert.equal(api.streamQuery(), 'fields=trough%2Corbit%2Crotor%2Celiminators%2Cfeed');
	/* a fit's priors as the command line writes them, on the free entries they belong to */
	const fit = api.fitRequest({ ...form, free: 'e, k_c:100:1e6, R', priors: 'k_c:25600:x10, R:0.18:0.1, mu:0.3:0.05', csv: 'x' });
	assert.deepEqual(fit.free, ['e', { name: 'k_c', min: 100, max: 1e6, prior: { mean: 25600, factor: 10 } },
		{ name: 'R', prior: { mean: 0.18, sd: 0.1 } }, { name: 'mu', prior: { mean: 0.3, sd: 0.05 } }]);
	assert.deepEqual(api.fitRequest({ ...form, free: 'e', priors: ' ', csv: 'x' }).free, ['e']);
});

test('problem+json becomes an ApiError naming the field', () => {
	const e = new api.ApiError(422, { type: 'out-of-range', title: 'Value out of range', status: 422,
		detail: 'layers = 999 is out of range [1, 64]', field: 'scene.layers', min: 1, max: 64 });
	assert.equal(e.field, 'scene.layers');
	assert.equal(e.message, 'layers = 999 is out of range [1, 64]');
	const text = problemText(e);
	assert.match(text, /^422 Value out of range: layers = 999 is out of range \[1, 64\] \(field: scene\.layers\)$/);
	assert.equal(new api.ApiError(500, null).message, 'HTTP 500');
});

test('pick, num and rotation spellings', () => {
	assert.equal(api.pick({ a: { b: 2 } }, ['a.c', 'a.b']), 2);
	assert.equal(api.pick(null, ['a']), undefined);
	assert.ok(Number.isNaN(api.num(null)));
	assert.equal(api.num('1.5'), 1.5);
	/* the core's sign of phi': the paper's clockwise is +1 (docs/MODEL.md) */
	assert.equal(api.rotationName(1), 'cw');
	assert.equal(api.rotationName(-1), 'ccw');
	assert.equal(api.rotationName('ccw'), 'ccw');
	assert.equal(api.rotationName('up'), undefined);
	assert.deepEqual(api.methodEnum({ a: { properties: { method: { enum: ['rk4', 'dopri5'] } } } }), ['rk4', 'dopri5']);
});

test('window trace keeps the last span seconds and ignores repeats', () => {
	const tr = new Trace(1, { policy: 'window', span: 1, capacity: 10000 });
	for (let i = 0; i <= 300; i++) tr.push(i * 0.01, [i]);
	assert.equal(tr.push(1.0, [0]), false, 'a sample back in time is ignored');
	const [t, v] = tr.data();
	close(t[0], 2.0, 1e-9);
	close(t[t.length - 1], 3.0, 1e-9);
	assert.equal(v[v.length - 1], 300);
	assert.equal(t.length, 101);
});

test('history trace halves its resolution at capacity and keeps the start', () => {
	const tr = new Trace(1, { policy: 'history', capacity: 100 });
	for (let i = 0; i < 1000; i++) tr.push(i, [2 * i]);
	assert.ok(tr.length < 100, `length ${tr.length}`);
	assert.ok(tr.length >= 50, `length ${tr.length}`);
	assert.equal(tr.cols[0][0], 0);
	assert.ok(tr.cols[0][tr.length - 1] > 900);
	for (let i = 0; i < tr.length; i++) assert.equal(tr.cols[1][i], 2 * tr.cols[0][i]);
});

test('least-squares slope and the recent transport velocity', () => {
	close(slope([0, 1, 2, 3], [1, 3, 5, 7]), 2);
	assert.ok(Number.isNaN(slope([1], [1])));
	/* hops within each 40 ms period on top of a 0.1 m/s drift */
	const ts = [], xs = [];
	for (let i = 0; i < 2000; i++) {
		const t = i * 1e-3;
		ts.push(t);
		xs.push(0.1 * t + 2e-4 * Math.sin(2 * Math.PI * t / 0.04));
		if (t > 1) xs[i] = 0.1 * 1 - 0.05 * (t - 1) + 2e-4 * Math.sin(2 * Math.PI * t / 0.04);
	}
	close(recentVelocity(ts, xs, 0.5), -0.05, 2e-3);
	assert.ok(Number.isNaN(recentVelocity(ts.slice(0, 50), xs.slice(0, 50), 0.5, 0.2)), 'too short');
});

test('formatting: units, signs, directions', () => {
	assert.equal(fmt(-0.0001, 3), '0.000');
	assert.equal(fmt(NaN), '–');
	assert.equal(fmt(1.5, 1, 's'), '1.5 s');
	assert.equal(fmtVelocity(0.1234), '+0.123 m/s');
	assert.equal(fmtVelocity(-0.05), '-0.050 m/s');
	assert.equal(fmtVelocityPm(0.15258, 0.00191), '+0.153 ± 0.002 m/s');
	assert.equal(fmtVelocityPm(-0.147, NaN), '-0.147 m/s');
	assert.equal(steadyLabel(true), 'steady');
	assert.equal(steadyLabel(false), 'settling');
	assert.equal(steadyLabel(undefined), '');
	assert.equal(direction(0.2), 'right');
	assert.equal(direction(-0.2), 'left');
	assert.equal(direction(5e-4), 'still');
	assert.equal(direction(NaN), '');
	assert.equal(wrapBeta(200), 20);
	assert.equal(wrapBeta(-10), 170);
	assert.equal(parsePace('max'), 'max');
	assert.equal(parsePace(' 2 '), 2);
	assert.equal(parsePace('0'), undefined);
});

test('schematic geometry: n(beta) and u(beta) are orthonormal, guides at beta', () => {
	for (const b of [0, 38, 90, 128, 179]) {
		const n = vibrationDirection(b), u = guideDirection(b);
		close(n[0] * u[0] + n[1] * u[1], 0, 1e-12);
		close(Math.hypot(...n), 1);
		close(Math.hypot(...u), 1);
	}
	const [a, c] = guideEnds([0.3, 0], 38, 0.2);
	const ang = Math.atan2(c[1] - a[1], c[0] - a[0]) * 180 / Math.PI;
	close(ang, 128, 1e-9); /* the guide lies at beta + 90 degrees */
	const n = vibrationDirection(38);
	assert.ok(n[0] > 0 && n[1] > 0, 'beta = 38 deg points up and to the right');
	columnPositions(5).forEach((x, i) => close(x, [-0.8, -0.4, 0, 0.4, 0.8][i], 1e-12));
	assert.deepEqual(columnPositions(1), [0]);
	const [x, y] = toSvg(0, 1);
	assert.equal(x, VIEW.x0);
	assert.ok(y < VIEW.y0, 'model up is screen up');
});

test('the token header: set for the tab, none without a token', () => {
	assert.deepEqual(api.authHeaders(), {});
	assert.equal(api.hasToken(), false);
	api.setToken(' 0123456789abcdef0123\n');
	assert.deepEqual(api.authHeaders(), { Authorization: 'Bearer 0123456789abcdef0123' });
	assert.equal(api.hasToken(), true);
	api.setToken(null);
	assert.deepEqual(api.authHeaders(), {});
});

test('fit panel: χ² with its unit and the reduced χ², at three significant digits; progress without "done · done"', () => {
	assert.equal(fitChi2Text({ chi2: 1.9e-4, dof: 4, chi2_unit: '(m/s)^2' }),
		'χ² = 1.90e-4 (m/s)² with 4 degrees of freedom; reduced χ²/dof = 4.75e-5 (m/s)²');
	assert.equal(fitChi2Text({ chi2: 3.9, dof: 1, chi2_unit: 'deg^2' }),
		'χ² = 3.9 deg² with 1 degrees of freedom; reduced χ²/dof = 3.9 deg²');
	assert.equal(fitChi2Text({ chi2: 2.5, dof: 3, chi2_unit: '' }),
		'χ² = 2.5 with 3 degrees of freedom; reduced χ²/dof = 0.833');
	assert.equal(fitChi2Text({ chi2: 0, dof: 0, chi2_unit: '' }), 'χ² = 0 with 0 degrees of freedom');
	assert.equal(fitChi2Text({ chi2: 2.5, dof: 3, chi2_unit: '', chi2_prior: 0.41234 }),
		"χ² = 2.5 with 3 degrees of freedom; reduced χ²/dof = 0.833; the priors' share 0.412");
	assert.equal(priorText({ mean: 0.02, sd: 0.002 }), '0.02 ± 0.002');
	assert.equal(priorText({ mean: 25600, factor: 10 }), '25600 ×÷ 10');
	assert.equal(priorText(null), '');
	assert.equal(fitProgressText({ state: 'done', phase: 'done', iteration: 3, evaluations: 40, values: { e: 0.0181234 } }),
		'done · iteration 3 · 40 evaluations · e = 0.01812');
	assert.equal(fitProgressText({ state: 'running', phase: 'covariance', iteration: 2, evaluations: 9, values: {} }),
		'running · covariance · iteration 2 · 9 evaluations');
});

test('axis ticks carry the decimals of their step', () => {
	assert.deepEqual([157.025, 157.0275, 157.03].map(v => tickText(v, 0.0025)), ['157.0250', '157.0275', '157.0300']);
	assert.deepEqual([-0.5, 0, 0.5].map(v => tickText(v, 0.5)), ['-0.5', '0.0', '0.5']);
	assert.deepEqual([0, 500, 1000].map(v => tickText(v, 500)), ['0', '500', '1000']);
	assert.equal(tickText(-1e-17, 0.1), '0.0');
	assert.deepEqual([0.1 + 0.2, 0.4].map(v => tickText(v, 0.1)), ['0.3', '0.4']);
	assert.equal(tickText(3, NaN), '3');
});

test('numbers as a person wrote them: no float noise, settings as given', () => {
	assert.equal(fmtGiven(0.022000000000000002), '0.022');
	assert.equal(fmtGiven(16.016000000000002), '16.016');
	assert.equal(fmtGiven(31.487812499999997), '31.4878125');
	assert.equal(fmtGiven(121.9), '121.9');
	assert.equal(fmtGiven(0.052, 's'), '0.052 s');
	assert.equal(fmtGiven(38), '38');
	assert.equal(fmtGiven(-1.5e-7), '-1.5e-7');
	assert.equal(fmtGiven(0.15039742644948292), '0.150397426449483');
	assert.equal(fmtGiven(NaN), '–');
});
