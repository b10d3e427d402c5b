// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of a session that reaches its end time, with the set-up of
// lib.mjs: the live pace set to "max" gives the session an until 60
// simulated seconds on (docs/api.md), where it finishes. The page says
// where it ended and its resume button runs it on (PATCH {"until": null});
// it used to show "finished" with Pause and Resume both disabled, and no
// control on the page could run the session again (PATCH {"running":
// true} is a 409: "raise until to run on").
// Scene: ideal drive, 5 columns x 2 layers, pace 2 (cheap; the point is
// the page, not the physics).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, apiGet, until } from './lib.mjs';

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

const text = sel => page.textContent(sel);
const disabled = sel => page.$eval(sel, e => e.disabled);
async function setPace(value) {
	await page.fill('#pace-live', value);
	await page.press('#pace-live', 'Enter');
	await page.click('#session-label'); /* off the field, so the poll may write it */
}

test('a session finished at its until says so, and "Run on" runs it on', async () => {
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('#session-form input[name="layers"]', '2');
	await page.fill('#session-form input[name="columns"]', '5');
	await page.fill('#session-form input[name="pace"]', '2');
	await page.click('#start');
	const id = await until(() => page.evaluate(() => document.body.dataset.sessionId), 10000, 'a session attached');
	await until(async () => await text('#state-now') === 'running', 5000, 'the session running');
	assert.equal(await text('#resume'), 'Resume');
	assert.equal(await disabled('#resume'), true);

	/* flat out to the daemon's end, 60 simulated seconds on */
	await setPace('max');
	const end = (await until(async () => {
		const s = await apiGet(d, `/api/v1/sessions/${id}`);
		return s.state === 'finished' && s;
	}, 30000, 'the session finished at its until')).until;
	assert.ok(end >= 60, `until ${end}`);
	await until(async () => (await text('#state-now')).startsWith('finished'), 3000, 'the page showing it finished');
	assert.equal(await text('#state-now'), `finished at until = ${end} s`);
	assert.equal(await disabled('#pause'), true);
	assert.equal(await disabled('#resume'), false);
	assert.equal(await text('#resume'), 'Run on');

	/* back to pace 2 (the until stays), then run on: no end any more */
	await setPace('2');
	await page.click('#resume');
	await until(async () => await text('#state-now') === 'running', 5000, 'the session running again');
	const s = await apiGet(d, `/api/v1/sessions/${id}`);
	assert.equal(s.state, 'running');
	assert.equal(s.until, null);
	assert.equal(s.pace, 2);
	await until(async () => (await apiGet(d, `/api/v1/sessions/${id}`)).status.t > end + 0.5, 5000, 'simulated time past the old until');
	assert.equal(await text('#resume'), 'Resume');
	assert.equal(await disabled('#resume'), true);
	assert.equal(await disabled('#pause'), false);
	assert.equal(await page.$$eval('#messages .msg.error', m => m.length), 0);
	assert.deepEqual(ui.pageErrors, []);
});
