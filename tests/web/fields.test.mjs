// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of refused inputs, with the set-up of lib.mjs: a form the
// daemon refuses shows the daemon's problem (status, detail naming the
// member and its range) and outlines the input behind that member, also
// where the member's name is not the input's: sample_rate is the session
// form's Samples (rate), vary.NAME the sweep's "or vary", free[0] the
// fit's "free", schedule[i].beta and .until the experiment's beta1, beta2,
// t_switch and t_end. The page outlined none of these (it looked the
// member's last name up in the form).
import { test, before, after, beforeEach } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon();
	ui = await openDashboard(d);
	page = ui.page;
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});
beforeEach(async () => {
	await page.$$eval('#messages .msg', ms => ms.forEach(m => m.remove()));
});

/* Fill form's inputs, submit with button and wait for the refusal: the
 * error message's text and the names of the outlined inputs. */
async function refused(form, fills, button) {
	for (const [name, value] of Object.entries(fills)) await page.fill(`${form} [name="${name}"]`, value);
	await page.click(button);
	const msg = await page.waitForSelector('#messages .msg.error', { timeout: 10000 });
	return {
		text: await msg.$eval('.msg-text', e => e.textContent),
		outlined: await page.$$eval(`${form} [aria-invalid="true"]`, es => es.map(e => e.name)),
	};
}

test('the session form: a refused sample rate outlines Samples', async () => {
	const r = await refused('#session-form', { rate: '1e9' }, '#start');
	assert.equal(r.text, 'Start session refused: 422 Value out of range: sample_rate must lie in [1, 10000]');
	assert.deepEqual(r.outlined, ['rate']);
	await page.fill('#session-form [name="rate"]', '500');
	assert.deepEqual(await page.$$eval('#session-form [aria-invalid="true"]', es => es.map(e => e.name)), [],
		'typing in the field clears its outline');
});

test('the sweep: an unknown setting in "or vary" outlines it', async () => {
	const r = await refused('#sweep-form', { vary: 'bogus=1:2:1' }, '#sweep-run');
	assert.equal(r.text, 'Sweep refused: 422 Unknown field: vary.bogus: unknown setting "bogus"; ' +
		'GET /api/v1/presets lists the settings');
	assert.deepEqual(r.outlined, ['vary']);
	await page.fill('#sweep-form [name="vary"]', '');
});

test('the experiment: β₂ out of range outlines β₂, a switch after the end outlines "run to"', async () => {
	let r = await refused('#experiment-form', { beta2: '200' }, '#experiment-run');
	assert.equal(r.text, 'Experiment refused: 422 Value out of range: schedule[1].beta: beta must be a finite number in [0, 180] deg');
	assert.deepEqual(r.outlined, ['beta2']);
	await page.fill('#experiment-form [name="beta2"]', '128');
	await page.$$eval('#messages .msg', ms => ms.forEach(m => m.remove()));
	r = await refused('#experiment-form', { t_switch: '7' }, '#experiment-run');
	assert.equal(r.text, 'Experiment refused: 422 Value out of range: schedule[1].until must exceed ' +
		'the previous segment\'s end (7 s) and be at most 10000 s');
	assert.deepEqual(r.outlined, ['t_end']);
	await page.fill('#experiment-form [name="t_switch"]', '3');
});

test('the fit: an unknown free parameter outlines "free"', async () => {
	const r = await refused('#fit-form', { free: 'nosuch' }, '#fit-run');
	assert.equal(r.text, 'Fit refused: 422 Unknown field: unknown parameter \'nosuch\'; \'convsim list\' ' +
		'shows every setting (field: free[0])');
	assert.deepEqual(r.outlined, ['free']);
	assert.deepEqual(ui.pageErrors, []);
});
