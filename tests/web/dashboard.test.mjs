// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the dashboard against the real daemon: starts
// $CONVSIMD (default build/convsimd) on port 0, drives web/ in Debian's
// chromium through playwright-core and checks what a user sees against
// what the API says. Saves tests/out/dashboard.png.
//
// Scene: ideal drive, 5 columns x 2 layers, pace 2 (cheap to simulate; the
// point here is the UI, not the physics). The daemon runs with a token
// (--token-file) and the page is opened as `make run` prints it, with
// #token=... in the fragment: every request, the stream and the downloads
// below carry it.
import { test, before, after, beforeEach } from 'node:test';
import assert from 'node:assert/strict';
import { mkdirSync, readFileSync } from 'node:fs';
import path from 'node:path';
import { ROOT, startDaemon, stopDaemon, launchChromium, apiGet, until } from './lib.mjs';

const OUT = path.join(ROOT, 'tests/out');
const PACE = process.env.DASHBOARD_PACE || '2';

/* the daemon of lib.mjs's startDaemon, its base URL, token and header */
let daemon, base, TOKEN, AUTH;
let browser, page;
const pageErrors = [];
/* console errors of the whole tour (a 404 of a poll after Delete, ...):
 * the tour ends with none but those a test provokes on purpose */
const consoleErrors = [];
let currentTest = '';
beforeEach((t) => { currentTest = t.name; });

const attr = (sel, name) => page.$eval(sel, (e, n) => e.dataset[n], name);
const count = async sel => Number(await attr(sel, 'points'));
const tEnd = async sel => Number(await attr(sel, 'tEnd'));
const samples = async () => Number(await attr('#live-state', 'samples'));
const shownDirection = () => attr('#v-arrow', 'direction');
const visible = sel => page.isVisible(sel);

/* Click sel, wait for the download it starts; its name and bytes.
 * Chromium (156) silently drops a download that follows ten others within
 * about a second, so the clicks are spaced: at most 8 in any 2 s. */
const recentDownloads = [];
async function download(sel, retried = false) {
	while (recentDownloads.length >= 8) {
		const wait = recentDownloads[0] + 2000 - Date.now();
		if (wait <= 0) { recentDownloads.shift(); continue; }
		await new Promise(r => setTimeout(r, wait));
	}
	recentDownloads.push(Date.now());
	const [dl] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click(sel)]);
	const got = { name: dl.suggestedFilename(), bytes: readFileSync(await dl.path()) };
	/* headless chromium now and then hands over an empty file for one of
	 * many quick blob downloads (1 run in 3 of the whole tour); once more */
	if (got.bytes.length === 0 && !retried) return download(sel, true);
	return got;
}
/* a time's text on the nanosecond grid (at most 9 decimals, no float noise) */
const onNsGrid = c => /^\d+(\.\d{1,9})?$/.test(c);
const csvLines = d => d.bytes.toString('utf8').trim().split('\n');
const TRAJ_HEAD = 't,beta,beta_target,x,y,alpha,s1,s2,deck_x,deck_y,rotor_speed,motor_torque,power,' +
	'feed_displacement,feed_velocity,transport_velocity,transport_velocity_uncertainty,e_input,e_dissipated,e_residual';

before(async () => {
	mkdirSync(OUT, { recursive: true });
	daemon = await startDaemon();
	({ base, token: TOKEN, auth: AUTH } = daemon);
	browser = await launchChromium();
	page = await browser.newPage({ viewport: { width: 1600, height: 1300 } });
	page.on('pageerror', e => pageErrors.push(e.message));
	page.on('console', m => { if (m.type() === 'error') consoleErrors.push(`${m.text()} (${m.location().url}) in "${currentTest}"`); });
});

after(async () => {
	await browser?.close();
	await stopDaemon(daemon?.proc);
});

let sessionId;

test('the page loads from the daemon and finds it online', async () => {
	const res = await page.goto(`${base}/#token=${TOKEN}`);
	assert.equal(res.status(), 200);
	await page.waitForSelector('body[data-ready="true"]', { timeout: 15000 });
	/* the token left the address bar for this tab's sessionStorage */
	assert.ok(!page.url().includes(TOKEN), page.url());
	assert.equal(await page.evaluate(() => sessionStorage.getItem('convsim.token')), TOKEN);
	assert.match(await page.title(), /convsim/);
	await page.waitForSelector('#conn[data-state="online"]', { timeout: 10000 });
	const presets = await page.$$eval('#f-preset option', o => o.map(x => x.value));
	assert.ok(presets.includes('czubak2016'), `presets offered: ${presets}`);
	/* nothing to download yet: no links, no plot exports */
	for (const sel of ['#sweep-csv', '#session-downloads', '#experiment-downloads', '.plot-export'])
		assert.equal(await visible(sel), false, `${sel} hidden before there is anything to download`);
	assert.deepEqual(pageErrors, []);
});

test('a session starts from the form', async () => {
	await page.selectOption('select[name="drive"]', 'ideal');
	await page.fill('input[name="layers"]', '2');
	await page.fill('input[name="columns"]', '5');
	await page.fill('input[name="beta"]', '38');
	await page.selectOption('select[name="rotation"]', 'cw');
	/* start: steady (on the forced response, the default) or rest (the paper's run-up) */
	assert.deepEqual(await page.$$eval('select[name="scene_start"] option', o => o.map(x => x.value)), ['steady', 'rest']);
	assert.equal(await page.$eval('select[name="scene_start"]', e => e.value), 'steady');
	await page.selectOption('select[name="scene_start"]', 'steady');
	await page.fill('input[name="pace"]', PACE);
	await page.fill('input[name="rate"]', '500');
	await page.click('#start');
	sessionId = await until(() => page.$eval('body', b => b.dataset.sessionId), 10000, 'a session id on the page');
	const s = await apiGet(daemon, `/api/v1/sessions/${sessionId}`);
	assert.equal(s.id, sessionId);
	assert.equal(s.columns, 5);
	assert.equal(s.layers, 2);
	assert.equal(s.spec.scene.start, 'steady');
	await until(async () => !(await page.$eval('#beta-slider', e => e.disabled)), 5000, 'the β control enabled');
	/* the preset as it is, 2 layers: checked against the DEM map's 2-grain
	 * beds, one short line under the velocity, no banner */
	assert.equal(s.status.model_checked, true);
	assert.equal(s.status.feed_warning, null);
	const line = `DEM check: within ±${s.status.model_error.toFixed(3)} m/s here`;
	await until(async () => await page.$eval('#v-model', e => e.textContent) === line, 5000, 'the model check line');
	assert.equal(await page.$('#feed-warning'), null, 'no banner');
});

test('stream samples arrive and the plots grow', async () => {
	await until(async () => await samples() > 20, 20000, 'stream samples');
	const a = { n: await samples(), feed: await tEnd('#plot-feed'), rotor: await tEnd('#plot-rotor'), orbit: await count('#plot-orbit') };
	assert.ok(a.orbit > 1, `orbit points ${a.orbit}`);
	await new Promise(r => setTimeout(r, 1500));
	const b = { n: await samples(), feed: await tEnd('#plot-feed'), rotor: await tEnd('#plot-rotor') };
	assert.ok(b.n > a.n, `samples ${a.n} -> ${b.n}`);
	/* the history plots thin when full, so their point count may drop; what
	 * must grow is the simulated time they cover, with points drawn */
	assert.ok(b.rotor > a.rotor, `rotor plot reaches t = ${a.rotor} -> ${b.rotor} s`);
	assert.ok(b.feed > a.feed, `feed plot reaches t = ${a.feed} -> ${b.feed} s`);
	assert.ok(await count('#plot-rotor') > 1 && await count('#plot-feed') > 1, 'rotor and feed plots draw points');
	const t = await page.$eval('#t-now', e => e.textContent);
	assert.match(t, /^\d+\.\d{3} s$/);
});

test('every live plot exports PNG and CSV; the trajectory downloads as CSV and JSON', async () => {
	for (const name of ['orbit', 'feed', 'rotor', 'strokes', 'trough']) {
		const png = await download(`#plot-${name} + .plot-export button[data-export="png"]`);
		assert.equal(png.name, `${name}.png`);
		assert.deepEqual([...png.bytes.subarray(0, 4)], [0x89, 0x50, 0x4e, 0x47], `${name}.png is a PNG`);
		const csv = await download(`#plot-${name} + .plot-export button[data-export="csv"]`);
		assert.equal(csv.name, `${name}.csv`);
		const lines = csvLines(csv);
		assert.ok(lines.length > 5, `${name}.csv has rows`);
		const width = lines[0].split(',').length;
		assert.ok(lines.every(l => l.split(',').length === width), `${name}.csv is rectangular`);
		assert.ok(lines.slice(1).every(l => l.split(',').every(c => c === '' || Number.isFinite(Number(c))) || name === 'orbit'), `${name}.csv numbers`);
		/* times on the daemon's grid as it writes them: k·dt (0.022, not the
		 * period midpoint's 0.022000000000000002) */
		if (name !== 'orbit') {
			const noisy = lines.slice(1).map(l => l.split(',')[0]).filter(c => !onNsGrid(c));
			assert.deepEqual(noisy.slice(0, 3), [], `${name}.csv: times with at most 9 decimals`);
		}
	}
	assert.equal(csvLines(await download('#plot-rotor + .plot-export button[data-export="csv"]'))[0], 't / s,rotor speed / (rad/s),β / °');
	assert.equal(csvLines(await download('#plot-orbit + .plot-export button[data-export="csv"]'))[0],
		'series,horizontal displacement x / mm,vertical displacement y / mm');
	/* five identical columns (the symmetric machine): one line, said so */
	assert.ok(await visible('#feed-note'));
	assert.match(await page.$eval('#feed-note', e => e.textContent), /All 5 columns move identically/);
	assert.equal(csvLines(await download('#plot-feed + .plot-export button[data-export="csv"]'))[0], 't / s,columns 1–5 (identical)');
	/* the note under a plot starts below its export bar (it overlapped it) */
	const gap = await page.evaluate(() => {
		const bar = document.querySelector('#plot-feed + .plot-export').getBoundingClientRect();
		return document.querySelector('#feed-note').getBoundingClientRect().top - bar.bottom;
	});
	assert.ok(gap >= 0, `#feed-note starts ${gap} px into the export bar`);
	/* each plot's text alternative: named, and a data table reached by the keyboard */
	for (const name of ['orbit', 'feed', 'rotor', 'strokes', 'trough']) {
		assert.equal(await page.$eval(`#plot-${name}`, e => e.getAttribute('role')), 'img');
		assert.ok((await page.$eval(`#plot-${name}`, e => e.getAttribute('aria-label'))).length > 5);
		const summary = page.locator(`#plot-${name} + .plot-export .plot-data summary`);
		await summary.focus();
		assert.equal(await summary.evaluate(e => e === document.activeElement && e.tabIndex >= 0), true, `${name}: the summary takes focus`);
		await page.keyboard.press('Enter');
		/* the table is filled by the toggle event, which comes after open is set */
		const t = await until(() => page.$eval(`#plot-${name} + .plot-export .plot-data`, d => d.open && d.querySelector('th') && {
			label: d.querySelector('table').getAttribute('aria-label'),
			head: Array.from(d.querySelectorAll('th')).map(h => h.textContent).join(','),
			rows: d.querySelectorAll('tbody tr').length }), 3000, `${name}'s data table`);
		assert.match(t.label, /: data$/);
		assert.equal(t.head, csvLines(await download(`#plot-${name} + .plot-export button[data-export="csv"]`))[0]);
		assert.ok(t.rows > 5, `${name}: ${t.rows} rows`);
		await page.keyboard.press('Enter');
	}
	/* the recorded trajectory, with the CLI's columns */
	assert.ok(await visible('#session-downloads'));
	const traj = await download('#traj-csv');
	assert.equal(traj.name, `trajectory-${sessionId}.csv`);
	const tl = csvLines(traj);
	assert.equal(tl[0], `${TRAJ_HEAD},column_1,column_2,column_3,column_4,column_5`);
	assert.ok(tl.length > 10);
	const tj = JSON.parse((await download('#traj-json')).bytes.toString('utf8'));
	assert.equal(tj.fields.join(','), tl[0]);
});

test('β = 38°, clockwise: the page shows transport to the right', async () => {
	await until(async () => await shownDirection() === 'right', 30000, 'direction "right"');
	const text = await page.$eval('#v-value', e => e.textContent);
	assert.match(text, /^\+\d\.\d{3} m\/s$/);
	assert.equal(await page.$eval('#schematic', e => e.dataset.direction), 'right');
	/* the daemon's estimate with its error bar, and "steady" once it has
	 * settled (the steady start needs no transient) */
	const shown = await until(async () => {
		const d = await page.$eval('#v-daemon', e => e.textContent);
		const mark = await page.$eval('#v-steady', e => e.dataset.steady);
		return /^\+0\.\d{3} ± 0\.\d{3} m\/s$/.test(d) && mark === 'steady' ? { d, mark } : null;
	}, 30000, 'the daemon estimate ± its error bar, steady');
	assert.equal(await page.$eval('#v-steady', e => e.textContent), 'steady');
	const st = (await apiGet(daemon, `/api/v1/sessions/${sessionId}`)).status;
	/* the bar against the accuracy target, as the status says, and the
	 * steps the engine chose for the scene */
	const tol = await until(async () => await page.$eval('#v-tol', e => e.dataset.tol) || null, 10000, 'the tol mark');
	const now = (await apiGet(daemon, `/api/v1/sessions/${sessionId}`)).status;
	assert.ok(tol === 'within' || tol === 'beyond', `tol mark ${tol}`);
	assert.equal(typeof now.tol_met, 'boolean');
	assert.equal(now.tol, 0.01);
	assert.equal(await page.$eval('#v-tol', e => e.textContent), `${tol} 1.0 %`);
	assert.match(await page.$eval('#m-method', e => e.textContent), /^dem · step 1\.25 ms, 5 feed sub-steps$/);
	assert.equal(typeof st.transport_velocity_uncertainty, 'number');
	const [v, u] = shown.d.split(' ± ').map(Number.parseFloat);
	assert.ok(Math.abs(v - st.transport_velocity) < 0.01 && u > 0, `shown ${shown.d}, API ${st.transport_velocity}`);
});

test('the session picker says what the tiles say: the same time and the state', async () => {
	await until(async () => {
		const { tile, label } = await page.evaluate(() => ({
			tile: document.querySelector('#t-now').textContent,
			label: document.querySelector('#session-select').selectedOptions[0].textContent,
		}));
		const t = Number.parseFloat(tile);
		const m = / · t (\d+\.\d) s · (\w+)$/.exec(label);
		return m && Number(m[1]) === Math.round(t * 10) / 10 && m[2] === 'running';
	}, 5000, 'the picker with the tile\'s time and "running"');
});

test('identical strokes: one line, said so, as for the feed\'s columns', async () => {
	await until(() => visible('#strokes-note'), 5000, 'the strokes note');
	assert.match(await page.$eval('#strokes-note', e => e.textContent), /Both eliminators move identically/);
	assert.equal(csvLines(await download('#plot-strokes + .plot-export button[data-export="csv"]'))[0],
		't / s,s₁ = s₂ / mm (identical)');
});

test('moving the β slider turns the session to 128° and reverses the shown direction', async () => {
	await page.locator('#beta-slider').fill('128');
	/* one β per moment: the readout and the drawing from the same sample
	 * during the ramp (the readout followed the polled status, the drawing
	 * the stream: 93.6° beside 97.6°) */
	const pairs = [];
	for (let k = 0; k < 25; k++) {
		pairs.push(await page.evaluate(() => [document.querySelector('#beta-now').textContent,
			document.querySelector('#schematic .sch-beta').textContent]));
		await page.waitForTimeout(40);
	}
	const differ = pairs.filter(([now, drawn]) => now.replace(' °', '') !== (drawn.match(/^β = (-?[\d.]+)°/) || [])[1]);
	assert.deepEqual(differ, [], 'β now and the drawing\'s β');
	assert.ok(new Set(pairs.map(p => p[0])).size > 1, `β moved while sampled: ${pairs.map(p => p[0])}`);
	const s = await until(async () => {
		const j = await apiGet(daemon, `/api/v1/sessions/${sessionId}`);
		return j.status && Math.abs(j.status.beta_target - 128) < 1e-9 ? j : null;
	}, 5000, 'beta_target = 128 in the API');
	assert.ok(s.status.beta_target === 128);
	await until(async () => {
		const j = await apiGet(daemon, `/api/v1/sessions/${sessionId}`);
		return Math.abs(j.status.beta - 128) < 1e-6;
	}, 30000, 'beta to reach 128 in the API');
	assert.equal(await page.$eval('#beta-number', e => e.value), '128');
	await until(async () => await shownDirection() === 'left', 30000, 'direction "left"');
	assert.match(await page.$eval('#v-value', e => e.textContent), /^-\d\.\d{3} m\/s$/);
	await until(async () => await page.$eval('#beta-now', e => e.textContent) === '128.0 °', 5000, 'β now 128.0 ° on the page');
	await until(async () => await page.$eval('#schematic', e => e.dataset.beta) === '128.00', 5000, 'the schematic at 128°');
});

test('the drive row changes omega_ss and switches the drive, checked through the API', async () => {
	await page.locator('#omega-ss').fill('150');
	await page.locator('#omega-ss').press('Enter');
	await until(async () => (await apiGet(daemon, `/api/v1/sessions/${sessionId}`)).status.omega_ss === 150,
		5000, 'omega_ss = 150 in the API');
	await page.locator('#motor').click();
	await until(async () => (await apiGet(daemon, `/api/v1/sessions/${sessionId}`)).status.drive_on === false,
		5000, 'drive_on = false in the API');
	await until(async () => await page.$eval('#drive-now', e => e.textContent) === 'off', 5000, 'drive shown off');
	assert.equal(await page.$eval('#motor', e => e.textContent), 'Switch on');
	await page.locator('#motor').click();
	await until(async () => (await apiGet(daemon, `/api/v1/sessions/${sessionId}`)).status.drive_on === true,
		5000, 'drive_on = true again');
	await page.locator('#pace-live').fill('abc');
	await page.locator('#pace-live').press('Enter');
	const refused = await page.waitForSelector('#messages .msg.error', { timeout: 5000 });
	assert.match(await refused.textContent(), /400.*pace must be a number or "max"/);
	await page.click('#messages .msg.error .msg-close');
	assert.equal(await page.$$eval('#messages .msg.error', l => l.length), 0);
});

test('a refused input shows the daemon\'s problem detail', async () => {
	const body = { preset: 'czubak2016', params: { beta: 38, rotation: 'cw' },
		scene: { columns: 5, layers: 999, feed: true, drive: 'ideal' }, integrator: { method: 'rk4' }, pace: 1 };
	const res = await fetch(base + '/api/v1/sessions', { method: 'POST', headers: { 'Content-Type': 'application/json', ...AUTH }, body: JSON.stringify(body) });
	assert.equal(res.status, 422);
	assert.match(res.headers.get('content-type'), /application\/problem\+json/);
	const problem = await res.json();
	await page.fill('input[name="layers"]', '999');
	await page.fill('input[name="pace"]', '1');
	await page.click('#start');
	const msg = await page.waitForSelector('#messages .msg.error', { timeout: 5000 });
	const text = await msg.textContent();
	assert.ok(text.includes(problem.detail), `message "${text}" lacks the detail "${problem.detail}"`);
	assert.match(text, /422/);
	assert.equal(await page.$eval('input[name="layers"]', e => e.getAttribute('aria-invalid')), 'true');
	/* the message covers nothing, wherever the page is scrolled */
	for (const y of [0, 400, 900]) {
		const covered = await page.evaluate(y => {
			window.scrollTo(0, y);
			const box = document.querySelector('#messages').getBoundingClientRect();
			const hit = r => r.width > 0 && r.height > 0 && r.left < box.right && r.right > box.left &&
				r.top < box.bottom && r.bottom > box.top;
			return Array.from(document.querySelectorAll('input, select, button, textarea, td, th, .plot, h2, h3'))
				.filter(e => !e.closest('#messages') && hit(e.getBoundingClientRect()))
				.map(e => e.id || e.name || e.tagName);
		}, y);
		assert.deepEqual(covered, [], `scrolled to ${y}: the message covers ${covered}`);
	}
	await page.evaluate(() => window.scrollTo(0, 0));
	/* nothing else was created, and the page still follows the same session */
	const list = await apiGet(daemon, '/api/v1/sessions');
	assert.equal(list.sessions.length, 1);
	assert.equal(await page.$eval('body', b => b.dataset.sessionId), sessionId);
	await page.fill('input[name="layers"]', '2');
});

test('a sweep draws v(β) for both rotations', async () => {
	assert.equal(await visible('#sweep-csv'), false, 'no sweep CSV link before a sweep');
	/* an empty plot lists no series (it drew 4 and 8 entries) and spans β 0…180 (was −1…1) */
	for (const name of ['sweep', 'fit']) {
		const shown = await page.$$eval(`#plot-${name} .u-legend .u-series`, rows => rows
			.filter(r => getComputedStyle(r).display !== 'none').map(r => r.textContent));
		assert.deepEqual(shown, [], `${name}: legend of an empty plot`);
		assert.deepEqual(await page.evaluate(n => { const x = window.convsim.plots[n].plot.scales.x; return [x.min, x.max]; }, name), [0, 180]);
	}
	await page.fill('#sweep-form input[name="from"]', '30');
	await page.fill('#sweep-form input[name="to"]', '130');
	await page.fill('#sweep-form input[name="step"]', '50');
	await page.fill('#sweep-form input[name="t_end"]', '3'); /* past the preset's transient (0 s) */
	await page.click('#sweep-run');
	await until(async () => await count('#plot-sweep') >= 6, 60000, 'six sweep points');
	/* columns: beta, then v, u and steady/settling for each rotation */
	const rows = await page.$$eval('#sweep-table tbody tr', r => r.map(x => Array.from(x.cells, c => c.textContent)));
	assert.deepEqual(rows.map(r => r[0]), ['30.0', '80.0', '130.0']);
	const v = rows.map(r => [Number(r[1]), Number(r[4])]);
	assert.ok(v.flat().every(Number.isFinite), `sweep table ${JSON.stringify(rows)}`);
	const u = rows.map(r => [Number(r[2]), Number(r[5])]);
	assert.ok(u.flat().every(x => x > 0), `sweep table ${JSON.stringify(rows)}`);
	assert.ok(rows.every(r => ['steady', 'settling'].includes(r[3]) && ['steady', 'settling'].includes(r[6])),
		`sweep table ${JSON.stringify(rows)}`);
	/* the CSV link serves the same six points */
	const href = await page.$eval('#sweep-csv', a => a.hidden ? null : a.getAttribute('href'));
	assert.match(href, /^\/api\/v1\/sweeps\/[^/?]+\?format=csv$/);
	assert.equal((await fetch(base + href)).status, 401, 'the link alone is not enough');
	const csv = (await (await fetch(base + href, { headers: AUTH })).text()).trim().split('\n');
	assert.equal(csv.length, 7, csv.join('\n'));
	assert.equal(csv[0], 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
	const got = csvLines(await download('#sweep-csv'));
	assert.deepEqual(got, csv);
	const plot = csvLines(await download('#plot-sweep + .plot-export button[data-export="csv"]'));
	assert.equal(plot[0], 'series,β / °,transport velocity v / (m/s),error');
	assert.equal(plot.length, 7);
});

test('a study over two settings draws a map of v per rotation, its bars on hover; over one, curves over it', async () => {
	await page.fill('#sweep-form input[name="t_end"]', '0.5');
	await page.fill('#sweep-form input[name="vary"]', 'mu=0.3,0.9; beta=30:150:60');
	await page.click('#sweep-run');
	const cellsOf = rot => page.$$eval(`#sweep-map .heatmap[data-rotation="${rot}"] .cell`,
		c => c.map(x => ({ title: x.title, v: Number(x.dataset.v), bg: x.style.background })));
	await until(async () => (await page.$$eval('#sweep-map .cell[data-v]', c => c.length)) === 12, 60000, 'a map of 2 x 3 points per rotation');
	assert.equal(await visible('#plot-sweep'), false, 'the map in place of the curves');
	/* no stray export bar of the hidden curves; a colour scale with its unit */
	assert.equal(await visible('#plot-sweep + .plot-export'), false, 'the curves\' export bar beside the map');
	const scale = await page.$eval('#sweep-map .colour-scale', e => ({ title: e.querySelector('.title').textContent,
		ticks: Array.from(e.querySelectorAll('.ticks .label')).map(l => Number(l.textContent)), h: e.getBoundingClientRect().height }));
	assert.equal(scale.title, 'v / (m/s)');
	assert.equal(scale.ticks.length, 3);
	assert.ok(scale.ticks[0] < 0 && scale.ticks[1] === 0 && scale.ticks[2] === -scale.ticks[0], `ticks ${scale.ticks}`);
	assert.ok(scale.h > 10);
	/* the cells are the daemon's points: mu down, beta across */
	const href = await page.$eval('#sweep-csv', a => a.getAttribute('href'));
	const study = (await (await fetch(base + href.replace('?format=csv', ''), { headers: AUTH })).json());
	assert.deepEqual(study.vary.map(a => a.name), ['mu', 'beta']);
	for (const rot of ['cw', 'ccw']) {
		const cells = await cellsOf(rot);
		const points = study.points.filter(p => p.rotation === rot);
		assert.equal(cells.length, 6);
		cells.forEach((c, i) => {
			const p = points[i];
			assert.equal(c.v, p.velocity, `${rot} cell ${i}`);
			assert.equal(c.title, `mu = ${p.mu}, beta = ${p.beta}, ${rot}: v = ${p.velocity.toFixed(4)} ± ${p.uncertainty.toFixed(4)} m/s`);
			/* red for v > 0, blue for v < 0 */
			assert.match(c.bg, p.velocity > 0 ? /^rgb\(255, / : /, 255\)$/, `${rot} cell ${i}: ${c.bg} for v = ${p.velocity}`);
		});
	}
	/* the map's own export: the CSV rows are the sweep's points, the PNG
	 * an image of the map's size */
	const mapCsv = csvLines(await download('#sweep-map + .plot-export button[data-export="csv"]'));
	assert.equal(mapCsv[0], 'mu,beta,rotation,velocity,uncertainty,steady,dt,substeps');
	assert.deepEqual(mapCsv.slice(1), study.points.map(p =>
		[p.mu, p.beta, p.rotation, p.velocity, p.uncertainty, p.steady, p.dt, p.substeps].map(String).join(',')));
	const png = await download('#sweep-map + .plot-export button[data-export="png"]');
	assert.equal(png.name, 'sweep-map.png');
	assert.equal(png.bytes.subarray(0, 8).toString('hex'), '89504e470d0a1a0a', 'a PNG');
	const size = await page.$eval('#sweep-map', el => {
		const r = el.getBoundingClientRect(), d = window.devicePixelRatio || 1;
		return [Math.round(r.width * d), Math.round(r.height * d)];
	});
	assert.ok(size[0] > 100 && size[1] > 40, `map ${size}`);
	assert.deepEqual([png.bytes.readUInt32BE(16), png.bytes.readUInt32BE(20)], size, 'the PNG has the map\'s size');
	assert.ok(png.bytes.length > 1000, `${png.bytes.length} bytes`);
	const rows = await page.$$eval('#sweep-table tbody tr', r => r.map(x => Array.from(x.cells, c => c.textContent)));
	assert.equal(rows.length, 12);
	assert.deepEqual(rows[0].slice(0, 3), ['0.3', '30', 'cw']);
	const csv = (await (await fetch(base + href, { headers: AUTH })).text()).split('\n');
	assert.equal(csv[0], 'mu,beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
	/* one setting: v against it, a curve per rotation */
	await page.fill('#sweep-form input[name="vary"]', 'mu=0.3,0.6,0.9,1.2');
	await page.click('#sweep-run');
	await until(async () => await visible('#plot-sweep') && await count('#plot-sweep') === 8, 60000, 'the curves over mu');
	assert.equal(await visible('#sweep-map'), false);
	assert.equal(await visible('#sweep-map + .plot-export'), false, 'no map, no map export');
	const plot = csvLines(await download('#plot-sweep + .plot-export button[data-export="csv"]'));
	assert.equal(plot[0], 'series,mu,transport velocity v / (m/s),error');
	assert.deepEqual(plot.slice(1, 5).map(l => l.split(',')[1]), ['0.3', '0.6', '0.9', '1.2']);
	await page.fill('#sweep-form input[name="vary"]', '');
});

test('the calibration panel: pasted points, a fit, data with fitted and original curves', async () => {
	assert.equal(await visible('#fit-csv'), false, 'no fit CSV link before a fit');
	/* a refused CSV: the daemon's detail, nothing started */
	await page.fill('#fit-form textarea[name="csv"]', 'beta,v\n30,0.1\n60,0.05\n');
	await page.click('#fit-run');
	const msg = await page.waitForSelector('#messages .msg.error >> text=/column \'rotation\' is missing/', { timeout: 20000 });
	assert.match(await msg.textContent(), /422/);
	assert.deepEqual((await apiGet(daemon, '/api/v1/fits')).fits, []);
	await page.fill('#fit-form textarea[name="csv"]', 'beta,rotation,v,sigma\n20,cw,0.05,0.005\n60,cw,0.05,0.005\n' +
		'110,cw,-0.05,0.005\n150,cw,-0.05,0.005\n');
	await page.fill('#fit-form input[name="free"]', 'e:0.001:0.1');
	/* a broad log-normal prior on e (its lower bound positive), as the command line writes it */
	await page.fill('#fit-form input[name="priors"]', 'e:0.02:x1.5');
	await page.fill('#fit-form input[name="t_end"]', '2');
	await page.fill('#fit-form input[name="curve_step"]', '60');
	await page.click('#fit-run');
	await page.waitForSelector('#fit-table tr[data-name="e"]', { timeout: 240000 });
	/* the band (4), data (4), fitted and original curves (4 each) on the plot */
	assert.equal(await count('#plot-fit'), 16);
	const href = await page.$eval('#fit-csv', a => a.hidden ? null : a.getAttribute('href'));
	assert.match(href, /^\/api\/v1\/fits\/[^/?]+\?format=csv$/);
	const id = href.split('/').pop().split('?')[0];
	const fit = await apiGet(daemon, `/api/v1/fits/${id}`);
	assert.equal(fit.state, 'done');
	const e = fit.result.parameters[0];
	const row = await page.$$eval('#fit-table tr[data-name="e"] td', c => c.map(x => x.textContent));
	assert.equal(row[0], 'e');
	assert.ok(Math.abs(Number(row[1]) - e.value) <= 1e-4 * Math.abs(e.value), `${row[1]} vs ${e.value}`);
	assert.equal(Number(row[3]), 0.0215);
	assert.equal(fit.result.standard_errors_from, 'sigma');
	assert.deepEqual(e.prior, { mean: 0.02, factor: 1.5 });
	assert.equal(row[6], '0.02 ×÷ 1.5', 'the prior as asked');
	/* χ² at three significant digits (with σ it has no unit) and the reduced χ² */
	const chi2 = await page.$eval('#fit-table .fit-chi2', e => e.textContent);
	const m = /χ² = (\S+) with 3 degrees of freedom; reduced χ²\/dof = (\S+); the priors' share (\S+)$/.exec(chi2);
	assert.ok(m, chi2);
	assert.equal(Number(m[1]), Number(fit.result.chi2.toPrecision(3)), chi2);
	assert.equal(Number(m[2]), Number((fit.result.chi2 / 3).toPrecision(3)), chi2);
	assert.equal(Number(m[3]), Number(fit.result.chi2_prior.toPrecision(3)), chi2);
	assert.ok(fit.result.chi2_prior > 0, "the fit ends away from the prior's median");
	/* measured points as markers, not joined; a legend of the series there are (no ccw data) */
	assert.deepEqual(await page.evaluate(() => window.convsim.plots.fit.joined), [true, true, false, true, true, false, true, true]);
	const legend = await page.$$eval('#plot-fit .u-legend .u-series', rows => rows
		.filter(r => getComputedStyle(r).display !== 'none').map(r => r.querySelector('.u-label').textContent));
	assert.deepEqual(legend, ['95 % band cw', 'data cw', 'fitted cw', 'original cw']);
	/* the band: the fitted curve ± half the band's width, shaded around it */
	const band = await page.evaluate(() => ({ data: window.convsim.plots.fit.plot.data[1], errs: window.convsim.plots.fit.errs[0] }));
	const cw = fit.result.curve.cw;
	assert.deepEqual(band.data, [fit.result.curve.beta, cw.fit]);
	band.errs.forEach((h, k) => assert.ok(Math.abs(cw.fit[k] + h - cw.band.upper[k]) < 1e-12 && h > 0, `${k}: ${h}`));
	/* the progress line says "done" once, not "done · done" */
	assert.match(await page.$eval('#fit-progress .ptext', e => e.textContent), /^done · iteration \d+ · \d+ evaluations/);
	const csv = csvLines(await download('#fit-csv'));
	assert.equal(csv[0], 'kind,name,beta,rotation,measured,sigma,model,uncertainty,residual,start,band_lower,band_upper');
	assert.equal(csv.filter(l => l.startsWith('curve,')).length, 4);
});

test('a sweep with the last fit\'s band: the band shaded under each curve, as the daemon gives it', async () => {
	const box = '#sweep-form input[name="band"]';
	assert.equal(await page.$eval(box, b => b.disabled), false, 'a finished fit offers its band');
	const fitId = /^band of fit (\S+)$/.exec(await page.textContent('#sweep-band-text'))?.[1];
	assert.ok(fitId, await page.textContent('#sweep-band-text'));
	await page.fill('#sweep-form input[name="vary"]', '');
	await page.fill('#sweep-form input[name="from"]', '30');
	await page.fill('#sweep-form input[name="to"]', '150');
	await page.fill('#sweep-form input[name="step"]', '60');
	await page.fill('#sweep-form input[name="t_end"]', '2');
	await page.check(box);
	const before = await page.$eval('#sweep-csv', a => a.getAttribute('href'));
	await page.click('#sweep-run');
	/* 3 angles x 2 rotations, each a curve point and a band point */
	await until(async () => await count('#plot-sweep') === 12 && await page.$eval('#sweep-csv', a => a.getAttribute('href')) !== before,
		120000, 'the sweep with its bands');
	await page.uncheck(box);
	const href = await page.$eval('#sweep-csv', a => a.getAttribute('href'));
	const s = await apiGet(daemon, href.replace('?format=csv', ''));
	await until(async () => (await apiGet(daemon, href.replace('?format=csv', ''))).state === 'done', 120000, 'done');
	const done = await apiGet(daemon, href.replace('?format=csv', ''));
	assert.equal(s.band.fit, fitId);
	assert.deepEqual(done.band.parameters, ['e']);
	const plot = csvLines(await download('#plot-sweep + .plot-export button[data-export="csv"]'));
	for (const [rot, name] of [['cw', '95 % band cw'], ['ccw', '95 % band ccw']]) {
		const rows = plot.filter(l => l.startsWith(`${name},`)).map(l => l.split(',').slice(1).map(Number));
		const pts = done.points.filter(p => p.rotation === rot);
		assert.deepEqual(rows, pts.map(p => [p.beta, p.velocity, (p.band.upper - p.band.lower) / 2]), name);
		assert.ok(rows.every(r => r[2] > 0));
	}
	const legend = await page.$$eval('#plot-sweep .u-legend .u-series', rows => rows
		.filter(r => getComputedStyle(r).display !== 'none').map(r => r.querySelector('.u-label').textContent));
	assert.deepEqual(legend, ['95 % band cw', '95 % band ccw', 'clockwise', 'counter-clockwise']);
});

test('a β-change experiment reports its reversal time', async () => {
	await page.fill('#experiment-form input[name="beta1"]', '38');
	/* settings shown as given: 121.9 (was "122°" on the plot), 1.55 (was "1.55" but 0.052 "0.05") */
	await page.fill('#experiment-form input[name="beta2"]', '121.9');
	await page.fill('#experiment-form input[name="t_switch"]', '1.55');
	await page.fill('#experiment-form input[name="t_end"]', '4');
	await page.uncheck('#experiment-form input[name="watch"]');
	/* the experiment's fresh session takes the form's start: the run-up */
	await page.selectOption('select[name="scene_start"]', 'rest');
	/* the start is checked in the request the dashboard sends (which also
	 * keeps the experiment's session for its plot and trajectory) */
	const posted = page.waitForRequest(r => r.url().endsWith('/api/v1/experiments') && r.method() === 'POST');
	await page.click('#experiment-run');
	const sent = JSON.parse((await posted).postData());
	assert.equal(sent.session.scene.start, 'rest');
	assert.equal(sent.keep_session, true);
	const shown = await until(async () => {
		const t = await page.$eval('#reversal-time', e => e.textContent);
		return /^\d+\.\d{3} s$/.test(t) ? t : null;
	}, 60000, 'a reversal time');
	assert.ok(Number.parseFloat(shown) > 0);
	assert.ok(await count('#plot-experiment') > 0);
	/* the reversal time can show while the second segment still runs (a slow
	 * build): its mean v ± u comes when the experiment ends */
	await until(async () => {
		const rows = await page.$$eval('#experiment-table tbody tr', r => r.map(x => x.cells[4].textContent));
		return rows.length === 2 && rows.every(t => /^[+-]?\d\.\d{3} ± \d\.\d{3}/.test(t)) && rows;
	}, 60000, 'mean v ± u of both segments');
	/* its downloads: the segments and the session's trajectory */
	await until(() => visible('#experiment-downloads'), 10000, 'the experiment downloads');
	const seg = csvLines(await download('#experiment-csv'));
	assert.equal(seg[0], 'experiment,session,segment,beta,until,state,t_command,t_end,start_velocity,' +
		'steady_velocity,mean_velocity,uncertainty,steady,reversal_time,model_error,model_error_uncertainty,model_checked');
	assert.equal(seg.length, 3);
	assert.deepEqual(seg.slice(1).map(l => l.split(',')[3]), ['38', '121.9']);
	/* the table stays inside its card ("reversal / s" stood past the border at 1440 px) */
	await page.setViewportSize({ width: 1440, height: 1300 });
	await page.waitForTimeout(200);
	const spill = await page.evaluate(() => {
		const card = document.querySelector('#experiment-card').getBoundingClientRect();
		const t = document.querySelector('#experiment-table');
		const box = (t.closest('.table-scroll') ?? t).getBoundingClientRect();
		return [box.left - card.left, card.right - box.right];
	});
	await page.setViewportSize({ width: 1600, height: 1300 });
	assert.ok(spill[0] >= 0 && spill[1] >= 0, `experiment table: ${spill} px inside the card's left and right`);
	assert.deepEqual(await page.$$eval('#experiment-table tbody tr', r => r.map(x => x.cells[1].textContent)), ['38', '121.9']);
	assert.equal(await page.$eval('#experiment-table tbody tr:nth-child(2)', r => r.cells[2].textContent), seg[2].split(',')[6]);
	assert.deepEqual(await page.evaluate(() => window.convsim.plots.experiment.markers.map(m => m.label).filter(l => l.startsWith('β'))),
		['β → 121.9°']);
	/* the first segment commands the β the session already has: nothing reverses, no time */
	assert.deepEqual(seg.slice(1).map(l => l.split(',')[13] !== ''), [false, true], seg.join('\n'));
	const reversals = await page.$$eval('#experiment-table tbody tr', r => r.map(x => x.cells[5].textContent));
	assert.equal(reversals[0], '–');
	assert.match(reversals[1], /^\d+\.\d{3}$/);
	const et = csvLines(await download('#experiment-traj'));
	assert.ok(et[0].startsWith(TRAJ_HEAD));
	assert.ok(Number(et[et.length - 1].split(',')[0]) >= 3.9, 'the trajectory covers the experiment');
	const ep = csvLines(await download('#plot-experiment + .plot-export button[data-export="csv"]'));
	assert.equal(ep[0], 't / s,feed velocity / (m/s),β / °');
	assert.deepEqual(ep.slice(1).map(l => l.split(',')[0]).filter(c => !onNsGrid(c)).slice(0, 3), [], 'experiment.csv: times on the grid');
	await page.selectOption('select[name="scene_start"]', 'steady');
});

test('the token stays with the tab: a reload works; a tab without it is told', async () => {
	const attached = await page.$eval('body', b => b.dataset.sessionId);
	await page.reload();
	await page.waitForSelector('body[data-ready="true"]', { timeout: 15000 });
	await page.waitForSelector('#conn[data-state="online"]', { timeout: 10000 });
	assert.equal(await page.$eval('body', b => b.dataset.sessionId), attached);
	await until(async () => await samples() > 0, 10000, 'stream samples after the reload');
	assert.equal(await page.$$eval('#messages .msg.error', l => l.length), 0);
	const other = await browser.newPage(); /* a new context: no sessionStorage */
	try {
		await other.goto(base + '/');
		const msg = await other.waitForSelector('#messages .msg.error', { timeout: 10000 });
		assert.match(await msg.textContent(), /asks for its token.*#token=/);
	} finally {
		await other.close();
	}
});

test('screenshot of the dashboard', async () => {
	await page.waitForTimeout(300);
	await page.screenshot({ path: path.join(OUT, 'dashboard.png'), fullPage: true });
	assert.deepEqual(pageErrors, []);
});

test('a Kloss-drive session from the picker: the rotor plot\'s period means leave β visible', async () => {
	const r = await fetch(base + '/api/v1/sessions', { method: 'POST', headers: { 'Content-Type': 'application/json', ...AUTH },
		body: JSON.stringify({ params: { beta: 38 }, scene: { drive: 'motor', columns: 5, layers: 2 }, pace: Number(PACE), sample_rate: 500 }) });
	assert.equal(r.status, 201);
	const id = (await r.json()).id;
	await until(async () => (await page.$$eval('#session-select option', o => o.map(x => x.value))).includes(id), 10000, 'the new session in the picker');
	await page.selectOption('#session-select', id);
	await until(async () => await page.$eval('body', b => b.dataset.sessionId) === id, 5000, 'attached');
	await until(async () => await tEnd('#plot-rotor') > 2, 30000, 'two seconds of rotor speed');
	const shown = await page.evaluate(() => {
		const [t, w] = window.convsim.plots.rotor.plot.data;
		const last = t.length - 1, from = t.findIndex(x => x >= t[last] - 1);
		const ws = w.slice(from).filter(Number.isFinite);
		return Math.max(...ws) - Math.min(...ws);
	});
	/* the raw rotor speed ripples at the excitation frequency */
	const traj = await apiGet(daemon, `/api/v1/sessions/${id}/trajectory?from=1`);
	const k = traj.fields.indexOf('rotor_speed');
	const raw = traj.rows.map(row => row[k]);
	const ripple = Math.max(...raw) - Math.min(...raw);
	assert.ok(ripple > 0.5, `raw ripple ${ripple} rad/s`);
	assert.ok(shown < ripple / 4, `the plot's rotor speed spans ${shown} rad/s over its last second, the raw ${ripple}`);
});

test('the rotor plot\'s ticks: every one with the decimals of its step', async () => {
	const ticks = await until(async () => {
		const t = await page.$eval('#plot-rotor', e => e.dataset.yTicks || '');
		return t.split(' ').filter(Boolean).length >= 3 ? t.split(' ') : null;
	}, 10000, 'the rotor plot\'s ticks');
	const decimals = new Set(ticks.map(x => (x.split('.')[1] || '').length));
	assert.equal(decimals.size, 1, `one number of decimals: ${ticks.join(' ')}`);
	const v = ticks.map(Number);
	const steps = v.slice(1).map((x, i) => x - v[i]);
	for (const st of steps) assert.ok(Math.abs(st - steps[0]) <= 1e-9 * Math.abs(v[0]), `evenly spaced as written: ${ticks.join(' ')}`);
});

test('a liggghts-bed4 session shows its DEM check in plain words, and the new one after a β change', async () => {
	const r = await fetch(base + '/api/v1/sessions', { method: 'POST', headers: { 'Content-Type': 'application/json', ...AUTH },
		body: JSON.stringify({ preset: 'liggghts-bed4', params: { beta: 30 }, scene: { drive: 'ideal', columns: 2 }, pace: 1 }) });
	assert.equal(r.status, 201);
	const bed = await r.json();
	assert.equal(bed.status.model_checked, true);
	await until(async () => (await page.$$eval('#session-select option', o => o.map(x => x.value))).includes(bed.id), 10000, 'the new session in the picker');
	await page.selectOption('#session-select', bed.id);
	const want = e => `DEM check: within ±${e.toFixed(3)} m/s here`;
	await until(async () => await page.$eval('#v-model', e => e.textContent) === want(bed.status.model_error), 5000,
		`${want(bed.status.model_error)} on the page`);
	assert.equal(await page.$eval('#v-model', e => e.dataset.checked), 'true');
	const p = await fetch(`${base}/api/v1/sessions/${bed.id}`, { method: 'PATCH', headers: { 'Content-Type': 'application/json', ...AUTH },
		body: JSON.stringify({ beta: 150 }) });
	assert.equal(p.status, 200);
	const at150 = (await p.json()).status.model_error;
	assert.ok(at150 > bed.status.model_error, `${at150} at 150 deg, ${bed.status.model_error} at 30`);
	await until(async () => await page.$eval('#v-model', e => e.textContent) === want(at150), 5000, `${want(at150)} after the β change`);
	await page.selectOption('#session-select', sessionId);
	/* the first session, its omega_ss changed by the drive row: not checked */
	await until(async () => /not checked against DEM/.test(await page.$eval('#v-model', e => e.textContent)), 5000,
		'the first session\'s line again');
	assert.equal(await page.$eval('#v-model', e => e.dataset.checked), 'false');
	const del = await fetch(`${base}/api/v1/sessions/${bed.id}`, { method: 'DELETE', headers: { 'Content-Type': 'application/json', ...AUTH } });
	assert.equal(del.status, 204);
});

test('Delete clears the tiles and the plots', async () => {
	const gone = await page.$eval('body', b => b.dataset.sessionId);
	const after = [];
	const seen = r => { if (r.url().includes(gone)) after.push(`${r.method()} ${r.url()}`); };
	await page.click('#delete');
	page.on('request', seen);
	await until(async () => !(await page.$eval('body', b => b.dataset.sessionId)), 5000, 'the session detached');
	await until(async () => await page.$eval('#state-now', e => e.textContent) === 'no session', 5000, 'no session shown');
	for (const sel of ['#t-now', '#rotor-now', '#rtf-now', '#v-value', '#v-daemon'])
		assert.equal(await page.$eval(sel, e => e.textContent), '–', sel);
	for (const sel of ['#plot-rotor', '#plot-feed', '#plot-orbit', '#plot-strokes', '#plot-trough'])
		assert.equal(await count(sel), 0, `${sel} emptied`);
	/* and it stays so: no poll brings the deleted session back, and none
	 * asks for it (each would be a 404 in the console) */
	after.length = 0;
	await new Promise(r => setTimeout(r, 2500));
	page.off('request', seen);
	assert.equal(await page.$eval('#state-now', e => e.textContent), 'no session');
	assert.deepEqual(after, [], 'no request for the deleted session');
	/* the tour's refusals on purpose: 422s (a refused input, a refused CSV) and a 400 (pace "abc") */
	const provoked = e => /status of 422 .* in "(a refused input|the calibration panel)/.test(e) || /status of 400 .* in "the drive row/.test(e);
	assert.deepEqual(consoleErrors.filter(e => !provoked(e)), [], 'no console error in the whole tour but those provoked');
});

test('a phone (390 px): one column, no sideways scroll; one h1', async () => {
	await page.setViewportSize({ width: 390, height: 844 });
	try {
		await until(async () => await page.evaluate(() => document.documentElement.scrollWidth) <= 390, 5000, 'no sideways scroll');
		const wide = await page.evaluate(() => [...document.querySelectorAll('main *, header *')]
			.filter(e => { const b = e.getBoundingClientRect(); return b.width > 0 && b.right > 391; })
			.map(e => `${e.tagName}#${e.id}.${e.className}`).slice(0, 5));
		assert.deepEqual(wide, [], 'nothing reaches past the screen');
		/* the picker shows the session it is on, not only its arrow */
		const pick = await page.$eval('#session-select', e => ({ w: e.getBoundingClientRect().width, text: e.selectedOptions[0]?.textContent }));
		assert.ok(pick.w >= 200, `the picker is ${pick.w} px wide`);
		assert.ok(pick.text.length > 3, pick.text);
		for (const sel of ['#sweep-run', '#conn'])
			if (await page.$(sel)) {
				const b = await page.$eval(sel, e => { const r = e.getBoundingClientRect(); return [r.left, r.right]; });
				assert.ok(b[0] >= 0 && b[1] <= 390, `${sel} on screen: ${b}`);
			}
		/* an empty plot's text sits in the plotting area, clear of the axes'
		 * tick labels (it covered the left axis's labels at this width):
		 * each plot shown as empty for a moment */
		const boxes = await page.$$eval('.plot', ps => ps.filter(p => p.offsetParent && p.querySelector('.u-over')).map(p => {
			const was = p.classList.contains('empty');
			p.classList.add('empty');
			const a = getComputedStyle(p, '::after');
			const r = p.getBoundingClientRect(), q = p.querySelector('.u-over').getBoundingClientRect();
			const box = { id: p.id, text: a.content, after: [a.left, a.top, a.width, a.height].map(parseFloat),
				over: [q.left - r.left, q.top - r.top, q.width, q.height] };
			p.classList.toggle('empty', was);
			return box;
		}));
		assert.ok(boxes.length >= 8, `plots shown: ${boxes.map(b => b.id)}`);
		for (const b of boxes) {
			assert.notEqual(b.text, 'none', `${b.id}: the empty text is shown`);
			b.after.forEach((v, i) => assert.ok(Math.abs(v - b.over[i]) <= 1.5,
				`${b.id}: the empty text's box ${b.after} is the plotting area ${b.over}`));
		}
	} finally {
		await page.setViewportSize({ width: 1600, height: 1300 });
	}
	assert.equal(await page.$$eval('h1', h => h.length), 1);
	assert.match(await page.$eval('h1', h => h.textContent), /convsim/);
});

test('problem pages are rendered: code as code, no raw backticks', async () => {
	const other = await browser.newPage({ extraHTTPHeaders: AUTH });
	try {
		const res = await other.goto(`${base}/api/v1/problems/out-of-range`);
		assert.equal(res.status(), 200);
		const text = await other.evaluate(() => document.body.innerText);
		assert.doesNotMatch(text, /`/);
		assert.ok(await other.$$eval('p code', c => c.map(x => x.textContent).includes('field')));
	} finally {
		await other.close();
	}
});

test('the page says so when the daemon goes away', async () => {
	await stopDaemon(daemon?.proc);
	await page.waitForSelector('#conn[data-state="offline"]', { timeout: 10000 });
	const text = await page.$eval('#messages', e => e.textContent);
	assert.match(text, /does not answer/);
});
