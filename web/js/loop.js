// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * loop.js - the closed-loop and identification panel (docs/control.md):
 * runs a fresh session of the new-session form's model with a PI loop on
 * beta over a setpoint list, or with beta steps around operating points,
 * and shows per setpoint the settling time, overshoot, IAE and steady
 * error with v, setpoint and beta on one time axis; per operating point
 * the fitted gain, time constant and dead time with their standard errors
 * and the fitted response over the measured one. v(t) is the feed's mean
 * velocity over each excitation period from the session's recorded
 * trajectory (api-loop.js periodVelocity), as the daemon samples it.
 * Its Stop button (stop.js) ends a run.
 */

import * as api from './api.js';
import { fmt, fmtGiven, fmtSig, fmtPm, fmtTime } from './format.js';
import { app, $, $$, report, setOnline, numberOf, busy, progress } from './ui.js';
import { readSessionForm } from './session.js';
import { stopButton, experimentEnded } from './stop.js';

function readLoopForm() {
	const f = $('#loop-form').elements;
	return {
		...readSessionForm(),
		kind: f.kind.value, setpoints: f.setpoints.value, controller: f.controller.value,
		kp: numberOf(f.kp), ki: numberOf(f.ki), disturbances: f.disturbances.value,
		points: f.points.value, step: numberOf(f.step), hold: numberOf(f.hold),
	};
}

/* The fields and the plot of the kind chosen; kp and ki only for given gains. */
function showKind() {
	const f = $('#loop-form').elements;
	const kind = f.kind.value;
	for (const el of $$('#loop-form .loop-fields')) el.hidden = el.dataset.kind !== kind;
	f.kp.disabled = f.ki.disabled = f.controller.value !== 'pi';
	$('#loop-plot-control').hidden = kind !== 'control';
	$('#loop-plot-identify').hidden = kind !== 'identify';
}

let follow = null; /* polls a run until it ends or is stopped (stop.js) */

export function wireLoop() {
	const f = $('#loop-form').elements;
	f.kind.addEventListener('change', showKind);
	f.controller.addEventListener('change', showKind);
	$('#loop-form').addEventListener('submit', runLoop);
	follow = stopButton('#loop-stop', '#loop-progress');
	showKind();
}

async function runLoop(ev) {
	ev.preventDefault();
	const form = readLoopForm();
	const btn = $('#loop-run'), box = $('#loop-progress');
	busy(btn, true);
	$('#loop-downloads').hidden = true;
	try {
		const j = await api.createLoopExperiment(form);
		setOnline(true);
		app.loop = { id: j.id, sessionId: j.sessionId, kind: j.kind, done: false };
		progress(box, 0, 'started');
		showLoop(j);
		const end = await follow(j, api.getLoopExperiment, u => {
			showLoop(u);
			const tText = Number.isFinite(u.t) ? ` · t = ${fmtTime(u.t)}` : '';
			progress(box, u.progress, `${u.state || 'running'}${tText}`);
		});
		if (!end) return; /* stopped: stop.js said so */
		const traj = end.sessionId ? await api.trajectory(end.sessionId).catch(() => null) : null;
		showLoop(end, traj);
		const csv = $('#loop-csv'), trajLink = $('#loop-traj');
		csv.href = api.experimentCsvUrl(end.id);
		csv.download = `experiment-${end.id}.csv`;
		if (end.sessionId) {
			trajLink.href = api.trajectoryUrl(end.sessionId, 'csv');
			trajLink.download = `experiment-${end.id}-trajectory.csv`;
		}
		trajLink.hidden = !end.sessionId;
		$('#loop-downloads').hidden = false;
		app.loop.done = true;
		experimentEnded(end);
	} catch (err) {
		report(err, 'Experiment', $('#loop-form'), FIELD_INPUT);
	} finally {
		busy(btn, false);
	}
}

/* The input behind a refused member that report() does not find by its
 * path: control.setpoint[1].v is the setpoints text, disturbances[0]
 * the disturbances text, identify.beta the operating points. */
const FIELD_INPUT = [[/^control\.setpoint/, 'setpoints'], [/^disturbances/, 'disturbances'], [/^identify\.beta/, 'points']];

function showLoop(j, traj) {
	$('#loop-plot-control').hidden = j.kind !== 'control';
	$('#loop-plot-identify').hidden = j.kind !== 'identify';
	$('#loop-gains-box').hidden = true;
	if (j.kind === 'identify') {
		identTable(j);
		if (traj) plotIdent(j, traj);
	} else {
		controlTable(j);
		if (traj) plotControl(j, traj);
	}
}

function fillTable(head, rows) {
	const table = $('#loop-table');
	table.replaceChildren();
	const tr = table.createTHead().insertRow();
	for (const h of head) tr.append(Object.assign(document.createElement('th'), { textContent: h, scope: 'col' }));
	const body = table.createTBody();
	for (const r of rows) {
		const row = body.insertRow();
		for (const c of r) row.insertCell().textContent = c;
	}
}

/* The text of a closed loop's result cells (the browser test formats the
 * API's values the same way). */
export const loopCells = (sp, beta, i) => [String(i + 1), fmtGiven(sp.v), fmt(beta, 1),
	fmt(sp.settlingTime, 3), fmt(100 * sp.overshoot, 1), fmtSig(sp.iae, 3), fmt(100 * sp.steadyError, 2)];

function controlTable(j) {
	const c = j.control;
	if (!c) return;
	const gains = `kp = ${fmtSig(c.kp, 3)} ° per m/s, ki = ${fmtSig(c.ki, 3)} ° per m`;
	const m = c.identification;
	const model = m ? ` from an identification at ${fmt(m.beta0, 1)}°: K = ${fmtPm(m.gain, m.gainSe, 'm/s per °')}, ` +
		`T = ${fmtPm(m.timeConstant, m.timeConstantSe, 's')}, L = ${fmtPm(m.deadTime, m.deadTimeSe, 's')}` : '';
	const how = c.tuning === 'simc' ? `tuned by SIMC (τc = ${fmtSig(c.tauC, 3)} s)${model}` : 'as given';
	$('#loop-summary').textContent = `PI on β with feedforward: ${gains}, ${how}.`;
	fillTable(['setpoint', 'v / (m/s)', 'β feedforward / °', 'settling (2 %) / s', 'overshoot / %', 'IAE / m', 'steady error / %'],
		c.setpoints.map((sp, i) => loopCells(sp, j.segments[i]?.beta, i)));
	gainsTable(c);
}

/* The text of a curve change's cells (the browser test formats the API's
 * values the same way). */
export const curveCells = k => [fmt(k.t, 3), k.rotation === 'ccw' ? 'counter-clockwise' : 'clockwise',
	fmtGiven(k.omegaSs), fmt(k.beta0, 1), fmtSig(k.slope, 3), fmtSig(k.kp, 3), fmtSig(k.ki, 3),
	k.retuned ? 're-tuned' : 'kept'];

/* The gains in use after each curve change (docs/control.md, "auto" after
 * a curve change), under the per-setpoint table; hidden while there is none. */
function gainsTable(c) {
	const box = $('#loop-gains-box'), table = $('#loop-gains');
	box.hidden = !c.curves.length;
	table.replaceChildren();
	if (!c.curves.length) return;
	const n = c.curveChanges, shown = c.curves.length;
	const more = n > shown ? ` (${n} changes: the first ${shown - 1} and the last)` : '';
	table.createCaption().textContent = `Gains after each curve change${more}: from the change on, ` +
		(c.tuning === 'simc' ? 're-tuned by SIMC from the new curve\'s slope at the operating point.' : 'the given gains, kept.');
	const tr = table.createTHead().insertRow();
	for (const h of ['at t / s', 'rotation', 'ω_ss / (rad/s)', 'β₀ / °', 'slope / (m/s per °)', 'kp / (° per m/s)', 'ki / (° per m)', 'gains'])
		tr.append(Object.assign(document.createElement('th'), { textContent: h, scope: 'col' }));
	const body = table.createTBody();
	for (const k of c.curves) {
		const row = body.insertRow();
		for (const x of curveCells(k)) row.insertCell().textContent = x;
	}
}

/* The text of an identification's cells: each value ± its standard error. */
export const identCells = m => [fmtGiven(m.beta0), fmtPm(m.gain, m.gainSe), fmtPm(m.timeConstant, m.timeConstantSe),
	fmtPm(m.deadTime, m.deadTimeSe), fmtSig(m.slope, 3), fmtSig(m.rms, 2)];

function identTable(j) {
	const id = j.identify;
	if (!id) return;
	$('#loop-summary').textContent = `v = v₀ + K Σ Δβⱼ (1 − exp(−(t − tⱼ − L)/T)) fitted from the steps of ±${fmtGiven(id.step)}° held ${fmtGiven(id.hold)} s; ± one standard error.`;
	fillTable(['β₀ / °', 'gain K / (m/s per °)', 'time constant T / s', 'dead time L / s', 'v(β) slope / (m/s per °)', 'residual / (m/s)'],
		id.models.map(identCells));
}

const gaps = a => a.map(x => (Number.isFinite(x) ? x : null)); /* uPlot wants null, not NaN */

function plotControl(j, traj) {
	const t = traj.t ?? [];
	const v = api.periodVelocity(traj);
	const sp = t.map(x => {
		const i = j.segments.findIndex(s => x >= s.tStart && x <= s.tEnd);
		return i >= 0 ? j.control?.setpoints[i]?.v : NaN;
	});
	app.plots.loop.setData([t, gaps(v), gaps(sp), gaps(traj.beta ?? [])]);
	const marks = (j.control?.disturbances ?? []).map(d => ({
		x: d.tApplied, color: '#7c3aed',
		label: `${Object.entries(d.set).map(([k, x]) => `${k} → ${x}`).join(', ')}` +
			(Number.isFinite(d.recoveryTime) ? ` · back within 2 % in ${fmt(d.recoveryTime, 2)} s` : ''),
	}));
	app.plots.loop.setMarkers(marks);
}

function plotIdent(j, traj) {
	const t = traj.t ?? [];
	const fits = (j.identify?.models ?? []).map((m, p) => {
		const seg = j.segments.slice(5 * p, 5 * p + 5);
		const steps = seg.slice(1).map((s, k) => ({ t: s.tStart, d: s.beta - seg[k].beta }));
		return { m, steps, from: (Number.isFinite(j.tStart) ? j.tStart : 0) + m.tFrom, to: seg[4]?.tEnd };
	});
	const fitted = t.map(x => {
		const f = fits.find(g => x >= g.from && x <= g.to);
		return f ? api.fopdtAt(f.m, f.steps, x) : NaN;
	});
	app.plots.ident.setData([t, gaps(api.periodVelocity(traj)), gaps(fitted), gaps(traj.beta ?? [])]);
	app.plots.ident.setMarkers(fits.map(f => ({ x: f.from, label: `β₀ = ${fmtGiven(f.m.beta0)}°: fitted from here`, color: '#475569' })));
}
