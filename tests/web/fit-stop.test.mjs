// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the calibration panel's Stop (docs/getting-started.md)
// against the real daemon: idle, Stop is shown and disabled, as the
// experiment panels' Stop is; a fit still running is stopped from the page
// with a DELETE ?only=running that carries the token and no body (the
// daemon refuses a DELETE with one, 400), the fit is gone (404), the panel says so in one
// message, once, and is ready for a new fit, Stop disabled again.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openSmallScene, apiGet, until } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon();
	ui = await openSmallScene(d);
	page = ui.page;
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

const messages = () => page.$$eval('#messages .msg-text', m => m.map(x => x.textContent));
/* The Stop button's look: shown, disabled, its label. */
const look = () => page.$eval('#fit-stop', b => ({ shown: b.checkVisibility(), disabled: b.disabled, label: b.textContent.trim() }));

test('Stop ends a running fit with one message', async () => {
	assert.deepEqual(await look(), { shown: true, disabled: true, label: 'Stop' }, 'idle: shown and disabled');
	await page.fill('#fit-form input[name="t_end"]', '30');
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/fits') && r.request().method() === 'POST');
	await page.click('#fit-run');
	const fit = await (await answered).json();
	assert.ok(fit.id, JSON.stringify(fit));
	await until(async () => !(await look()).disabled, 5000, 'Stop enabled');
	/* evaluations of 30 s each: many seconds of fit, and a shutdown that
	 * waits for those running at the stop no longer than the after hook */
	assert.equal((await apiGet(d, `/api/v1/fits/${fit.id}`)).state, 'running');
	/* only while it runs: a fit that ended first would be kept (409) */
	const sent = page.waitForRequest(r => r.method() === 'DELETE' && r.url().endsWith(`/api/v1/fits/${fit.id}?only=running`));
	const done = page.waitForResponse(r => r.request().method() === 'DELETE' && r.url().endsWith(`/api/v1/fits/${fit.id}?only=running`));
	await page.click('#fit-stop');
	const req = await sent;
	assert.equal((await req.allHeaders()).authorization, `Bearer ${d.token}`);
	assert.equal(req.postData(), null);
	assert.equal((await done).status(), 204);
	const text = `Fit ${fit.id} stopped.`;
	await until(async () => (await messages()).includes(text), 10000, 'the stop message');
	await until(async () => !(await page.$eval('#fit-run', b => b.disabled)), 10000, 'Run fit enabled');
	/* several of the page's poll intervals (0.5 s): a second word on the
	 * same stop would have come by now */
	await new Promise(r => setTimeout(r, 2000));
	assert.deepEqual((await messages()).filter(m => /\bfit\b/i.test(m)), [text], 'one message, once');
	assert.deepEqual(await look(), { shown: true, disabled: true, label: 'Stop' }, 'idle again: shown and disabled');
	assert.equal(await page.$eval('#fit-progress .ptext', e => e.textContent), 'stopped');
	assert.equal((await fetch(`${d.base}/api/v1/fits/${fit.id}`, { headers: d.auth })).status, 404);
	assert.deepEqual((await apiGet(d, '/api/v1/fits')).fits, []);
	assert.deepEqual(ui.pageErrors, []);
});
