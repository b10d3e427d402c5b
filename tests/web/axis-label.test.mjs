// SPDX-License-Identifier: GPL-3.0-or-later
// Browser test of the sweep and fit plots' y axis label, with the set-up of
// lib.mjs: uPlot centres the rotated label on the plotting area, so it is
// whole where its width is at most the area's height. At 400 px the long
// label, "transport velocity v / (m/s)", was wider and cut at both ends;
// there the plots label the axis "v / (m/s)", at 1600 px in full. The
// width is measured in the page with the axes' label font.
import { test, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, stopDaemon, openDashboard } from './lib.mjs';

let d, ui;
after(async () => {
	await ui?.browser.close();
	assert.equal(await stopDaemon(d?.proc), 0);
});

/* For each of the sweep and fit plots: the y label as drawn, its width
 * and the plotting area's height (CSS px). */
const labels = page => page.evaluate(() => ['sweep', 'fit'].map(name => {
	const u = window.convsim.plots[name].plot;
	const axis = u.axes[1];
	const label = typeof axis.label === 'function' ? axis.label(u, 1) : axis.label;
	const ctx = document.createElement('canvas').getContext('2d');
	ctx.font = '600 11px system-ui, sans-serif';
	return { name, label, width: Math.ceil(ctx.measureText(label).width), room: Math.floor(u.bbox.height / devicePixelRatio) };
}));

test('the sweep and fit plots\' y label fits at 400 px and is whole at 1600 px', async () => {
	d = await startDaemon();
	ui = await openDashboard(d, 400, 900);
	for (const l of await labels(ui.page)) {
		assert.equal(l.label, 'v / (m/s)', `${l.name} at 400 px (width ${l.width}, room ${l.room})`);
		assert.ok(l.width <= l.room, `${l.name}: "${l.label}" ${l.width} px in ${l.room} px`);
	}
	await ui.page.setViewportSize({ width: 1600, height: 1300 });
	await ui.page.waitForFunction(() => window.convsim.plots.sweep.plot.width > 500, null, { timeout: 10000 });
	for (const l of await labels(ui.page)) {
		assert.equal(l.label, 'transport velocity v / (m/s)', `${l.name} at 1600 px`);
		assert.ok(l.width <= l.room, `${l.name}: "${l.label}" ${l.width} px in ${l.room} px`);
	}
	/* the data's column keeps the long name */
	assert.equal(await ui.page.evaluate(() => window.convsim.plots.sweep.labels[1]), 'transport velocity v / (m/s)');
	assert.deepEqual(ui.pageErrors, []);
});
