// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of values the page sends as typed, with the set-up of
// lib.mjs: Δt 0 or -1, Samples 0 or -5 and a negative slew go to the
// daemon, which refuses the bad ones naming the member (the message and
// the outlined input) and changes nothing; an empty Δt or Samples still
// asks for the default. The page dropped them (the session started with
// the default; β jumped instead of ramping). A refused β (181, -5) puts
// the slider and the number field back on the session's β target: the
// slider stood at 180 or 0 until the field lost focus. An empty Columns
// field reads "must be a number" (it read "must be a number ()").
// Scene: ideal drive, 5 columns x 2 layers, no feed, pace 1 (cheap).
import { test, before, after, beforeEach } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, apiGet, until } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon();
	ui = await openDashboard(d);
	page = ui.page;
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('#session-form input[name="layers"]', '2');
	await page.uncheck('#session-form input[name="feed"]');
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});
beforeEach(async () => {
	await page.$$eval('#messages .msg', ms => ms.forEach(m => m.remove()));
});

const outlined = sel => page.$$eval(`${sel} [aria-invalid="true"]`, es => es.map(e => e.name || `#${e.id}`));
const sessionIds = async () => (await apiGet(d, '/api/v1/sessions')).sessions.map(s => s.id).sort();

/* Fill the session form, start, and return the POST body the page sent
 * and the refusal's text (null when it was accepted). */
async function start(fills) {
	for (const [name, value] of Object.entries(fills)) await page.fill(`#session-form [name="${name}"]`, value);
	const [req] = await Promise.all([
		page.waitForRequest(r => r.method() === 'POST' && r.url().endsWith('/api/v1/sessions'), { timeout: 10000 }),
		page.click('#start'),
	]);
	const res = await req.response();
	const body = JSON.parse(req.postData());
	if (res.status() < 400) return { body, refused: null, id: (await res.json()).id };
	const msg = await page.waitForSelector('#messages .msg.error', { timeout: 10000 });
	return { body, refused: await msg.$eval('.msg-text', e => e.textContent) };
}

test('the session form sends Δt and Samples as typed; the daemon refuses the bad ones', async () => {
	const before = await sessionIds();
	let r = await start({ dt: '-1' });
	assert.equal(r.body.integrator.dt, -1);
	assert.equal(r.refused, 'Start session refused: 422 Value out of range: dt must be a finite number in [0, 0.01] s (field: integrator.dt)');
	assert.deepEqual(await outlined('#session-form'), ['dt']);
	await page.fill('#session-form [name="dt"]', '');
	for (const rate of ['0', '-5']) {
		await page.$$eval('#messages .msg', ms => ms.forEach(m => m.remove()));
		r = await start({ rate });
		assert.equal(r.body.sample_rate, Number(rate));
		assert.equal(r.body.integrator.dt, undefined, 'an empty Δt asks for the default');
		assert.equal(r.refused, 'Start session refused: 422 Value out of range: sample_rate must lie in [1, 10000]');
		assert.deepEqual(await outlined('#session-form'), ['rate']);
	}
	assert.deepEqual(await sessionIds(), before, 'a refusal creates nothing');

	/* Δt 0 is the method's default step (the field's placeholder says so) */
	assert.equal(await page.getAttribute('#session-form [name="dt"]', 'placeholder'), 'default (0)');
	r = await start({ dt: '0', rate: '' });
	assert.equal(r.refused, null);
	assert.equal(r.body.integrator.dt, 0);
	assert.equal(r.body.sample_rate, undefined, 'an empty Samples asks for the default');
	const s = await apiGet(d, `/api/v1/sessions/${r.id}`);
	assert.equal(s.spec.integrator.dt, 0);
	assert.equal(s.sample_rate, 250);
	await until(async () => await page.evaluate(() => document.body.dataset.sessionId) === r.id, 10000, 'the session attached');
	await page.fill('#session-form [name="dt"]', '');
	await page.fill('#session-form [name="rate"]', '500');
});

/* The attached session (the test before's), else a new one from the form. */
async function attached() {
	let id = await page.evaluate(() => document.body.dataset.sessionId);
	if (id) return id;
	id = (await start({})).id;
	await until(async () => await page.evaluate(() => document.body.dataset.sessionId) === id, 10000, 'the session attached');
	await until(async () => await page.textContent('#state-now') === 'running', 10000, 'the session running');
	return id;
}

test('a negative slew is sent and refused: β stays where it was', async () => {
	const id = await attached();
	await page.fill('#beta-rate', '-1');
	await page.fill('#beta-number', '50');
	await page.press('#beta-number', 'Enter');
	const msg = await page.waitForSelector('#messages .msg.error', { timeout: 10000 });
	assert.equal(await msg.$eval('.msg-text', e => e.textContent),
		'β change refused: 422 Value out of range: beta_rate must be a finite number in [0.1, 3600] deg/s');
	assert.deepEqual(await outlined('#control-card'), ['#beta-rate']);
	const s = await apiGet(d, `/api/v1/sessions/${id}`);
	assert.equal(s.status.beta_target, 38);
	assert.equal(s.status.beta, 38);
	await page.fill('#beta-rate', '');
});

test('a refused β puts the slider and the number field back on the target', async () => {
	await attached();
	for (const typed of ['181', '-5']) {
		await page.$$eval('#messages .msg', ms => ms.forEach(m => m.remove()));
		await page.fill('#beta-number', typed);
		await page.press('#beta-number', 'Enter');
		const msg = await page.waitForSelector('#messages .msg.error', { timeout: 10000 });
		assert.equal(await msg.$eval('.msg-text', e => e.textContent),
			'β change refused: 422 Value out of range: beta must be a finite number in [0, 180] deg');
		/* the number field keeps the focus: no poll would have written it */
		assert.equal(await page.evaluate(() => document.activeElement.id), 'beta-number');
		assert.equal(await page.inputValue('#beta-slider'), '38', `slider after β ${typed}`);
		assert.equal(await page.inputValue('#beta-number'), '38', `number field after β ${typed}`);
		assert.equal(await page.textContent('#beta-target'), '38.0 °');
	}
});

test('an empty Columns field: the daemon\'s message has no empty brackets', async () => {
	await page.fill('#session-form [name="columns"]', '');
	const r = await start({});
	assert.equal(r.body.scene.columns, null);
	assert.equal(r.refused, 'Start session refused: 400 Wrong type: scene.columns must be a number');
	assert.deepEqual(await outlined('#session-form'), ['columns']);
	await page.fill('#session-form [name="columns"]', '5');
	assert.deepEqual(ui.pageErrors, []);
});
