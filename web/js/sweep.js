// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * sweep.js - the sweep panel: runs v(beta) for both rotations on the
 * new-session form's model, or a study over the settings of its "vary"
 * field, follows its progress, and shows the plot (with each point's error
 * bar; a study over one setting as curves over it), a study over two
 * settings as a map of v per rotation (each cell's title: v and its error
 * bar; exported beside it as a PNG and as the CSV of its points), the
 * table (v, its error bar u, steady or settling) and the CSV link. With
 * "band of the last fit" the sweep takes that fit's bands
 * (band_from_fit), shaded under the curves as the fit's own band is.
 */

import * as api from './api.js';
import { fmt, steadyLabel } from './format.js';
import { app, $, message, report, setOnline, numberOf, busy, progress, poll } from './ui.js';
import { readSessionForm } from './session.js';
import { addExport } from './plots.js';

export async function runSweep(ev) {
	ev.preventDefault();
	const f = $('#sweep-form').elements;
	const base = readSessionForm();
	const form = { ...base, from: numberOf(f.from), to: numberOf(f.to), step: numberOf(f.step), tEnd: numberOf(f.t_end), vary: f.vary.value,
		bandFit: f.band.checked ? app.lastFit : undefined };
	const btn = $('#sweep-run');
	const box = $('#sweep-progress');
	busy(btn, true);
	try {
		const j = await api.createSweep(form);
		setOnline(true);
		progress(box, j.progress, 'started');
		showSweep(j);
		const end = await poll(api.getSweep, j.id, u => {
			showSweep(u);
			progress(box, u.progress, `${u.state || 'running'} · ${u.points.length} points`);
		});
		const missing = end.points.filter(p => !Number.isFinite(p.v)).length;
		if (end.failed) message('error', `Sweep ${end.id} ${end.state}${end.error ? ': ' + end.error : ''}`);
		else if (missing) message('warn', `Sweep ${end.id} finished, but ${missing} of ${end.points.length} points gave no transport velocity: ` +
			'the run time per point must exceed the scene\'s transient by at least one excitation period (the transport velocity ignores t < transient).');
		else {
			const settling = end.points.filter(p => p.steady === false).length;
			message(settling ? 'warn' : 'ok', `Sweep ${end.id} finished: ${end.points.length} points` +
				(settling ? `, ${settling} still settling at the end (a longer run time per point helps).` : ', all steady.'));
		}
	} catch (err) {
		report(err, 'Sweep', $('#sweep-form'));
	} finally {
		busy(btn, false);
	}
}

function showSweep(j) {
	const csv = $('#sweep-csv');
	csv.hidden = !j.id;
	if (j.id) {
		csv.href = api.sweepCsvUrl(j.id);
		csv.download = `sweep-${j.id}.csv`;
	}
	const vary = j.vary || ['beta'];
	const map = $('#sweep-map');
	map.hidden = vary.length !== 2;
	$('#plot-sweep').hidden = vary.length === 2;
	if (vary.length === 2) drawMaps(map, j.points, vary);
	const exp = mapExport(map);
	exp.points = vary.length === 2 ? j.points : [];
	exp.vary = vary;
	exp.bar.hidden = !exp.points.length;
	/* the curves' export goes with the curves: none beside the map */
	if (vary.length === 2) app.plots.sweep.bar.hidden = true;
	if (vary.length === 1 && vary[0] !== 'beta') return showCurves(j.points, vary[0]);
	if (vary.length !== 1) return showStudyTable(j.points, vary);
	setXLabel('β / °');
	const by = rot => j.points.filter(p => p.rotation === rot).sort((a, b) => a.beta - b.beta);
	const cw = by('cw'), ccw = by('ccw');
	plotCurves(cw, ccw, p => p.beta);
	const table = $('#sweep-table');
	table.replaceChildren();
	const head = table.createTHead().insertRow();
	for (const h of ['β / °', 'v clockwise / (m/s)', '± u', '', 'v counter-clockwise / (m/s)', '± u', ''])
		head.append(Object.assign(document.createElement('th'), { textContent: h }));
	const betas = [...new Set(j.points.map(p => p.beta))].sort((a, b) => a - b);
	const body = table.createTBody();
	for (const b of betas) {
		const row = body.insertRow();
		row.insertCell().textContent = fmt(b, 1);
		for (const p of [cw.find(q => q.beta === b), ccw.find(q => q.beta === b)]) {
			row.insertCell().textContent = fmt(p?.v, 4);
			row.insertCell().textContent = fmt(p?.u, 4);
			addSteady(row, p);
		}
	}
}

/* The steady / settling mark of point p in a new cell of row. */
function addSteady(row, p) {
	const mark = row.insertCell();
	mark.textContent = steadyLabel(Number.isFinite(p?.v) ? p.steady : undefined);
	mark.className = 'steady-mark';
	mark.dataset.steady = mark.textContent;
}

/* The plot's x axis names what it is over (and its CSV export's column). */
function setXLabel(label) {
	const plot = app.plots.sweep;
	if (plot.labels[0] === label) return;
	plot.labels[0] = label;
	plot.plot.axes[0].label = label;
	plot.plot.redraw(false, true);
}

/* A study over one setting: v against it, one curve per rotation. */
function showCurves(points, name) {
	setXLabel(name);
	const by = rot => points.filter(p => p.rotation === rot).sort((a, b) => a.at[name] - b.at[name]);
	const cw = by('cw'), ccw = by('ccw');
	plotCurves(cw, ccw, p => p.at[name]);
	showStudyTable(points, [name]);
}

/* The curves of v (with each point's error bar) over x(p), per rotation,
 * and under them the fit's 95 % band where the sweep has one (shaded as
 * v ± its half-width: the band is symmetric about v). */
function plotCurves(cw, ccw, x) {
	const banded = pts => pts.filter(p => p.band && Number.isFinite(p.band[0]) && Number.isFinite(p.band[1]));
	const bands = [banded(cw), banded(ccw)];
	app.plots.sweep.setData([...bands.map(b => [b.map(x), b.map(p => p.v)]),
		[cw.map(x), cw.map(p => p.v)], [ccw.map(x), ccw.map(p => p.v)]],
	[...bands.map(b => b.map(p => (p.band[1] - p.band[0]) / 2)), cw.map(p => p.u), ccw.map(p => p.u)]);
}

/* A study's table: the varied settings, the rotation, v, u, steady. */
function showStudyTable(points, vary) {
	const table = $('#sweep-table');
	table.replaceChildren();
	const head = table.createTHead().insertRow();
	for (const h of [...vary, 'rotation', 'v / (m/s)', '± u', ''])
		head.append(Object.assign(document.createElement('th'), { textContent: h }));
	const body = table.createTBody();
	for (const p of points) {
		const row = body.insertRow();
		for (const n of vary) row.insertCell().textContent = String(p.at?.[n]);
		row.insertCell().textContent = p.rotation;
		row.insertCell().textContent = fmt(p.v, 4);
		row.insertCell().textContent = fmt(p.u, 4);
		addSteady(row, p);
	}
}

/* The colour of v on a scale symmetric about 0 (blue < 0 < red), vmax
 * its largest magnitude; grey when there is no v. */
function colourOf(v, vmax) {
	if (!Number.isFinite(v)) return '#e5e7eb';
	const t = vmax > 0 ? Math.min(1, Math.abs(v) / vmax) : 0;
	const c = Math.round(255 * (1 - t));
	return v >= 0 ? `rgb(255,${c},${c})` : `rgb(${c},${c},255)`;
}

/* A study over two settings: per rotation, a grid of cells, the first
 * setting down, the second across, each coloured by v, its title naming
 * the point and v with its error bar. */
function drawMaps(box, points, [rowName, colName]) {
	box.replaceChildren();
	const values = n => [...new Set(points.map(p => p.at[n]))].sort((a, b) => a - b);
	const rows = values(rowName), cols = values(colName);
	const vmax = Math.max(0, ...points.map(p => Math.abs(p.v)).filter(Number.isFinite));
	for (const rot of ['cw', 'ccw']) {
		const mine = points.filter(p => p.rotation === rot);
		if (!mine.length) continue;
		const grid = Object.assign(document.createElement('div'), { className: 'heatmap' });
		grid.dataset.rotation = rot;
		grid.style.gridTemplateColumns = `auto repeat(${cols.length}, 1fr)`;
		grid.append(Object.assign(document.createElement('div'), { className: 'title',
			textContent: `v / (m/s), ${rot === 'cw' ? 'clockwise' : 'counter-clockwise'}: ${rowName} down, ${colName} across` }));
		grid.append(Object.assign(document.createElement('div'), { className: 'label' }));
		for (const c of cols) grid.append(Object.assign(document.createElement('div'), { className: 'label', textContent: String(c) }));
		for (const r of rows) {
			grid.append(Object.assign(document.createElement('div'), { className: 'label', textContent: String(r) }));
			for (const c of cols) {
				const p = mine.find(q => q.at[rowName] === r && q.at[colName] === c);
				const cell = Object.assign(document.createElement('div'), { className: 'cell' });
				cell.style.background = colourOf(p?.v, vmax);
				cell.title = `${rowName} = ${r}, ${colName} = ${c}, ${rot}: v = ${fmt(p?.v, 4)} ± ${fmt(p?.u, 4)} m/s`;
				if (p && Number.isFinite(p.v)) cell.dataset.v = String(p.v);
				grid.append(cell);
			}
		}
		box.append(grid);
	}
	box.append(colourScale(vmax));
}

/* The map's colour scale: −vmax (blue) through 0 (white) to +vmax (red),
 * in m/s, the colours of colourOf. */
function colourScale(vmax) {
	const scale = Object.assign(document.createElement('div'), { className: 'colour-scale' });
	scale.setAttribute('role', 'img');
	scale.setAttribute('aria-label', `colour scale: blue ${fmt(-vmax, 3)} m/s (feed moves left), white 0, red ${fmt(vmax, 3)} m/s (right)`);
	const bar = Object.assign(document.createElement('div'), { className: 'bar' });
	bar.style.background = `linear-gradient(to right, ${colourOf(-vmax, vmax)}, ${colourOf(0, vmax)}, ${colourOf(vmax, vmax)})`;
	const ticks = Object.assign(document.createElement('div'), { className: 'ticks' });
	for (const v of [-vmax, 0, vmax]) ticks.append(Object.assign(document.createElement('span'), { className: 'label', textContent: fmt(v, 3) }));
	scale.append(Object.assign(document.createElement('div'), { className: 'title', textContent: 'v / (m/s)' }), bar, ticks);
	return scale;
}

/* The map's export buttons (PNG, CSV) beside it, made once: the owner
 * holds the points and settings shown. */
let mapOwner = null;
function mapExport(box) {
	if (mapOwner) return mapOwner;
	mapOwner = { points: [], vary: [], csvRows: () => mapRows(mapOwner.points, mapOwner.vary), canvas: () => mapCanvas(box) };
	mapOwner.bar = addExport(mapOwner, box);
	return mapOwner;
}

/* The tidy rows behind the map: a header, then one row per point in the
 * daemon's order: both varied settings, the rotation, v and its error bar
 * (m/s), steady, and the steps it was measured with (dt in s, substeps). */
function mapRows(points, [rowName, colName]) {
	return [[rowName, colName, 'rotation', 'velocity', 'uncertainty', 'steady', 'dt', 'substeps'],
		...points.map(p => [p.at?.[rowName], p.at?.[colName], p.rotation, p.v, p.u, p.steady, p.dt, p.substeps])];
}

/* The map as it is on the page, drawn onto a canvas of its size (CSS
 * pixels times the device's pixel ratio): each cell's colour, each
 * label's and title's text where they are. */
function mapCanvas(box) {
	const dpr = window.devicePixelRatio || 1;
	const at = box.getBoundingClientRect();
	const c = document.createElement('canvas');
	c.width = Math.round(at.width * dpr);
	c.height = Math.round(at.height * dpr);
	const ctx = c.getContext('2d');
	ctx.scale(dpr, dpr);
	ctx.fillStyle = '#fff';
	ctx.fillRect(0, 0, at.width, at.height);
	for (const el of box.querySelectorAll('.cell, .label, .title')) {
		const r = el.getBoundingClientRect(), css = getComputedStyle(el);
		const x = r.left - at.left, y = r.top - at.top;
		if (el.classList.contains('cell')) {
			ctx.fillStyle = css.backgroundColor;
			ctx.fillRect(x, y, r.width, r.height);
			continue;
		}
		ctx.fillStyle = css.color;
		ctx.font = css.font;
		ctx.textBaseline = 'middle';
		ctx.fillText(el.textContent, x + parseFloat(css.paddingLeft || '0'), y + r.height / 2);
	}
	return c;
}
