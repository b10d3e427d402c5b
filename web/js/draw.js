// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * draw.js - redraws plots, the velocity tile and the schematic from the
 * traces at most every animation frame (every 50 ms), and only when the
 * page is dirty.
 */

import { fmt, fmtVelocity, direction, ARROW } from './format.js';
import { app, $, numberOf } from './ui.js';
import { currentVelocity, MM } from './live.js';
import { buildFeedPlot, buildStrokesPlot } from './figures.js';

let lastDraw = 0;
export function frame(now) {
	requestAnimationFrame(frame);
	if (!app.dirty || now - lastDraw < 50) return;
	lastDraw = now;
	app.dirty = false;
	draw();
}

function draw() {
	const tr = app.traces;
	if (tr) {
		const o = tr.orbit.data();
		app.plots.orbit.setData([[o[1], o[2]]]);
		const sd = tr.strokes.data();
		const same = columnsAlike(sd);
		buildStrokesPlot(same);
		app.plots.strokes.setData(same ? sd.slice(0, 2) : sd);
		app.plots.trough.setData(tr.trough.data());
		app.plots.rotor.setData(tr.rotor.data());
		if (app.columns) {
			const d = tr.feed.data();
			const alike = columnsAlike(d);
			buildFeedPlot(app.columns, alike);
			app.plots.feed.setData(alike ? d.slice(0, 2) : d);
		}
		$('#live-state').dataset.samples = String(app.samples);
		$('#live-state').dataset.dropped = String(app.dropped);
		if (app.stream && app.samples)
			$('#live-state').textContent = `stream: ${app.samples} samples` + (app.dropped ? `, ${app.dropped} missed (slow client)` : '');
	}
	const v = currentVelocity();
	const dir = direction(v);
	app.lastVelocity = v;
	$('#v-value').textContent = fmtVelocity(v);
	const arrow = $('#v-arrow');
	arrow.textContent = ARROW[dir];
	arrow.dataset.direction = dir;
	$('#tile-velocity').dataset.direction = dir;
	$('#v-dir').textContent = dir === 'right' ? 'feed moves right (+x)' : dir === 'left' ? 'feed moves left (−x)' : dir === 'still' ? 'feed at rest' : 'no reading yet';
	const s = app.session;
	const last = app.lastSample;
	const strokes = tr?.strokes.data();
	const range = strokes && strokes[0].length ? [1, 2].map(c => {
		const v = strokes[c].filter(Number.isFinite);
		return v.length ? [Math.min(...v) / MM, Math.max(...v) / MM] : null;
	}) : undefined;
	/* one β per moment: the readout shows the drawing's (the latest
	 * sample's, else the polled status's) */
	const beta = Number.isFinite(last?.beta) ? last.beta : s?.beta ?? numberOf($('#session-form').elements.beta);
	if (s || Number.isFinite(last?.beta)) $('#beta-now').textContent = fmt(beta, 1, '°');
	app.schematic.update({
		beta,
		betaTarget: s?.betaTarget,
		rotation: last?.rotation ?? s?.rotation ?? $('#session-form').elements.rotation.value,
		strokes: last?.strokes,
		phase: last?.phi,
		strokeRange: range,
		columns: app.columns || (s ? (s.feed === false ? 0 : s.columns) : ($('#session-form').elements.feed.checked ? numberOf($('#session-form').elements.columns) : 0)),
		layers: s?.layers ?? numberOf($('#session-form').elements.layers),
		direction: dir,
	});
}

/* 1 if every column's trace equals the first's (to 1e-12 of its size):
 * the feed's columns, the two strokes. */
function columnsAlike(d) {
	if (d.length < 3 || !d[0].length) return false;
	let size = 1e-12;
	for (const v of d[1]) if (Number.isFinite(v)) size = Math.max(size, Math.abs(v));
	for (let k = 2; k < d.length; k++)
		for (let i = 0; i < d[k].length; i++)
			if (!(Math.abs(d[k][i] - d[1][i]) <= 1e-12 * size)) return false;
	return true;
}
