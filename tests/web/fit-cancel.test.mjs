// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the calibration panel's Cancel (docs/getting-started.md)
// against the real daemon: a fit still running is cancelled from the page
// with a DELETE that carries the token and no body (the daemon refuses a
// DELETE with one, 400), the fit is gone (404), the panel says so and is
// ready for a new fit.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, apiGet, until } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon();
	ui = await openDashboard(d);
	page = ui.page;
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('#session-form input[name="layers"]', '2');
	await page.fill('#session-form input[name="columns"]', '5');
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

const messages = () => page.$$eval('#messages .msg-text', m => m.map(x => x.textContent));

test('Cancel stops a running fit', async () => {
	await page.fill('#fit-form input[name="t_end"]', '30');
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/fits') && r.request().method() === 'POST');
	await page.click('#fit-run');
	const fit = await (await answered).json();
	assert.ok(fit.id, JSON.stringify(fit));
	await until(() => page.isVisible('#fit-cancel'), 5000, 'Cancel offered');
	/* evaluations of 30 s each: many seconds of fit, and a shutdown that
	 * waits for those running at the cancel no longer than the after hook */
	assert.equal((await apiGet(d, `/api/v1/fits/${fit.id}`)).state, 'running');
	const sent = page.waitForRequest(r => r.method() === 'DELETE' && r.url().endsWith(`/api/v1/fits/${fit.id}`));
	const done = page.waitForResponse(r => r.request().method() === 'DELETE' && r.url().endsWith(`/api/v1/fits/${fit.id}`));
	await page.click('#fit-cancel');
	const req = await sent;
	assert.equal((await req.allHeaders()).authorization, `Bearer ${d.token}`);
	assert.equal(req.postData(), null);
	assert.equal((await done).status(), 204);
	await until(async () => (await messages()).includes(`Fit ${fit.id} cancelled`), 10000, 'the cancel message');
	await until(async () => !(await page.$eval('#fit-run', b => b.disabled)), 10000, 'Run fit enabled');
	assert.equal(await page.isVisible('#fit-cancel'), false);
	assert.ok(!(await messages()).some(m => m.startsWith('Cancel refused')), (await messages()).join('\n'));
	assert.equal((await fetch(`${d.base}/api/v1/fits/${fit.id}`, { headers: d.auth })).status, 404);
	assert.deepEqual((await apiGet(d, '/api/v1/fits')).fits, []);
	assert.deepEqual(ui.pageErrors, []);
});
