// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the dashboard's closed-loop and identification panel
// (docs/control.md, docs/dashboard.md) against the real daemon: a short
// closed loop and a short identification run from the form at pace "max"
// on a small scene (ideal drive, 5 columns x 2 layers), and an "auto"
// loop with the same change of omega_ss, and what the page shows is
// checked against the API's answer: the request the form sends, the
// tables' text from the API's values (the gains after a curve change),
// the plot's series and its data table, the phone layout, no console
// errors.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync } from 'node:fs';
import path from 'node:path';
import { ROOT, startDaemon, stopDaemon, openSmallScene, apiGet, until, download } from './lib.mjs';

const OUT = path.join(ROOT, 'tests/out');

let d, ui, page;
before(async () => {
	mkdirSync(OUT, { recursive: true });
	d = await startDaemon();
	ui = await openSmallScene(d);
	page = ui.page;
	await page.fill('#session-form input[name="rate"]', '500');
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

/* The formatting the panel promises (docs/dashboard.md), written out
 * here on its own: fixed decimals, a dash for null, and a value ± its
 * standard error with the error at two significant digits. */
const DASH = '–';
const fixed = (x, n) => (x === null ? DASH : x.toFixed(n).replace(/^-(0\.?0*)$/, '$1'));
const sig = (x, n) => String(Number(x.toPrecision(n)));
function pm(v, se) {
	const n = Math.max(0, 1 - Math.floor(Math.log10(se)));
	return `${fixed(v, n)} ± ${se.toFixed(n)}`;
}

const tableText = (id = 'loop-table') => page.$$eval(`#${id} tbody tr`, rs => rs.map(r => Array.from(r.cells, c => c.textContent)));
/* a curve change's row as the panel promises it, from the API's values */
const curveRow = k => [fixed(k.t, 3), k.rotation === 'ccw' ? 'counter-clockwise' : 'clockwise', String(k.omega_ss),
	fixed(k.beta0, 1), sig(k.slope, 3), sig(k.kp, 3), sig(k.ki, 3), k.retuned ? 're-tuned' : 'kept'];
const plotData = name => page.evaluate(n => window.convsim.plots[n].plot.data.map(c => Array.from(c)), name);
const finite = a => a.filter(x => x !== null && Number.isFinite(x));

async function runFromForm(expectBody) {
	const posted = page.waitForRequest(r => r.url().endsWith('/api/v1/experiments') && r.method() === 'POST');
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/experiments') && r.request().method() === 'POST');
	await page.click('#loop-run');
	const body = (await posted).postDataJSON();
	expectBody(body);
	const id = (await (await answered).json()).id;
	await until(() => page.isVisible('#loop-downloads'), 60000, 'the experiment done on the page');
	const e = await apiGet(d, `/api/v1/experiments/${id}`);
	assert.equal(e.state, 'done', e.error);
	return e;
}

/* Open the plot's "Data table" from the keyboard: its header is the CSV
 * export's, and it has rows. */
async function dataTable(name) {
	const summary = page.locator(`#plot-${name} + .plot-export .plot-data summary`);
	await summary.focus();
	await page.keyboard.press('Enter');
	const t = await until(() => page.$eval(`#plot-${name} + .plot-export .plot-data`, el => el.open && el.querySelector('th') && {
		head: Array.from(el.querySelectorAll('th'), h => h.textContent).join(','), rows: el.querySelectorAll('tbody tr').length,
	}), 3000, `${name}'s data table`);
	const csv = await download(page, `#plot-${name} + .plot-export button[data-export="csv"]`);
	assert.equal(csv.name, `${name}.csv`);
	assert.equal(t.head, csv.text.split('\n')[0]);
	assert.ok(t.rows > 100, `${name}: ${t.rows} rows`);
	// Enter on the focused CSV button downloads it again; taken here, not
	// by the PNG's wait below (which it reached once, a late event)
	const [again] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.keyboard.press('Enter')]);
	assert.equal(again.suggestedFilename(), `${name}.csv`);
	const png = await download(page, `#plot-${name} + .plot-export button[data-export="png"]`);
	assert.equal(png.name, `${name}.png`);
	assert.ok(png.bytes.subarray(0, 8).equals(Buffer.from([0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a])), 'a PNG');
	assert.match(await page.getAttribute(`#plot-${name}`, 'aria-label'), /against time \(plot; its data: the Data table below\)$/);
}

test('a closed loop from the form: v, setpoint and beta on one axis, the per-setpoint table', { timeout: 90000 }, async () => {
	await page.selectOption('#loop-form select[name="kind"]', 'control');
	assert.equal(await page.isVisible('#loop-form input[name="points"]'), false, 'the identification fields hidden');
	await page.fill('#loop-form input[name="setpoints"]', '0.10:1.5, -0.05:3');
	await page.selectOption('#loop-form select[name="controller"]', 'pi');
	await page.fill('#loop-form input[name="kp"]', '2');
	await page.fill('#loop-form input[name="ki"]', '800');
	await page.fill('#loop-form input[name="disturbances"]', '2.2: omega_ss=150');
	const e = await runFromForm(body => {
		assert.deepEqual(body.control, { setpoint: [{ v: 0.1, until: 1.5 }, { v: -0.05, until: 3 }], controller: { kp: 2, ki: 800 } });
		assert.deepEqual(body.disturbances, [{ at: 2.2, set: { omega_ss: 150 } }]);
		assert.equal(body.keep_session, true);
		assert.equal(body.session.pace, undefined, 'pace "max", the daemon\'s default');
		assert.deepEqual(body.session.scene, { columns: 5, layers: 2, feed: true, drive: 'ideal', start: 'steady' });
	});
	assert.equal(e.kind, 'control');
	/* the table: one row a setpoint, the API's values as formatted */
	const want = e.control.setpoints.map((s, i) => [String(i + 1), String(s.v), fixed(e.segments[i].beta, 1),
		fixed(s.settling_time, 3), fixed(100 * s.overshoot, 1), sig(s.iae, 3), fixed(100 * s.steady_error, 2)]);
	assert.deepEqual(await tableText(), want);
	assert.match(await page.textContent('#loop-summary'), /kp = 2 ° per m\/s, ki = 800 ° per m, as given/);
	/* the plot: t, v, setpoint, beta (right axis) with data */
	assert.equal(await page.isVisible('#plot-loop'), true);
	assert.equal(await page.isVisible('#plot-ident'), false);
	const [t, v, sp, beta] = await plotData('loop');
	assert.ok(t.length > 250 && t[t.length - 1] >= 2.99, `${t.length} rows to t = ${t[t.length - 1]}`);
	assert.ok(finite(v).length > t.length - 10, 'v from the first period on');
	assert.deepEqual([...new Set(finite(sp))], [0.1, -0.05]);
	const { beta_min: lo, beta_max: hi } = e.control.reachable;
	assert.ok(finite(beta).slice(-100).every(b => b >= lo - 1e-9 && b <= hi + 1e-9), 'beta on the branch');
	/* v as the page derives it agrees with the daemon's steady error: the
	 * mean over each segment's last quarter, within 1.5 mm/s (the page's
	 * window slides, the daemon's steps a period at a time) */
	e.segments.forEach((s, i) => {
		const r = e.control.setpoints[i].v, from = s.t_end - (s.t_end - s.t_command) / 4;
		const w = v.filter((x, k) => t[k] >= from && t[k] <= s.t_end);
		const mean = w.reduce((a, b) => a + b, 0) / w.length;
		assert.ok(Math.abs(Math.abs(mean - r) - e.control.setpoints[i].steady_error * Math.abs(r)) < 0.0015,
			`segment ${i}: page ${mean}, setpoint ${r}, steady error ${e.control.setpoints[i].steady_error}`);
	});
	/* the disturbance as a marker where it was applied */
	const marks = await page.evaluate(() => window.convsim.plots.loop.markers.map(m => [m.x, m.label]));
	assert.equal(marks.length, 1);
	assert.equal(marks[0][0], e.control.disturbances[0].t_applied);
	assert.match(marks[0][1], /^omega_ss → 150/);
	/* the curve change it made: the given gains kept, in words under the table */
	assert.equal(e.control.curves.length, 1);
	assert.deepEqual(await tableText('loop-gains'), [curveRow(e.control.curves[0])]);
	assert.deepEqual((await tableText('loop-gains'))[0].slice(2), ['150', fixed(e.control.curves[0].beta0, 1), sig(e.control.curves[0].slope, 3), '2', '800', 'kept']);
	assert.match(await page.textContent('#loop-gains caption'), /^Gains after each curve change: from the change on, the given gains, kept\.$/);
	await dataTable('loop');
	await page.locator('#loop-card').screenshot({ path: `${OUT}/control-loop.png` });
});

test('"auto" with a curve change: the gains in use after it, re-tuned from the new curve', { timeout: 90000 }, async () => {
	await page.selectOption('#loop-form select[name="controller"]', 'auto');
	const e = await runFromForm(body => {
		assert.equal(body.control.controller, 'auto');
		assert.deepEqual(body.disturbances, [{ at: 2.2, set: { omega_ss: 150 } }]);
	});
	const c = e.control, k = c.curves[0];
	assert.equal(c.curve_changes, 1);
	assert.equal(k.retuned, true);
	assert.notEqual(sig(k.kp, 3), sig(c.controller.kp, 3), 'the new curve\'s gains differ from the request\'s');
	/* the line above keeps the request's gains; the table under it the ones in use after the change */
	assert.match(await page.textContent('#loop-summary'), new RegExp(`kp = ${sig(c.controller.kp, 3)} ° per m/s, ki = ${sig(c.controller.ki, 3)} ° per m, tuned by SIMC`));
	const rows = await tableText('loop-gains');
	assert.deepEqual(rows, [curveRow(k)]);
	assert.equal(rows[0][7], 're-tuned');
	assert.equal(await page.isVisible('#loop-gains'), true);
	assert.deepEqual(await page.$$eval('#loop-gains th', h => h.map(x => [x.textContent, x.scope])), [
		['at t / s', 'col'], ['rotation', 'col'], ['ω_ss / (rad/s)', 'col'], ['β₀ / °', 'col'], ['slope / (m/s per °)', 'col'],
		['kp / (° per m/s)', 'col'], ['ki / (° per m)', 'col'], ['gains', 'col']]);
	assert.equal(await page.getAttribute('#loop-gains', 'aria-label'), 'gains in use after each curve change');
	assert.match(await page.textContent('#loop-gains caption'), /re-tuned by SIMC from the new curve's slope at the operating point\.$/);
});

test('an identification from the form: K, T, L with their standard errors, the fit over the response', { timeout: 90000 }, async () => {
	await page.selectOption('#loop-form select[name="kind"]', 'identify');
	assert.equal(await page.isVisible('#loop-form input[name="setpoints"]'), false, 'the closed loop\'s fields hidden');
	await page.fill('#loop-form input[name="points"]', '60');
	await page.fill('#loop-form input[name="step"]', '4');
	await page.fill('#loop-form input[name="hold"]', '0.6');
	const e = await runFromForm(body => {
		assert.deepEqual(body.identify, { beta: 60, step: 4, hold: 0.6 });
		assert.equal(body.control, undefined);
	});
	assert.equal(e.kind, 'identify');
	assert.equal(await page.isVisible('#loop-gains'), false, 'no curve changes in an identification');
	const m = e.identify.models[0];
	assert.ok(m.gain_se > 0 && m.time_constant_se > 0 && m.dead_time_se > 0, JSON.stringify(m));
	const rows = await tableText();
	assert.deepEqual(rows.map(r => r.slice(0, 4)), [['60', pm(m.gain, m.gain_se), pm(m.time_constant, m.time_constant_se), pm(m.dead_time, m.dead_time_se)]]);
	assert.deepEqual(await page.$$eval('#loop-table th', h => h.map(x => x.textContent).slice(0, 4)),
		['β₀ / °', 'gain K / (m/s per °)', 'time constant T / s', 'dead time L / s']);
	assert.equal(await page.isVisible('#plot-ident'), true);
	assert.equal(await page.isVisible('#plot-loop'), false);
	const [t, measured, fitted, beta] = await plotData('ident');
	assert.ok(t.length > 250, `${t.length} rows`);
	assert.ok(finite(measured).length > t.length - 10 && finite(beta).length === t.length);
	/* the fitted response from t_from to the point's end, close to the
	 * measured one there: within a few of the fit's residuals on average */
	const k = t.map((x, i) => i).filter(i => fitted[i] !== null);
	assert.ok(Math.abs(t[k[0]] - (e.t_start + m.t_from)) < 0.011, `fitted from ${t[k[0]]}`);
	assert.ok(t[k[k.length - 1]] >= e.segments[4].t_end - 0.011);
	const mad = k.reduce((a, i) => a + Math.abs(fitted[i] - measured[i]), 0) / k.length;
	assert.ok(mad < 3 * m.rms, `mean |fitted - measured| ${mad}, the fit's rms ${m.rms}`);
	await dataTable('ident');
	await page.locator('#loop-card').screenshot({ path: `${OUT}/control-identify.png` });
});

test('a setpoint out of the machine\'s reach: the daemon\'s 422 on the page, the setpoints field marked, nothing started', async () => {
	const before = (await apiGet(d, '/api/v1/experiments')).experiments.length;
	await page.selectOption('#loop-form select[name="kind"]', 'control');
	await page.fill('#loop-form input[name="setpoints"]', '0.10:1, 0.5:2');
	await page.fill('#loop-form input[name="disturbances"]', '');
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/experiments') && r.request().method() === 'POST');
	await page.click('#loop-run');
	const res = await answered;
	assert.equal(res.status(), 422);
	const problem = await res.json();
	assert.equal(problem.field, 'control.setpoint[1].v');
	await until(async () => (await page.textContent('#messages')).includes(problem.detail), 5000, 'the detail on the page');
	assert.equal(await page.getAttribute('#loop-form input[name="setpoints"]', 'aria-invalid'), 'true');
	assert.equal(await page.getAttribute('#loop-form input[name="setpoints"]', 'title'), problem.detail);
	assert.equal((await apiGet(d, '/api/v1/experiments')).experiments.length, before);
});

test('a phone (390 px): the panel without sideways scroll; no console errors', async () => {
	await page.setViewportSize({ width: 390, height: 844 });
	await until(async () => await page.evaluate(() => document.documentElement.scrollWidth) <= 390, 5000, 'no sideways scroll');
	const wide = await page.evaluate(() => [...document.querySelectorAll('#loop-card *')]
		.filter(e => { const b = e.getBoundingClientRect(); return b.width > 0 && b.right > 391 && !e.closest('.table-scroll'); })
		.map(e => `${e.tagName}#${e.id}.${e.className}`).slice(0, 5));
	assert.deepEqual(wide, [], 'nothing of the panel reaches past the screen');
	assert.deepEqual(ui.pageErrors, []);
	/* but the refused request's, provoked above */
	assert.deepEqual(ui.consoleErrors.filter(e => !/status of 422/.test(e)), []);
	assert.equal(ui.consoleErrors.length, 1, ui.consoleErrors.join('\n'));
});
