// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of a daemon restart under an open dashboard, with the
// set-up of lib.mjs and a --data-dir, so that the daemon restores its
// sessions when it starts again: the badge turns red while it is down,
// and once it is back (same port, same token) the page is attached to
// the same session and its live plots go on from the daemon's stream.
// The page used to close the stream for good at the daemon's "end"
// record (reason "shutdown"): the tiles followed the polled status, the
// plots and the big transport velocity stood still at the stop.
// Scene: ideal drive, 5 columns x 2 layers, pace 2 (cheap; the point is
// the page, not the physics).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { startDaemon, stopDaemon, openDashboard, apiGet, until } from './lib.mjs';

const DATA = mkdtempSync(path.join(tmpdir(), 'convsim-web-data-'));
let d, ui, page;
before(async () => {
	d = await startDaemon({ args: ['--data-dir', DATA] });
	ui = await openDashboard(d);
	page = ui.page;
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

const attr = (sel, name) => page.$eval(sel, (e, n) => e.dataset[n], name);
const samples = async () => Number(await attr('#live-state', 'samples'));
const rotorEnd = async () => Number(await attr('#plot-rotor', 'tEnd'));

test('the daemon stops and starts again: the page says so, and its live plots go on', async () => {
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('#session-form input[name="layers"]', '2');
	await page.fill('#session-form input[name="columns"]', '5');
	await page.fill('#session-form input[name="pace"]', '2');
	await page.click('#start');
	const id = await until(() => page.evaluate(() => document.body.dataset.sessionId), 10000, 'a session attached');
	await until(async () => await rotorEnd() > 1, 15000, 'a second of rotor speed drawn');

	const { port } = new URL(d.base);
	assert.equal(await stopDaemon(d.proc), 0);
	await page.waitForSelector('#conn[data-state="offline"]', { timeout: 10000 });
	assert.equal(await page.textContent('#conn'), 'daemon: unreachable');
	const down = { n: await samples(), t: await rotorEnd() };

	d = await startDaemon({ port: Number(port), token: d.token, args: ['--data-dir', DATA] });
	await page.waitForSelector('#conn[data-state="online"]', { timeout: 15000 });
	assert.equal(await page.textContent('#conn'), 'daemon: connected');
	assert.equal(await page.$eval('#messages', m => m.textContent.includes('does not answer')), false,
		'the "does not answer" message goes once the daemon answers');
	/* the restored session runs on: one simulated second more on the plots,
	 * and the stream's count goes on with them (how many come in that
	 * second depends on the load: a page that reads too slowly misses
	 * the records the ring overwrote, docs/api-streams.md) */
	const s = await apiGet(d, `/api/v1/sessions/${id}`);
	assert.equal(s.state, 'running');
	await until(async () => await rotorEnd() > down.t + 1, 15000,
		`the rotor plot past t = ${down.t + 1} s (it stood at ${down.t} s when the daemon stopped)`);
	assert.ok(await samples() > down.n, `samples ${await samples()} after ${down.n} at the stop`);
	assert.equal(await page.evaluate(() => document.body.dataset.sessionId), id);
	assert.match(await page.textContent('#live-state'), /^stream: \d+ samples$/);
	assert.deepEqual(ui.pageErrors, []);
});
