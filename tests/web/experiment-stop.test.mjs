// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the experiment panels' Stop button (docs/getting-started.md)
// against the real daemon: a β-change experiment, a closed loop and an
// identification long enough to be still running are stopped from the page
// (DELETE /api/v1/experiments/ID?only=running with the token), and what the page says
// is checked against the API: the experiment is gone (404), its fresh
// session removed, or kept and running when the plots follow it; the
// polling ends and the panel is ready for a new run. Idle, every panel's
// Stop (the fit's too) is shown and disabled. An experiment that ended
// disables Stop and keeps its result; so does a Stop pressed after the
// experiment ended but before the page's poll saw it (its DELETE only
// while running, which the daemon refuses, 409: one message that it had
// finished); a Stop refused (the experiment deleted
// meanwhile) is shown as a message, never thrown.
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

/* An experiment's or a session's GET status, with the token. */
const status = async p => (await fetch(d.base + p, { headers: d.auth })).status;
const sessionIds = async () => (await apiGet(d, '/api/v1/sessions')).sessions.map(s => s.id);
const disabled = sel => page.$eval(sel, b => b.disabled);
const messages = () => page.$$eval('#messages .msg-text', m => m.map(x => x.textContent));
/* A Stop button's look: shown, disabled, its label. */
const look = sel => page.$eval(sel, b => ({ shown: b.checkVisibility(), disabled: b.disabled, label: b.textContent.trim() }));
const IDLE = { shown: true, disabled: true, label: 'Stop' };

test('idle, every panel\'s Stop is shown, disabled and labelled alike', async () => {
	for (const sel of ['#fit-stop', '#experiment-stop', '#loop-stop'])
		assert.deepEqual(await look(sel), IDLE, sel);
});

/* Click the panel's run button; the experiment's {id, session} from the
 * POST's answer, once the daemon runs it and Stop is offered. */
async function start(run, stop) {
	assert.equal(await disabled(stop), true, `${stop} disabled before a run`);
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/experiments') && r.request().method() === 'POST');
	await page.click(run);
	const ex = await (await answered).json();
	assert.ok(ex.id && ex.session, JSON.stringify(ex));
	await until(async () => (await apiGet(d, `/api/v1/experiments/${ex.id}`)).state === 'running', 20000, 'the experiment running');
	await until(async () => !(await disabled(stop)), 5000, `${stop} enabled while it runs`);
	assert.equal(await disabled(run), true, `${run} disabled while it runs`);
	return ex;
}

/* Click Stop: the DELETE it sends (token, JSON type, no body), its
 * 204, then the message text; after it no more polls of the experiment. */
async function stopFromPage(stop, ex, text) {
	const sent = page.waitForRequest(r => r.method() === 'DELETE' && r.url().endsWith(`/api/v1/experiments/${ex.id}?only=running`));
	const answered = page.waitForResponse(r => r.request().method() === 'DELETE' && r.url().endsWith(`/api/v1/experiments/${ex.id}?only=running`));
	await page.click(stop);
	const req = await sent;
	const h = await req.allHeaders();
	assert.equal(h.authorization, `Bearer ${d.token}`);
	assert.equal(h['content-type'], 'application/json');
	assert.equal(req.postData(), null);
	assert.equal((await answered).status(), 204);
	await until(async () => (await messages()).includes(text), 10000, `the message "${text}"`);
	let polls = 0;
	const count = r => { if (r.method() === 'GET' && r.url().endsWith(`/api/v1/experiments/${ex.id}`)) polls++; };
	page.on('request', count);
	await new Promise(r => setTimeout(r, 1500));
	page.off('request', count);
	assert.equal(polls, 0, 'the panel polls the experiment no more');
}

/* The panel ready for a new run: Run enabled, Stop disabled, its progress
 * line saying so. */
async function ready(run, stop, box) {
	await until(async () => !(await disabled(run)), 5000, `${run} enabled`);
	assert.deepEqual(await look(stop), IDLE, `${stop} shown and disabled again`);
	assert.equal(await page.$eval(`${box} .ptext`, e => e.textContent), 'stopped');
}

test('Stop ends a running β-change experiment and removes its fresh session', async () => {
	await page.uncheck('#experiment-form input[name="watch"]');
	await page.fill('#experiment-form input[name="t_switch"]', '1');
	await page.fill('#experiment-form input[name="t_end"]', '10000');
	const ex = await start('#experiment-run', '#experiment-stop');
	assert.ok((await sessionIds()).includes(ex.session));
	await stopFromPage('#experiment-stop', ex, `Experiment ${ex.id} stopped; its session was removed.`);
	assert.equal(await status(`/api/v1/experiments/${ex.id}`), 404);
	assert.equal(await status(`/api/v1/sessions/${ex.session}`), 404);
	assert.ok(!(await sessionIds()).includes(ex.session), 'the fresh session no longer listed');
	await ready('#experiment-run', '#experiment-stop', '#experiment-progress');
	assert.equal(await page.isVisible('#experiment-downloads'), false, 'no downloads of an experiment that is gone');
});

test('Stop of a watched β-change experiment leaves its session running, the plots on it', async () => {
	await page.check('#experiment-form input[name="watch"]');
	const ex = await start('#experiment-run', '#experiment-stop');
	await until(async () => await page.$eval('body', b => b.dataset.sessionId) === ex.session, 5000, 'the plots on its session');
	await stopFromPage('#experiment-stop', ex, `Experiment ${ex.id} stopped; session ${ex.session} keeps running.`);
	assert.equal(await status(`/api/v1/experiments/${ex.id}`), 404);
	const s = await apiGet(d, `/api/v1/sessions/${ex.session}`);
	assert.equal(s.experiment, null);
	assert.equal(s.state, 'running');
	assert.equal(await page.$eval('body', b => b.dataset.sessionId), ex.session, 'the plots still follow it');
	await ready('#experiment-run', '#experiment-stop', '#experiment-progress');
	/* its controls are the user's again: the live card deletes it */
	await page.click('#delete');
	await until(async () => !(await sessionIds()).includes(ex.session), 10000, 'the session deleted from the live card');
	await page.uncheck('#experiment-form input[name="watch"]');
});

for (const kind of ['control', 'identify']) {
	test(`Stop ends a running ${kind === 'control' ? 'closed loop' : 'identification'} and removes its fresh session`, async () => {
		await page.selectOption('#loop-form select[name="kind"]', kind);
		if (kind === 'control') await page.fill('#loop-form input[name="setpoints"]', '0.10:10000');
		else await page.fill('#loop-form input[name="hold"]', '600');
		const ex = await start('#loop-run', '#loop-stop');
		await stopFromPage('#loop-stop', ex, `Experiment ${ex.id} stopped; its session was removed.`);
		assert.equal(await status(`/api/v1/experiments/${ex.id}`), 404);
		assert.ok(!(await sessionIds()).includes(ex.session), 'the fresh session no longer listed');
		await ready('#loop-run', '#loop-stop', '#loop-progress');
		assert.equal(await page.isVisible('#loop-downloads'), false);
	});
}

test('an experiment that ended disables Stop and keeps its result', async () => {
	await page.fill('#experiment-form input[name="t_switch"]', '0.3');
	await page.fill('#experiment-form input[name="t_end"]', '0.6');
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/experiments') && r.request().method() === 'POST');
	await page.click('#experiment-run');
	const ex = await (await answered).json();
	await until(async () => (await messages()).includes(`Experiment ${ex.id} finished.`), 30000, 'the experiment finished');
	await until(async () => !(await disabled('#experiment-run')), 5000, 'Run enabled');
	assert.equal(await disabled('#experiment-stop'), true, 'Stop disabled once it ended');
	assert.equal((await apiGet(d, `/api/v1/experiments/${ex.id}`)).state, 'done');
	assert.ok((await sessionIds()).includes(ex.session), 'its kept session stays');
	await fetch(`${d.base}/api/v1/sessions/${ex.session}`, { method: 'DELETE', headers: { ...d.auth, 'Content-Type': 'application/json' } });
});

test('Stop pressed after the experiment ended, before the page saw it, keeps it and says it had finished', async () => {
	await page.uncheck('#experiment-form input[name="watch"]');
	await page.fill('#experiment-form input[name="t_switch"]', '0.3');
	await page.fill('#experiment-form input[name="t_end"]', '0.6');
	/* the page's polls of the experiment wait here until Stop is pressed:
	 * the experiment ends (pace max) while the page still thinks it runs */
	const one = /\/api\/v1\/experiments\/[^/?]+$/;
	let hold = true;
	const held = [], deletes = [];
	await page.route(one, route => {
		if (hold && route.request().method() === 'GET') held.push(route);
		else route.continue();
	});
	const seeDelete = r => { if (r.method() === 'DELETE' && /\/api\/v1\/experiments\/[^/?]+(\?|$)/.test(r.url())) deletes.push(r.url()); };
	page.on('request', seeDelete);
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/experiments') && r.request().method() === 'POST');
	await page.click('#experiment-run');
	const ex = await (await answered).json();
	await until(async () => (await apiGet(d, `/api/v1/experiments/${ex.id}`)).state === 'done', 30000, 'the daemon saying it is done');
	assert.equal(await disabled('#experiment-stop'), false, 'Stop still offered: the page has not seen the end');
	await page.click('#experiment-stop');
	hold = false;
	for (const route of held.splice(0)) await route.continue();
	await until(async () => !(await disabled('#experiment-run')), 10000, 'Run enabled');
	await new Promise(r => setTimeout(r, 1000));
	page.off('request', seeDelete);
	await page.unroute(one);
	/* the page did not know it had ended: its one DELETE asked to stop it
	 * only while it runs, and the daemon kept it */
	assert.deepEqual(deletes, [`${d.base}/api/v1/experiments/${ex.id}?only=running`], 'one DELETE, only while running');
	assert.equal(await status(`/api/v1/experiments/${ex.id}`), 200, 'the experiment still there');
	const text = `Experiment ${ex.id} had already finished; nothing was stopped.`;
	const said = (await messages()).filter(m => m.includes(`Experiment ${ex.id} `));
	assert.deepEqual(said, [text], 'one message, once, and not "stopped"');
	const kept = await apiGet(d, `/api/v1/experiments/${ex.id}`);
	assert.equal(kept.state, 'done');
	assert.equal(kept.segments?.length, 2, 'its result kept');
	assert.ok((await sessionIds()).includes(ex.session), 'its kept session stays');
	/* the panel as at a normal end: progress, result and downloads */
	assert.match(await page.$eval('#experiment-progress .ptext', e => e.textContent), /^done/);
	assert.equal(await page.isVisible('#experiment-downloads'), true);
	assert.deepEqual(await look('#experiment-stop'), IDLE);
	await fetch(`${d.base}/api/v1/sessions/${ex.session}`, { method: 'DELETE', headers: { ...d.auth, 'Content-Type': 'application/json' } });
});

test('a Stop refused (the experiment deleted meanwhile) is a message, and the panel is ready again', async () => {
	await page.fill('#experiment-form input[name="t_end"]', '10000');
	const ex = await start('#experiment-run', '#experiment-stop');
	/* another client deletes it just before the page's DELETE arrives */
	await page.route(`**/api/v1/experiments/${ex.id}*`, async route => {
		if (route.request().method() === 'DELETE')
			await fetch(`${d.base}/api/v1/experiments/${ex.id}`, { method: 'DELETE', headers: { ...d.auth, 'Content-Type': 'application/json' } });
		await route.continue();
	});
	await page.click('#experiment-stop');
	const text = `Stop refused: 404 Not found: no experiment with id "${ex.id}"`;
	await until(async () => (await messages()).includes(text), 10000, `the message "${text}"`);
	await page.unroute(`**/api/v1/experiments/${ex.id}*`);
	await ready('#experiment-run', '#experiment-stop', '#experiment-progress');
	await fetch(`${d.base}/api/v1/sessions/${ex.session}`, { method: 'DELETE', headers: { ...d.auth, 'Content-Type': 'application/json' } });
});

test('no page errors; console errors only the refused DELETEs\' 404 and 409', () => {
	assert.deepEqual(ui.pageErrors, []);
	/* the browser logs a refused request: the experiment deleted by
	 * another client (404) and the one that had ended first (409) */
	assert.deepEqual(ui.consoleErrors.filter(e => !/status of 40[49] .*\?only=running\)$/.test(e)), []);
	assert.ok(ui.consoleErrors.length <= 2, ui.consoleErrors.join('\n'));
});
