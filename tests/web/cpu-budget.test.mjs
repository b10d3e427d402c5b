// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of a session its CPU budget paused, with the set-up of
// lib.mjs: a pace "max" session given a small grant (PATCH {"cpu_budget":
// 0.05}) pauses with pause_reason "cpu-budget" (docs/budgets.md). The page
// says so in plain words with the CPU seconds the API gives ("paused: CPU
// budget spent (N CPU s)"; it read plain "paused"), and Resume runs it on
// (PATCH {"running": true}, which grants the daemon's --max-cpu-seconds
// anew).
// Scene: ideal drive, no feed (cheap; the point is the page).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, apiGet, until } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon({ args: ['--max-cpu-seconds', '600'] });
	ui = await openDashboard(d);
	page = ui.page;
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

const text = sel => page.textContent(sel);
async function call(method, p, body) {
	const res = await fetch(d.base + p, { method, headers: { ...d.auth, 'Content-Type': 'application/json' },
		body: JSON.stringify(body) });
	assert.equal(res.status, method === 'POST' ? 201 : 200, `${method} ${p}: ${await res.clone().text()}`);
	return res.json();
}

test('a session its CPU budget paused says so, and Resume runs it on', async () => {
	const { id } = await call('POST', '/api/v1/sessions',
		{ scene: { drive: 'ideal', feed: false }, pace: 'max', until: 1e6 });
	/* attach as a reload of #session=ID does (the token is kept for the tab) */
	await page.goto(`${d.base}/#session=${id}`);
	await page.reload();
	await page.waitForSelector('body[data-ready="true"]', { timeout: 15000 });
	await until(async () => await page.evaluate(() => document.body.dataset.sessionId) === id, 10000, 'the session attached');
	await call('PATCH', `/api/v1/sessions/${id}`, { cpu_budget: 0.05 });
	const s = await until(async () => {
		const s = await apiGet(d, `/api/v1/sessions/${id}`);
		return s.state === 'paused' && s;
	}, 20000, 'the session paused by its budget');
	assert.equal(s.pause_reason, 'cpu-budget');
	const cpu = String(Number(s.cpu_seconds.toPrecision(2)));
	await until(async () => (await text('#state-now')).startsWith('paused'), 5000, 'the page showing it paused');
	assert.equal(await text('#state-now'), `paused: CPU budget spent (${cpu} CPU s)`);
	assert.equal(await page.$eval('#resume', e => e.disabled), false);
	assert.equal(await page.$eval('#pause', e => e.disabled), true);

	await page.click('#resume');
	const r = await until(async () => {
		const r = await apiGet(d, `/api/v1/sessions/${id}`);
		return r.state === 'running' && r;
	}, 10000, 'the session running again');
	assert.equal(r.pause_reason, null);
	assert.ok(r.cpu_limit >= 600, `a new grant of --max-cpu-seconds: cpu_limit ${r.cpu_limit}`);
	await until(async () => await text('#state-now') === 'running', 5000, 'the page showing it running');
	assert.equal(await page.$eval('#resume', e => e.disabled), true);
	assert.equal(await page.$$eval('#messages .msg.error', m => m.length), 0);
	assert.deepEqual(ui.pageErrors, []);
	await call('PATCH', `/api/v1/sessions/${id}`, { running: false });
});
