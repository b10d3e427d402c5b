// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * live.js - the attached session's stream: samples into the bounded
 * traces (series.js) behind the live plots, control events into the
 * footer, and the transport velocity the page shows. Marks the page dirty;
 * draw.js redraws.
 */

import { Trace, recentVelocity } from './series.js';
import { fmt, fmtTime, rotationLabel, onGrid } from './format.js';
import { app, $ } from './ui.js';
import { buildFeedPlot } from './figures.js';

export const MM = 1000; /* m -> mm */

export function resetTraces(columns) {
	const K = Number.isFinite(columns) && columns > 0 ? columns : 0;
	app.columns = K;
	app.traces = {
		orbit: new Trace(2, { policy: 'window', span: 0.12, capacity: 3000 }),
		strokes: new Trace(2, { policy: 'window', span: 0.25, capacity: 4000 }),
		trough: new Trace(2, { policy: 'window', span: 0.25, capacity: 4000 }),
		rotor: new Trace(2, { policy: 'history', capacity: 3000 }),
		rotorPeriod: { t0: NaN, t: 0, sum: 0, n: 0 },
		feed: new Trace(K, { policy: 'history', capacity: 3000 }),
		feedMean: new Trace(1, { policy: 'window', span: 2, capacity: 20000 }),
	};
	buildFeedPlot(K);
	app.dirty = true;
}

export function onSample(s) {
	const tr = app.traces;
	if (!tr || !Number.isFinite(s.t)) return;
	app.samples++;
	if (s.columns.length && s.columns.length !== app.columns) {
		resetTraces(s.columns.length);
		return onSample(s);
	}
	const omega = Number.isFinite(s.rotorSpeed) ? Math.abs(s.rotorSpeed) : Math.abs(app.session?.rotorSpeed);
	if (omega > 1) {
		/* show about three excitation periods */
		const span = Math.min(1, Math.max(0.03, 3 * 2 * Math.PI / omega));
		tr.orbit.span = span;
		tr.strokes.span = tr.trough.span = Math.min(2, 2 * span);
	}
	if (s.deck.length === 2) tr.orbit.push(s.t, [s.deck[0] * MM, s.deck[1] * MM]);
	if (s.strokes.length) tr.strokes.push(s.t, [s.strokes[0] * MM, s.strokes[1] * MM]);
	if (s.trough.length >= 2) tr.trough.push(s.t, [s.trough[0] * MM, s.trough[1] * MM]);
	const beta = Number.isFinite(s.beta) ? s.beta : app.session?.beta;
	pushRotor(tr, s.t, s.rotorSpeed, beta, omega);
	if (s.columns.length) tr.feed.push(s.t, s.columns.map(x => x * MM));
	if (Number.isFinite(s.feedMean)) tr.feedMean.push(s.t, [s.feedMean]);
	if (app.experiment && app.experiment.sessionId === app.id && app.expTrace)
		app.expTrace.push(s.t, [s.feedVelocity, beta]);
	app.lastSample = s;
	app.dirty = true;
}

/* The rotor speed as its mean over each excitation period (at most 0.1 s
 * while it runs up), so the ripple at the excitation frequency does not
 * fill the plot and hide beta; beta as it is at the period's end. */
function pushRotor(tr, t, speed, beta, omega) {
	const p = tr.rotorPeriod;
	if (!Number.isFinite(speed)) { tr.rotor.push(t, [null, beta]); return; }
	if (!Number.isFinite(p.t0)) Object.assign(p, { t0: t, t: t, sum: 0, n: 0 });
	p.sum += speed;
	p.n++;
	p.t = t;
	const period = omega > 1 ? Math.min(0.1, 2 * Math.PI / omega) : 0.1;
	if (t - p.t0 >= period * (1 - 1e-9)) {
		tr.rotor.push(onGrid((p.t0 + t) / 2), [p.sum / p.n, beta]);
		Object.assign(p, { t0: t, sum: 0, n: 0 });
	}
}

export function onControl(c) {
	app.controls.push(c);
	const parts = [];
	if (Number.isFinite(c.beta)) parts.push(`β → ${fmt(c.beta, 1)}°`);
	if (c.rotation) parts.push(`rotation ${rotationLabel(c.rotation)}`);
	if (c.running !== undefined) parts.push(c.running ? 'resumed' : 'paused');
	if (Number.isFinite(c.omegaSs)) parts.push(`ω_ss ${fmt(c.omegaSs, 2)} rad/s`);
	if (parts.length) $('#live-state').textContent = `control at t = ${fmtTime(c.t)}: ${parts.join(', ')}`;
	app.dirty = true;
}

/* The transport velocity shown: the slope of the mean feed displacement
 * over the last half second of the stream (or ten periods, if longer),
 * else the daemon's running estimate. */
export function currentVelocity() {
	if (app.session?.feed === false) return NaN;
	const [ts, xs] = app.traces?.feedMean.data() ?? [[], []];
	const omega = Math.abs(app.lastSample?.rotorSpeed ?? app.session?.rotorSpeed ?? NaN);
	const span = omega > 1 ? Math.max(0.5, 10 * 2 * Math.PI / omega) : 0.5;
	const v = recentVelocity(ts, xs, Math.min(span, 2), 0.2);
	return Number.isFinite(v) ? v : app.session?.transportVelocity ?? NaN;
}
