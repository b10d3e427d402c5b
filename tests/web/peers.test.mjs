// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of a cluster's session picker: a replica started with
// --peers lists every peer's sessions with its own, and a peer that does not
// answer is named in the listing's "unreachable" (docs/cluster.md). The
// dashboard says so beside the picker, in words, with each peer and why in
// its title; a daemon without peers shows no such note.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard, apiGet, until } from './lib.mjs';

const daemons = [], uis = [];
after(async () => {
	for (const ui of uis) await ui.browser.close();
	for (const d of daemons) assert.equal(await stopDaemon(d.proc), 0);
});

const note = page => page.evaluate(() => {
	const e = document.querySelector('#peers-note');
	return { hidden: e.hidden, shown: e.offsetParent !== null, text: e.textContent, title: e.title };
});

test('a replica whose peer does not answer says beside the picker that its sessions are not listed', async () => {
	// port 1 on loopback: nothing listens, the connection is refused at once
	const dead = 'http://127.0.0.1:1';
	const d = await startDaemon({ args: ['--peers', dead] });
	daemons.push(d);
	const list = await apiGet(d, '/api/v1/sessions');
	assert.deepEqual(list.sessions, []);
	assert.equal(list.unreachable.length, 1);
	assert.equal(list.unreachable[0].peer, dead);
	const ui = await openDashboard(d);
	uis.push(ui);
	const n = await until(async () => { const n = await note(ui.page); return n.shown && n; }, 10000, 'the note');
	assert.equal(n.text, '1 replica did not answer: its sessions are not listed');
	assert.equal(n.title, `${dead}: ${list.unreachable[0].reason}`);
	assert.deepEqual(ui.pageErrors, []);
});

test('a daemon without peers shows no such note', async () => {
	const d = await startDaemon();
	daemons.push(d);
	const ui = await openDashboard(d);
	uis.push(ui);
	// the list was asked once the page is ready: the note stayed hidden
	assert.deepEqual(await note(ui.page), { hidden: true, shown: false, text: '', title: '' });
	assert.deepEqual(ui.pageErrors, []);
});
