// SPDX-License-Identifier: GPL-3.0-or-later
// What a browser test of the dashboard needs (dashboard.test.mjs and the
// test files beside it): $CONVSIMD (default build/convsimd) on port 0 with
// a token file, Debian's chromium through playwright-core, the page opened
// as `make run` prints it (#token=...), its page and console errors
// collected, and a poll helper.
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { randomBytes } from 'node:crypto';
import { mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { fileURLToPath } from 'node:url';
import { chromium } from '../node_modules/playwright-core/index.mjs';
import '../tether.mjs'; // nothing started here outlives the test

export const ROOT = path.resolve(path.dirname(fileURLToPath(import.meta.url)), '../..');
const DAEMON = path.resolve(ROOT, process.env.CONVSIMD || 'build/convsimd');
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';

/* The daemon with a fresh token; {proc, base, auth, token}. opts: port
 * (default 0: a free one), token (the same again, for a restart) and
 * args (more daemon options, e.g. ['--data-dir', DIR]). */
export function startDaemon({ port = 0, token = randomBytes(20).toString('hex'), args = [] } = {}) {
	const file = path.join(mkdtempSync(path.join(tmpdir(), 'convsim-web-')), 'token');
	writeFileSync(file, token + '\n', { mode: 0o600 });
	return new Promise((resolve, reject) => {
		const p = spawn(DAEMON, ['--port', String(port), '--token-file', file, ...args], { cwd: ROOT, stdio: ['ignore', 'pipe', 'pipe'] });
		let out = '', up = false;
		const timer = setTimeout(() => { p.kill('SIGKILL'); reject(new Error(`no "listening on" line from ${DAEMON} in 15 s:\n${out}`)); }, 15000);
		/* once up, later output (the daemon's words at a SIGTERM) leaves
		 * the 'exit' listeners alone: stopDaemon waits on one */
		const scan = chunk => {
			if (up) return;
			out += chunk;
			const m = /listening on (http:\/\/[^\s]+)/.exec(out);
			if (!m) return;
			up = true;
			clearTimeout(timer);
			p.removeAllListeners('exit');
			resolve({ proc: p, base: m[1].replace(/\/$/, '').replace('0.0.0.0', '127.0.0.1'), token, auth: { Authorization: `Bearer ${token}` } });
		};
		p.stdout.setEncoding('utf8').on('data', scan);
		p.stderr.setEncoding('utf8').on('data', scan);
		p.on('error', e => { clearTimeout(timer); reject(e); });
		p.on('exit', code => { clearTimeout(timer); reject(new Error(`${DAEMON} exited (${code}) before listening:\n${out}`)); });
	});
}

/* SIGTERM, then SIGKILL after 5 s; the exit code (null: killed). */
export async function stopDaemon(proc) {
	if (!proc || proc.exitCode !== null || proc.signalCode) return proc?.exitCode;
	const exited = new Promise(r => proc.once('exit', code => r(code)));
	proc.kill('SIGTERM');
	const t = setTimeout(() => proc.kill('SIGKILL'), 5000);
	const code = await exited;
	clearTimeout(t);
	return code;
}

/* Headless chromium ($CHROMIUM, default Debian's), quiet on the network. */
export function launchChromium() {
	return chromium.launch({
		executablePath: CHROMIUM,
		args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
			'--disable-background-networking', '--disable-component-update', '--disable-sync'],
	});
}

/* Chromium and a page of width x height on the daemon d's dashboard, ready;
 * {browser, page, pageErrors, consoleErrors}. */
export async function openDashboard(d, width = 1600, height = 1300) {
	const browser = await launchChromium();
	const page = await browser.newPage({ viewport: { width, height } });
	const pageErrors = [], consoleErrors = [];
	page.on('pageerror', e => pageErrors.push(e.message));
	page.on('console', m => { if (m.type() === 'error') consoleErrors.push(`${m.text()} (${m.location().url})`); });
	const res = await page.goto(`${d.base}/#token=${d.token}`);
	assert.equal(res.status(), 200);
	await page.waitForSelector('body[data-ready="true"]', { timeout: 15000 });
	return { browser, page, pageErrors, consoleErrors };
}

/* The dashboard of d, its new-session form set to a small scene: the
 * ideal drive, 5 columns of 2 layers (the panels' tests that run jobs). */
export async function openSmallScene(d) {
	const ui = await openDashboard(d);
	await ui.page.selectOption('select[name="drive"]', 'ideal');
	await ui.page.fill('#session-form input[name="layers"]', '2');
	await ui.page.fill('#session-form input[name="columns"]', '5');
	return ui;
}

/* GET path's JSON with the token; a status other than 200 fails. */
export async function apiGet(d, p) {
	const res = await fetch(d.base + p, { headers: d.auth });
	assert.equal(res.status, 200, `GET ${p}`);
	return res.json();
}

/* Poll fn until it returns a truthy value or ms pass. */
export async function until(fn, ms, what) {
	const end = Date.now() + ms;
	let last;
	while (Date.now() < end) {
		last = await fn();
		if (last) return last;
		await new Promise(r => setTimeout(r, 200));
	}
	throw new Error(`timed out after ${ms} ms waiting for ${what} (last: ${JSON.stringify(last)})`);
}

/* Click sel on page and take the download it starts: its name, bytes and
 * text. */
export async function download(page, sel) {
	const [dl] = await Promise.all([page.waitForEvent('download', { timeout: 10000 }), page.click(sel)]);
	const bytes = readFileSync(await dl.path());
	return { name: dl.suggestedFilename(), bytes, text: bytes.toString('utf8') };
}
