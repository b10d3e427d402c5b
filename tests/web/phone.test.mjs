// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the tiles on a phone (390 x 844), with the set-up of
// lib.mjs: every tile's value is shown whole, with its unit (the
// transport velocity, in half the width, read "+0.142 …"), and the page
// does not scroll sideways.
// Scene: ideal drive, 5 columns x 2 layers, pace 2, β 128° (a negative
// velocity, the longer text).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, until } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon();
	ui = await openDashboard(d, 390, 844);
	page = ui.page;
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

test('390 px: the tiles show their values whole', async () => {
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('#session-form input[name="layers"]', '2');
	await page.fill('#session-form input[name="columns"]', '5');
	await page.fill('#session-form input[name="beta"]', '128');
	await page.fill('#session-form input[name="pace"]', '2');
	await page.click('#start');
	await until(async () => /^-0\.\d{3} m\/s$/.test(await page.textContent('#v-value')), 15000, 'a negative transport velocity');
	await until(async () => /rad\/s$/.test(await page.textContent('#rotor-now')), 5000, 'the rotor speed');
	const tiles = await page.$$eval('#tiles .tile-value', es => es.map(e => ({
		text: e.textContent, cut: e.scrollWidth > e.clientWidth })));
	assert.equal(tiles.length, 4);
	for (const t of tiles) assert.equal(t.cut, false, `"${t.text}" cut short`);
	assert.equal(await page.evaluate(() => document.documentElement.scrollWidth), 390);
	assert.deepEqual(ui.pageErrors, []);
});
