// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * plots.js - the dashboard's charts, thin wrappers around the vendored uPlot.
 *
 * TimePlot: values against simulated time (uPlot's ordinary mode, shared x).
 * XYPlot:   curves in the plane (uPlot's mode 2, one [xs, ys] pair per
 *           series) drawn as polylines in data order, so a closed orbit
 *           stays closed; optional equal scaling keeps its true shape and so
 *           its direction.
 * Each plot resizes with its container and records how many points it
 * drew in data-points, and a time plot the latest time it drew in data-t-end,
 * on the container (the browser test reads both). Each has a PNG and a CSV
 * export under it, shown once it has something to export.
 */

import uPlot from '../vendor/uplot/uPlot.esm.js';
import { tickText } from './format.js';

export const PALETTE = ['#2563eb', '#dc2626', '#059669', '#d97706', '#7c3aed',
	'#0891b2', '#db2777', '#65a30d', '#475569', '#b45309'];

const AXIS = {
	stroke: '#475569',
	grid: { stroke: '#e2e8f0', width: 1 },
	ticks: { stroke: '#cbd5e1', width: 1 },
	font: '11px system-ui, sans-serif',
	labelFont: '600 11px system-ui, sans-serif',
	/* every tick with the decimals its step needs (uPlot's own text keeps
	 * at most three, so a 0.0025 step read 157.028, 157.03, 157.033) */
	values: (u, splits, axisIdx, space, step) => splits.map(v => (v == null ? '' : tickText(v, step))),
};

function axis(label, extra = {}) {
	return { ...AXIS, label, labelSize: 18, ...extra };
}

/* Auto range with a fallback, so that an empty plot still draws its axes. */
function autoRange(u, min, max) {
	if (min == null || max == null || !Number.isFinite(min) || !Number.isFinite(max)) return [0, 1];
	return uPlot.rangeNum(min, max, 0.1, true);
}

/* Save blob under name through a temporary download link (also auth.js's
 * downloads of the API's files). */
export function saveBlob(blob, name) {
	const a = document.createElement('a');
	a.href = URL.createObjectURL(blob);
	a.download = name;
	document.body.append(a);
	a.click();
	a.remove();
	setTimeout(() => URL.revokeObjectURL(a.href), 5000);
}

/* numbers as the daemon sent them (the shortest text that reads back as
 * the same double); the page's own times are on its grid (onGrid) */
const cell = v => (typeof v === 'number' ? (Number.isFinite(v) ? String(v) : '')
	: /[",\n]/.test(String(v)) ? `"${String(v).replace(/"/g, '""')}"` : String(v ?? ''));
export const csvText = rows => rows.map(r => r.map(cell).join(',')).join('\n') + '\n';

/* PNG and CSV buttons under a plot's container; the owner gives csvRows()
 * and either its uPlot (plot) or canvas(), a canvas to save (the study
 * map's); named after the container (plot-rotor: rotor, sweep-map:
 * sweep-map). Hidden until the owner shows it. */
export function addExport(owner, el) {
	const bar = document.createElement('div');
	bar.className = 'plot-export';
	bar.hidden = true;
	const name = (el.id || 'plot').replace(/^plot-/, '');
	for (const kind of ['png', 'csv']) {
		const b = document.createElement('button');
		b.type = 'button';
		b.className = 'link';
		b.dataset.export = kind;
		b.textContent = kind === 'png' ? 'PNG' : 'CSV';
		b.title = kind === 'png' ? 'this plot as an image' : 'the data of this plot';
		b.addEventListener('click', () => {
			if (kind === 'csv') return saveBlob(new Blob([csvText(owner.csvRows())], { type: 'text/csv' }), `${name}.csv`);
			const src = owner.canvas ? owner.canvas() : owner.plot.ctx.canvas;
			const c = document.createElement('canvas');
			c.width = src.width;
			c.height = src.height;
			const ctx = c.getContext('2d');
			ctx.fillStyle = '#fff';
			ctx.fillRect(0, 0, c.width, c.height);
			ctx.drawImage(src, 0, 0);
			c.toBlob(blob => saveBlob(blob, `${name}.png`), 'image/png');
		});
		bar.append(b);
	}
	bar.prepend(Object.assign(document.createElement('span'), { textContent: 'Export: ' }));
	bar.append(dataTable(owner, el));
	el.after(bar);
	return bar;
}

/* The text alternative of a plot's canvas: the plot named after its card's
 * title (role img), and a "Data table" disclosure (keyboard-reachable
 * through its summary) whose table, of the same rows as the CSV (the last
 * 500), is filled each time it opens. */
const DATA_ROWS = 500;
function dataTable(owner, el) {
	const title = el.closest('.card')?.querySelector('h3')?.firstChild?.textContent?.trim() || el.id;
	el.setAttribute('role', 'img');
	el.setAttribute('aria-label', `${title} (plot; its data: the Data table below)`);
	const d = document.createElement('details');
	d.className = 'plot-data';
	d.append(Object.assign(document.createElement('summary'), { textContent: 'Data table' }));
	const wrap = Object.assign(document.createElement('div'), { className: 'table-scroll' });
	const table = Object.assign(document.createElement('table'), { className: 'table' });
	table.setAttribute('aria-label', `${title}: data`);
	wrap.append(table);
	d.append(wrap);
	d.addEventListener('toggle', () => {
		if (!d.open) return;
		const [head = [], ...rows] = owner.csvRows();
		table.replaceChildren();
		const tr = table.createTHead().insertRow();
		for (const h of head) tr.append(Object.assign(document.createElement('th'), { textContent: h, scope: 'col' }));
		const body = table.createTBody();
		for (const r of rows.slice(-DATA_ROWS)) {
			const row = body.insertRow();
			for (const c of r) row.insertCell().textContent = typeof c === 'number' ? (Number.isFinite(c) ? String(c) : '') : String(c ?? '');
		}
	});
	return d;
}

function sizeOf(el, aspect) {
	const w = Math.max(200, Math.floor(el.clientWidth || 400));
	const h = Math.max(140, Math.floor(aspect ? w * aspect : (el.clientHeight || 220)));
	return { width: w, height: h };
}

/* The plotting area's box on the container, as CSS variables: an empty
 * plot's text (.plot.empty::after) sits there, inside the axes, so that it
 * never covers a tick label however narrow the plot. */
function placeEmpty(el, plot) {
	const r = el.getBoundingClientRect(), o = plot.over.getBoundingClientRect();
	if (!o.width) return;
	el.style.setProperty('--over-left', `${o.left - r.left}px`);
	el.style.setProperty('--over-top', `${o.top - r.top}px`);
	el.style.setProperty('--over-width', `${o.width}px`);
	el.style.setProperty('--over-height', `${o.height}px`);
}

function observe(el, plot, aspect, legendRoom) {
	const ro = new ResizeObserver(() => {
		const s = sizeOf(el, aspect);
		if (Math.abs(s.width - plot.width) > 2) plot.setSize({ width: s.width, height: s.height - legendRoom });
		requestAnimationFrame(() => placeEmpty(el, plot));
	});
	ro.observe(el);
	requestAnimationFrame(() => placeEmpty(el, plot));
	return ro;
}

export class TimePlot {
	/* series: [{label, color, scale ('y' or 'y2'), width, dash}];
	 * axes: {y: label, y2: label (optional)}; aspect = height / width. */
	constructor(el, { series, yLabel, y2Label, aspect = 0.7, xLabel = 't / s', yRange, y2Range, legend = true }) {
		this.el = el;
		this.markers = [];
		const self = this;
		const s = sizeOf(el, aspect);
		const legendRoom = legend ? 26 : 0;
		const scales = { x: { time: false } };
		scales.y = { range: yRange ?? autoRange };
		if (y2Label) scales.y2 = { range: y2Range ?? autoRange };
		this.labels = [xLabel, ...series.map(d => d.label)];
		/* the left axis's ticks as drawn, on the container (the browser test reads them) */
		const yValues = (u, splits, ai, space, step) => {
			const t = AXIS.values(u, splits, ai, space, step);
			el.dataset.yTicks = t.join(' ');
			return t;
		};
		const axes = [axis(xLabel, { size: 34 }), axis(yLabel, { size: 66, space: 24, values: yValues })];
		if (y2Label) axes.push(axis(y2Label, { scale: 'y2', side: 1, size: 50, space: 24, grid: { show: false } }));
		this.plot = new uPlot({
			width: s.width,
			height: s.height - legendRoom,
			scales,
			axes,
			legend: { show: legend, live: false },
			cursor: { drag: { x: false, y: false }, points: { size: 5 } },
			hooks: { draw: [u => drawMarkers(u, self.markers)] },
			series: [{ label: 't / s', value: (u, v) => v == null ? '–' : v.toFixed(3) },
				...series.map((d, i) => ({
					label: d.label,
					stroke: d.color ?? PALETTE[i % PALETTE.length],
					width: d.width ?? 1.5,
					dash: d.dash ?? DASHES[Math.floor(i / PALETTE.length) % DASHES.length],
					scale: d.scale ?? 'y',
					spanGaps: true,
					points: { show: false },
					value: (u, v) => v == null ? '–' : fmtVal(v),
				}))],
		}, [[], ...series.map(() => [])], el);
		this.ro = observe(el, this.plot, aspect, legendRoom);
		el.dataset.points = '0';
		el.classList.add('empty');
		this.bar = addExport(this, el);
	}

	/* The plotted data as rows, the labels first. */
	csvRows() {
		const d = this.plot.data;
		return [this.labels, ...d[0].map((t, i) => d.map(c => c[i]))];
	}

	setData(cols) {
		this.plot.setData(cols);
		const n = cols[0].length;
		this.el.dataset.points = String(n);
		/* the latest time drawn: it advances while samples arrive, even when
		 * a "history" trace thins and the point count drops */
		this.el.dataset.tEnd = n ? String(cols[0][n - 1]) : '';
		this.el.classList.toggle('empty', n === 0);
		this.bar.hidden = n === 0;
	}

	/* Vertical marker lines [{x, label, color}] (x in s). */
	setMarkers(list) {
		this.markers = list.filter(m => Number.isFinite(m.x));
		this.plot.redraw(false);
	}

	destroy() {
		this.ro.disconnect();
		this.plot.destroy();
		this.bar.remove();
	}
}

/* Line styles after the palette's colours run out: distinct columns stay
 * distinguishable. */
const DASHES = [undefined, [6, 3], [2, 2], [8, 3, 2, 3]];

function drawMarkers(u, markers) {
	if (!markers.length) return;
	const ctx = u.ctx;
	const { left, top, width, height } = u.bbox;
	ctx.save();
	ctx.font = `${11 * uPlot.pxRatio}px system-ui, sans-serif`;
	ctx.textBaseline = 'top';
	for (const m of markers) {
		const x = u.valToPos(m.x, 'x', true);
		if (x < left || x > left + width) continue;
		ctx.strokeStyle = ctx.fillStyle = m.color ?? '#475569';
		ctx.lineWidth = uPlot.pxRatio;
		ctx.setLineDash([4 * uPlot.pxRatio, 3 * uPlot.pxRatio]);
		ctx.beginPath();
		ctx.moveTo(x, top);
		ctx.lineTo(x, top + height);
		ctx.stroke();
		if (m.label) ctx.fillText(m.label, x + 4 * uPlot.pxRatio, top + 4 * uPlot.pxRatio + (m.row ?? 0) * 14 * uPlot.pxRatio);
	}
	ctx.restore();
}

function fmtVal(v) {
	const a = Math.abs(v);
	if (a !== 0 && (a < 1e-3 || a >= 1e5)) return v.toExponential(3);
	return v.toPrecision(4);
}

/* A polyline through the finite points of series sidx (data order; none
 * when line is false: measured points are not joined), with optional
 * round markers and vertical error bars y ± errs(sidx)[i] (errs returns an
 * array or nothing). Returns uPlot's path object. */
function polylinePaths(markers, errs, line = true) {
	return (u, sidx) => {
		const [xs, ys] = u.data[sidx];
		const s = u.series[sidx];
		const xk = s.facets[0].scale, yk = s.facets[1].scale;
		const path = new Path2D();
		let pen = false;
		const r = 3 * uPlot.pxRatio;
		for (let i = 0; line && i < xs.length; i++) {
			const x = xs[i], y = ys[i];
			if (x == null || y == null || !Number.isFinite(x) || !Number.isFinite(y)) { pen = false; continue; }
			const X = u.valToPos(x, xk, true), Y = u.valToPos(y, yk, true);
			if (pen) path.lineTo(X, Y); else path.moveTo(X, Y);
			pen = true;
		}
		if (markers) {
			for (let i = 0; i < xs.length; i++) {
				const x = xs[i], y = ys[i];
				if (x == null || y == null || !Number.isFinite(x) || !Number.isFinite(y)) continue;
				const X = u.valToPos(x, xk, true), Y = u.valToPos(y, yk, true);
				path.moveTo(X + r, Y);
				path.arc(X, Y, r, 0, 2 * Math.PI);
				path.moveTo(X, Y);
			}
		}
		const es = errs?.(sidx);
		for (let i = 0; es && i < xs.length; i++) {
			const x = xs[i], y = ys[i], e = es[i];
			if (x == null || y == null || !Number.isFinite(x) || !Number.isFinite(y) || !(e > 0)) continue;
			const X = u.valToPos(x, xk, true);
			const Y0 = u.valToPos(y - e, yk, true), Y1 = u.valToPos(y + e, yk, true);
			path.moveTo(X, Y0);
			path.lineTo(X, Y1);
			path.moveTo(X - r, Y0);
			path.lineTo(X + r, Y0);
			path.moveTo(X - r, Y1);
			path.lineTo(X + r, Y1);
			path.moveTo(X, Y1);
		}
		return { stroke: path, fill: null, clip: null, band: null, gaps: null, flags: 0 };
	};
}

/* A shaded band y ± errs(sidx)[i] along the series' points (a run of
 * finite points is one polygon), for a series drawn as a band. Returns
 * uPlot's path object: nothing stroked, the polygon filled. */
function bandPaths(errs) {
	return (u, sidx) => {
		const [xs, ys] = u.data[sidx];
		const s = u.series[sidx];
		const xk = s.facets[0].scale, yk = s.facets[1].scale;
		const es = errs(sidx) || [];
		const fill = new Path2D();
		const ok = i => Number.isFinite(xs[i]) && Number.isFinite(ys[i]) && es[i] >= 0;
		for (let i = 0; i < xs.length;) {
			if (!ok(i)) { i++; continue; }
			let j = i;
			while (j + 1 < xs.length && ok(j + 1)) j++;
			for (let k = i; k <= j; k++) {
				const X = u.valToPos(xs[k], xk, true), Y = u.valToPos(ys[k] + es[k], yk, true);
				if (k === i) fill.moveTo(X, Y); else fill.lineTo(X, Y);
			}
			for (let k = j; k >= i; k--) fill.lineTo(u.valToPos(xs[k], xk, true), u.valToPos(ys[k] - es[k], yk, true));
			fill.closePath();
			i = j + 1;
		}
		return { stroke: new Path2D(), fill, clip: null, band: null, gaps: null, flags: 0 };
	};
}

/* Axis ranges over every finite x and y of the data (y ± its error bar
 * where errs[i - 1] gives one). */
export function extent(data, errs = []) {
	let x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
	for (let i = 1; i < data.length; i++) {
		const [xs, ys] = data[i];
		const es = errs[i - 1];
		for (let j = 0; j < xs.length; j++) {
			const x = xs[j], y = ys[j];
			if (x == null || y == null || !Number.isFinite(x) || !Number.isFinite(y)) continue;
			const e = es && es[j] > 0 ? es[j] : 0;
			if (x < x0) x0 = x; if (x > x1) x1 = x;
			if (y - e < y0) y0 = y - e; if (y + e > y1) y1 = y + e;
		}
	}
	return { x0, x1, y0, y1 };
}

/* Ranges for equal scaling: both axes get the same units per pixel, the
 * larger of the two spans (padded by `pad`) decides. w, h: plot box px. */
export function equalRanges(ext, w, h, pad = 0.12, minSpan = 1e-9) {
	if (!Number.isFinite(ext.x0)) return { x: [-1, 1], y: [-1, 1] };
	const cx = (ext.x0 + ext.x1) / 2, cy = (ext.y0 + ext.y1) / 2;
	const unitsPerPx = Math.max((ext.x1 - ext.x0) / w, (ext.y1 - ext.y0) / h, minSpan / Math.min(w, h)) * (1 + 2 * pad);
	const hx = unitsPerPx * w / 2, hy = unitsPerPx * h / 2;
	return { x: [cx - hx, cx + hx], y: [cy - hy, cy + hy] };
}

function padRange(min, max, pad = 0.08) {
	if (!Number.isFinite(min) || !Number.isFinite(max)) return [-1, 1];
	if (max - min < 1e-12) { const d = Math.abs(max) * 0.1 || 1; return [min - d, max + d]; }
	const d = (max - min) * pad;
	return [min - d, max + d];
}

export class XYPlot {
	/* series: [{label, color, line, band}] (line: false draws the points
	 * alone; band: true shades y ± the error bars instead, in fill);
	 * equal: keep aspect 1:1 in data units; markers: draw a dot per point;
	 * zeroLine: draw y = 0; yShort: the y label where yLabel does not fit.
	 * The legend lists only the series that have points. */
	constructor(el, { series, xLabel, yLabel, yShort, aspect = 0.75, equal = false, markers = false, zeroLine = false, xRange, emptyX }) {
		this.el = el;
		this.equal = equal;
		this.xRange = xRange;
		this.emptyX = emptyX; /* the x axis of an empty plot (β: 0…180), not −1…1 */
		this.errs = [];
		this.labels = [xLabel, yLabel, series.map(d => d.label)];
		this.legend = series.length > 1;
		this.joined = series.map(d => d.line !== false); /* which series are lines, which points */
		const s = sizeOf(el, aspect);
		const legend = series.length > 1;
		const legendRoom = legend ? 26 : 0;
		this.ext = extent([]);
		const self = this;
		const rangeFn = axisKey => (u, min, max) => {
			if (self.equal) {
				const r = equalRanges(self.ext, u.bbox.width || 300, u.bbox.height || 200);
				return r[axisKey];
			}
			if (axisKey === 'x' && self.xRange) return self.xRange;
			const e = self.ext;
			if (axisKey === 'x' && self.emptyX && !Number.isFinite(e.x0)) return self.emptyX;
			return axisKey === 'x' ? padRange(e.x0, e.x1, 0.05) : padRange(Math.min(e.y0, zeroLine ? 0 : e.y0), Math.max(e.y1, zeroLine ? 0 : e.y1));
		};
		/* yLabel where it fits the plot's height, else yShort (400 px wide cut it at both ends) */
		const text = Object.assign(document.createElement('canvas').getContext('2d'), { font: AXIS.labelFont });
		const yText = yShort ? u => (text.measureText(yLabel).width <= u.bbox.height / uPlot.pxRatio ? yLabel : yShort) : yLabel;
		const hooks = {};
		if (zeroLine) {
			hooks.drawAxes = [u => {
				const ctx = u.ctx;
				const y = u.valToPos(0, 'y', true);
				if (y < u.bbox.top || y > u.bbox.top + u.bbox.height) return;
				ctx.save();
				ctx.strokeStyle = '#94a3b8';
				ctx.lineWidth = uPlot.pxRatio;
				ctx.beginPath();
				ctx.moveTo(u.bbox.left, y);
				ctx.lineTo(u.bbox.left + u.bbox.width, y);
				ctx.stroke();
				ctx.restore();
			}];
		}
		this.plot = new uPlot({
			mode: 2,
			width: s.width,
			height: s.height - legendRoom,
			legend: { show: legend, live: false },
			cursor: { show: false, drag: { x: false, y: false } },
			scales: { x: { time: false, range: rangeFn('x') }, y: { range: rangeFn('y') } },
			axes: [axis(xLabel, { size: 34 }), axis(yText, { size: 66, space: 24 })],
			hooks,
			series: [{}, ...series.map((d, i) => ({
				label: d.label,
				stroke: d.color ?? PALETTE[i % PALETTE.length],
				width: d.width ?? 1.5,
				facets: [{ scale: 'x', auto: true }, { scale: 'y', auto: true }],
				paths: d.band ? bandPaths(sidx => self.errs[sidx - 1])
					: polylinePaths(markers || d.line === false, sidx => self.errs[sidx - 1], d.line !== false),
				...(d.band ? { fill: d.fill, width: 0 } : {}),
				points: { show: false },
			}))],
		}, [null, ...series.map(() => [[], []])], el);
		if (this.legend) this.showLegend(series.map(() => false));
		this.ro = observe(el, this.plot, aspect, legendRoom);
		el.dataset.points = '0';
		el.classList.add('empty');
		this.bar = addExport(this, el);
	}

	/* The plotted points as rows: series, x, y (and its error bar). */
	csvRows() {
		const [xLabel, yLabel, names] = this.labels;
		const withErr = this.errs.some(e => e && e.length);
		const rows = [['series', xLabel, yLabel, ...(withErr ? ['error'] : [])]];
		this.plot.data.slice(1).forEach(([xs, ys], k) => xs.forEach((x, i) => {
			if (Number.isFinite(x) && Number.isFinite(ys[i]))
				rows.push([names[k], x, ys[i], ...(withErr ? [this.errs[k]?.[i] ?? NaN] : [])]);
		}));
		return rows;
	}

	/* pairs: one [xs, ys] per series; errs (optional): one array of error
	 * bars per series, drawn as y ± err. */
	setData(pairs, errs = []) {
		const data = [null, ...pairs];
		this.errs = errs;
		this.ext = extent(data, errs);
		this.plot.setData(data);
		let n = 0;
		const shown = [];
		for (const [xs, ys] of pairs) {
			let m = 0;
			for (let i = 0; i < xs.length; i++) if (Number.isFinite(xs[i]) && Number.isFinite(ys[i])) m++;
			shown.push(m > 0);
			n += m;
		}
		if (this.legend) this.showLegend(shown);
		this.el.dataset.points = String(n);
		this.el.classList.toggle('empty', n === 0);
		this.bar.hidden = n === 0;
	}

	/* The legend's entry of each series only while it has points: an empty
	 * plot lists none (it draws none). */
	showLegend(shown) {
		const names = this.labels[2];
		for (const row of this.plot.root.querySelectorAll('.u-legend .u-series')) {
			const k = names.indexOf(row.querySelector('.u-label')?.textContent);
			if (k >= 0) row.style.display = shown[k] ? '' : 'none';
		}
	}

	destroy() {
		this.ro.disconnect();
		this.plot.destroy();
		this.bar.remove();
	}
}
