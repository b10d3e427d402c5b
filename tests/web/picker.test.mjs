// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the header's session picker (issue 38) against the real
// daemon, with the set-up of lib.mjs: on a phone (390 x 844) the picker
// is wide enough for the label of the session it is on (it had shrunk to
// its arrow), and after "Run experiment" it names a session at every
// moment (it stood blank until the next refresh of the session list).
// Scene: ideal drive, 5 columns x 2 layers, pace 1 (cheap; the point is
// the header, not the physics).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, until } from './lib.mjs';

let d, ui, page;
before(async () => {
	d = await startDaemon();
	ui = await openDashboard(d, 390, 844);
	page = ui.page;
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('#session-form input[name="layers"]', '2');
	await page.fill('#session-form input[name="columns"]', '5');
	await page.fill('#session-form input[name="pace"]', '1');
	await page.click('#start');
	await until(() => page.evaluate(() => document.body.dataset.sessionId), 10000, 'a session attached');
});
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

/* What the picker shows: its value, the selected option's text, and
 * whether it names a session (a value, and a text that carries it). */
const PICKER = () => {
	const s = document.querySelector('#session-select');
	const text = s.selectedOptions[0]?.textContent ?? '';
	return { value: s.value, text, names: s.value !== '' && text.includes(s.value) };
};

/* The picker's content box, the selected label's width in the select's
 * font (canvas measureText) and its left and right edges. */
const measure = () => page.$eval('#session-select', s => {
	const cs = getComputedStyle(s);
	const ctx = document.createElement('canvas').getContext('2d');
	ctx.font = `${cs.fontStyle} ${cs.fontWeight} ${cs.fontSize} ${cs.fontFamily}`;
	const r = s.getBoundingClientRect();
	return {
		text: s.selectedOptions[0].textContent,
		textWidth: ctx.measureText(s.selectedOptions[0].textContent).width,
		inner: s.clientWidth - parseFloat(cs.paddingLeft) - parseFloat(cs.paddingRight),
		left: r.left, right: r.right,
	};
});

test('a phone (390 px) and 1440 px: the picker shows the whole label of its session, not only its arrow', async () => {
	/* the label once the first status poll has written t and the state */
	await until(async () => / · t \d/.test((await page.evaluate(PICKER)).text), 5000, 'the label from the status');
	/* the label, plus room for the arrow (chromium sizes a select to its
	 * longest option plus 20 px), inside the box; the old page gave the
	 * select at 390 px about its arrow's width, and cut the label's end
	 * at every width */
	const ARROW = 20;
	try {
		for (const width of [390, 1440]) {
			await page.setViewportSize({ width, height: 844 });
			const m = await measure();
			assert.ok(m.inner >= m.textWidth + ARROW, `${width} px: "${m.text}" is ${m.textWidth.toFixed(0)} px, ` +
				`the picker's content box ${m.inner} px (with ${ARROW} px for the arrow)`);
			assert.ok(m.left >= 0 && m.right <= width, `${width} px: the picker on screen: ${m.left}…${m.right}`);
		}
	} finally {
		await page.setViewportSize({ width: 390, height: 844 });
	}
});

test('after "Run experiment" the picker names a session at every moment for 3 s', async () => {
	const before = await page.evaluate(PICKER);
	assert.ok(before.names, `the picker before the run: ${JSON.stringify(before)}`);
	await page.fill('#experiment-form input[name="beta1"]', '38');
	await page.fill('#experiment-form input[name="beta2"]', '128');
	await page.fill('#experiment-form input[name="t_switch"]', '0.5');
	await page.fill('#experiment-form input[name="t_end"]', '1');
	await page.check('#experiment-form input[name="watch"]');
	const answered = page.waitForResponse(r => r.url().endsWith('/api/v1/experiments') && r.request().method() === 'POST');
	/* in the page, every 100 ms for 3 s from the click on */
	await page.evaluate(`window.pickerNow = ${PICKER}`);
	await page.evaluate(() => {
		window.pickerSamples = [];
		const t0 = performance.now();
		const timer = setInterval(() => {
			window.pickerSamples.push({ ms: Math.round(performance.now() - t0), ...window.pickerNow() });
			if (performance.now() - t0 >= 3000) clearInterval(timer);
		}, 100);
	});
	await page.click('#experiment-run');
	const sessionId = (await (await answered).json()).session;
	assert.ok(sessionId, 'the experiment keeps its session');
	const samples = await until(() => page.evaluate(() => {
		const s = window.pickerSamples;
		return s.length && s[s.length - 1].ms >= 3000 ? s : null;
	}), 6000, '3 s of samples');
	assert.ok(samples.length >= 25, `${samples.length} samples`);
	const blank = samples.filter(s => !s.names);
	assert.deepEqual(blank.slice(0, 3), [], `${blank.length} of ${samples.length} samples without a session`);
	assert.deepEqual([...new Set(samples.map(s => s.value))].filter(v => v !== before.value && v !== sessionId), [],
		'only the session before and the experiment\'s');
	assert.equal(samples[samples.length - 1].value, sessionId, 'the picker on the experiment\'s session');
	assert.deepEqual(ui.pageErrors, []);
});
