// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * figures.js - the page's plots: which plot shows what, with its series,
 * labels and axes (plots.js draws them), and the schematic. The feed plot
 * is rebuilt when the number of columns changes.
 */

import { TimePlot, XYPlot, PALETTE } from './plots.js';
import { Schematic } from './schematic.js';
import { app, $, numberOf } from './ui.js';

export function makePlots() {
	app.plots.orbit = new XYPlot($('#plot-orbit'), {
		series: [{ label: 'deck point', color: PALETTE[0], width: 1.75 }],
		xLabel: 'horizontal displacement x / mm', yLabel: 'vertical displacement y / mm',
		equal: true, aspect: 0.78,
	});
	app.plots.rotor = new TimePlot($('#plot-rotor'), {
		series: [{ label: 'rotor speed / (rad/s)', color: PALETTE[0] }, { label: 'β / °', color: PALETTE[3], scale: 'y2' }],
		yLabel: 'rotor speed / (rad/s)', y2Label: 'β / °', y2Range: [0, 180],
	});
	buildStrokesPlot(false);
	app.plots.trough = new TimePlot($('#plot-trough'), {
		series: [{ label: 'x / mm', color: PALETTE[0] }, { label: 'y / mm', color: PALETTE[1] }],
		yLabel: 'displacement / mm',
	});
	buildFeedPlot(0);
	app.schematic = new Schematic($('#schematic'));
	app.schematic.update({ beta: numberOf($('#session-form').elements.beta), rotation: 'cw', columns: 5, layers: 8 });
	/* a fit's bands first (band_from_fit), under the curves */
	app.plots.sweep = new XYPlot($('#plot-sweep'), {
		series: [{ label: '95 % band cw', color: PALETTE[0], band: true, fill: 'rgba(148, 163, 184, 0.3)' },
			{ label: '95 % band ccw', color: PALETTE[1], band: true, fill: 'rgba(203, 213, 225, 0.35)' },
			{ label: 'clockwise', color: PALETTE[0] }, { label: 'counter-clockwise', color: PALETTE[1] }],
		xLabel: 'β / °', yLabel: 'transport velocity v / (m/s)', yShort: 'v / (m/s)', markers: true, zeroLine: true, aspect: 0.5, emptyX: [0, 180],
	});
	/* the bands first, so that the curves and data are drawn over them */
	app.plots.fit = new XYPlot($('#plot-fit'), {
		series: [{ label: '95 % band cw', color: PALETTE[2], band: true, fill: 'rgba(148, 163, 184, 0.3)' },
			{ label: '95 % band ccw', color: PALETTE[4], band: true, fill: 'rgba(203, 213, 225, 0.35)' },
			{ label: 'data cw', color: PALETTE[0], line: false }, { label: 'fitted cw', color: PALETTE[2] },
			{ label: 'original cw', color: '#94a3b8' }, { label: 'data ccw', color: PALETTE[1], line: false },
			{ label: 'fitted ccw', color: PALETTE[4] }, { label: 'original ccw', color: '#cbd5e1' }],
		xLabel: 'β / °', yLabel: 'transport velocity v / (m/s)', yShort: 'v / (m/s)', zeroLine: true, aspect: 0.5, emptyX: [0, 180],
	});
	app.plots.experiment = new TimePlot($('#plot-experiment'), {
		series: [{ label: 'feed velocity / (m/s)', color: PALETTE[0] }, { label: 'β / °', color: PALETTE[3], scale: 'y2' }],
		yLabel: 'v / (m/s)', y2Label: 'β / °', y2Range: [0, 180], aspect: 0.5,
	});
	/* a closed loop: v and its setpoint on the left axis, β on the right */
	app.plots.loop = new TimePlot($('#plot-loop'), {
		series: [{ label: 'v / (m/s)', color: PALETTE[0] }, { label: 'setpoint / (m/s)', color: PALETTE[1], dash: [6, 3] },
			{ label: 'β / °', color: PALETTE[3], scale: 'y2' }],
		yLabel: 'v / (m/s)', y2Label: 'β / °', aspect: 0.5,
	});
	/* an identification: the measured response and the fitted model over it */
	app.plots.ident = new TimePlot($('#plot-ident'), {
		series: [{ label: 'measured v / (m/s)', color: PALETTE[0] }, { label: 'fitted FOPDT / (m/s)', color: PALETTE[1], width: 2 },
			{ label: 'β / °', color: PALETTE[3], scale: 'y2' }],
		yLabel: 'v / (m/s)', y2Label: 'β / °', aspect: 0.5,
	});
	/* the two share a card: each named for what it draws */
	$('#plot-loop').setAttribute('aria-label', 'Closed loop: v, setpoint and β against time (plot; its data: the Data table below)');
	$('#plot-ident').setAttribute('aria-label', 'Identification: measured and fitted v against time (plot; its data: the Data table below)');
}

/* The strokes plot; alike: both eliminators move the same (the symmetric
 * machine), drawn as one line with a note saying so, as the feed plot does. */
export function buildStrokesPlot(alike) {
	if (app.plots.strokes && app.plots.strokesAlike === alike) return;
	app.plots.strokes?.destroy();
	const series = alike ? [{ label: 's₁ = s₂ / mm (identical)', color: PALETTE[4] }]
		: [{ label: 's₁ / mm', color: PALETTE[4] }, { label: 's₂ / mm', color: PALETTE[5] }];
	app.plots.strokes = new TimePlot($('#plot-strokes'), { series, yLabel: 'stroke / mm' });
	app.plots.strokesAlike = alike;
	const note = $('#strokes-note');
	note.hidden = !alike;
	note.textContent = alike ? 'Both eliminators move identically (a symmetric machine), so one line stands for s₁ and s₂.' : '';
}

/* The feed plot for K columns; alike: every column moves the same (the
 * symmetric machine's columns), drawn as one line with a note saying so. */
export function buildFeedPlot(K, alike = false) {
	const el = $('#plot-feed');
	alike = alike && K > 1;
	if (app.plots.feed && app.plots.feedK === K && app.plots.feedAlike === alike) return;
	app.plots.feed?.destroy();
	const series = !K ? [{ label: 'columns', color: '#94a3b8' }]
		: alike ? [{ label: `columns 1–${K} (identical)` }]
			: Array.from({ length: K }, (_, k) => ({ label: `column ${k + 1}` }));
	app.plots.feed = new TimePlot(el, { series, yLabel: 'displacement / mm' });
	app.plots.feedK = K;
	app.plots.feedAlike = alike;
	const note = $('#feed-note');
	note.hidden = !alike;
	note.textContent = alike ? `All ${K} columns move identically (a symmetric machine: the engine computes one representative column), so one line stands for all ${K}.` : '';
}
