// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * status.js - the attached session's polled status on the page: the tiles
 * (the daemon's transport velocity with its error bar and steady mark,
 * simulated time, rotor speed, real-time factor), the live-control card
 * (buttons, beta slider and readout, rotation, drive row) and the model
 * card with its reductions, and the note when the scene's column model
 * lies outside its validated domain.
 */

import { fmt, fmtGiven, fmtSig, fmtTime, fmtVelocityPm, steadyLabel, fmtPace, RAD_S_TO_RPM, rotationLabel,
	wrapBeta, DASH } from './format.js';
import { app, $ } from './ui.js';
import { resetTraces } from './live.js';

/* The picker's label of a session: id, beta, sense, time and state, from
 * one status, so that it says what the tiles say. */
export function sessionLabel(s) {
	const state = s.state || (s.running === false ? 'paused' : s.running ? 'running' : '');
	return `${s.id} · β ${fmt(s.beta, 0)}° · ${s.rotation ?? ''} · t ${fmt(s.t, 1)} s` + (state ? ` · ${state}` : '');
}

export function showStatus(s) {
	app.session = s;
	const opt = Array.from($('#session-select').options).find(o => o.value === app.id);
	if (opt && s.id === app.id) opt.textContent = sessionLabel(s);
	$('#t-now').textContent = fmtTime(s.t);
	/* a session ends at its until (pace "max" sets one 60 s on, docs/api.md):
	 * say where, and offer to run on */
	const finished = s.state === 'finished' && !s.error;
	/* a session its CPU budget paused says so; Resume grants a new one
	 * (PATCH {"running": true}, docs/budgets.md) */
	const spent = s.state === 'paused' && s.pauseReason === 'cpu-budget';
	const state = s.error ? `error: ${s.error}` : finished && Number.isFinite(s.until)
		? `finished at until = ${fmtGiven(s.until)} s`
		: spent ? `paused: CPU budget spent (${fmtSig(s.cpuSeconds, 2)} CPU s)`
		: s.state || (s.running === false ? 'paused' : s.running ? 'running' : DASH);
	$('#state-now').textContent = state;
	$('#resume').title = spent ? 'Resume with a new CPU budget (the daemon\'s --max-cpu-seconds)' : '';
	document.body.dataset.running = s.running === false ? 'false' : 'true';
	/* a failed session can be neither paused nor resumed; a finished one
	 * runs on (controls.js lifts its until) */
	$('#pause').disabled = !app.id || !/^running$/i.test(s.state || (s.running ? 'running' : ''));
	$('#resume').disabled = !app.id || !(finished || /^paused$/i.test(s.state || (s.running === false ? 'paused' : '')));
	$('#resume').textContent = finished ? 'Run on' : 'Resume';
	$('#rotor-now').textContent = fmt(s.rotorSpeed, 2, 'rad/s');
	$('#rotor-rpm').textContent = Number.isFinite(s.rotorSpeed) ? `${fmt(Math.abs(s.rotorSpeed) * RAD_S_TO_RPM, 0)} rpm` +
		(Number.isFinite(s.omegaSs) ? ` · ω_ss ${fmt(s.omegaSs, 2)} rad/s` : '') : DASH;
	$('#rtf-now').textContent = Number.isFinite(s.realTimeFactor) ? `${fmtSig(s.realTimeFactor, 3)}×` : DASH;
	$('#sps-now').textContent = `${fmtSig(s.stepsPerSecond, 3, 'steps/s')} · pace ${fmtPace(s.pace)}`;
	/* β now: the stream's latest sample where there is one (draw.js), so
	 * that the readout and the drawing agree */
	if (!Number.isFinite(app.lastSample?.beta)) $('#beta-now').textContent = fmt(s.beta, 1, '°');
	$('#beta-target').textContent = fmt(Number.isFinite(s.betaTarget) ? s.betaTarget : s.beta, 1, '°');
	$('#rotation-now').textContent = rotationLabel(s.rotation);
	$('#drive-now').textContent = s.driveOn === false ? 'off' : s.driveOn ? 'on' : DASH;
	$('#motor').textContent = s.driveOn === false ? 'Switch on' : 'Switch off';
	if (document.activeElement !== $('#omega-ss') && Number.isFinite(s.omegaSs))
		$('#omega-ss').value = String(s.omegaSs);
	if (document.activeElement !== $('#pace-live') && s.pace !== undefined)
		$('#pace-live').value = s.pace === 'max' ? 'max' : Number.isFinite(s.pace) ? String(s.pace) : '';
	$('#v-daemon').textContent = fmtVelocityPm(s.transportVelocity, s.transportUncertainty);
	const mark = steadyLabel(Number.isFinite(s.transportVelocity) ? s.steady : undefined);
	$('#v-steady').textContent = mark;
	$('#v-steady').dataset.steady = mark;
	/* the whole bar against the accuracy target (docs/machine-zoo.md) */
	const tol = Number.isFinite(s.transportUncertainty) && Number.isFinite(s.tol) && s.tolMet !== undefined
		? (s.tolMet ? 'within' : 'beyond') : '';
	$('#v-tol').textContent = tol ? `${tol} ${fmt(100 * s.tol, 1)} %` : '';
	$('#v-tol').dataset.tol = tol;
	/* slider follows the target unless the user is moving it */
	if (!app.betaEditing && document.activeElement !== $('#beta-number')) showBetaTarget(s);
	const now = $('#beta-now-mark');
	now.hidden = !Number.isFinite(s.beta);
	if (Number.isFinite(s.beta)) now.style.left = `${(wrapBeta(s.beta) / 180) * 100}%`;
	$('#m-preset').textContent = s.preset ?? DASH;
	const scene = [];
	if (Number.isFinite(s.columns)) scene.push(`${s.columns} columns × ${s.layers} layers`);
	if (s.feed === false) scene.push('no feed');
	if (s.drive) scene.push(`${s.drive} drive`);
	if (s.start) scene.push(`${s.start} start`);
	$('#m-scene').textContent = scene.join(', ') || DASH;
	$('#m-method').textContent = (s.method ?? DASH) + (Number.isFinite(s.dt) && Number.isFinite(s.substeps)
		? ` · step ${fmtSig(1e3 * s.dt, 3)} ms, ${s.substeps} feed sub-steps` : '');
	$('#m-pace').textContent = fmtPace(s.pace);
	showReductions(s.reductions);
	showModelCheck(s);
	$('#plot-feed').dataset.empty = s.feed === false ? 'this scene has no feed' : 'waiting for stream samples';
	if (!app.columns && Number.isFinite(s.columns) && s.columns > 0 && s.feed !== false) resetTraces(s.columns);
	app.dirty = true;
}

/* The β slider and number field at the session s's β target (its β
 * where it has none). */
export function showBetaTarget(s) {
	const target = Number.isFinite(s.betaTarget) ? s.betaTarget : s.beta;
	if (!Number.isFinite(target)) return;
	$('#beta-slider').value = String(target);
	$('#beta-number').value = String(Math.round(target * 10) / 10);
}

/* No session attached: every tile, readout and model field back to a dash,
 * and the live plots emptied (a deleted session leaves nothing behind). */
export function clearStatus() {
	app.session = null;
	app.lastSample = null;
	for (const sel of ['#t-now', '#rotor-now', '#rotor-rpm', '#rtf-now', '#sps-now', '#v-daemon', '#beta-now',
		'#beta-target', '#rotation-now', '#drive-now', '#m-preset', '#m-scene', '#m-method', '#m-pace'])
		$(sel).textContent = DASH;
	$('#state-now').textContent = 'no session';
	$('#v-steady').textContent = '';
	$('#v-steady').dataset.steady = '';
	$('#v-tol').textContent = '';
	$('#v-tol').dataset.tol = '';
	showModelCheck(null);
	delete document.body.dataset.running;
	const box = $('#reductions');
	box.dataset.key = '';
	box.replaceChildren(DASH);
	resetTraces(0);
}

/* The model error in plain words under the transport velocity (docs/dem.md
 * "Model error"): "DEM check: within ±E m/s here" where the scene is
 * checked against the DEM map, else the daemon's note up to its details
 * ("not checked against DEM for 16-layer beds"); the whole note as the
 * line's title. Nothing without a feed. */
export function showModelCheck(s) {
	const line = $('#v-model');
	const note = s?.feed === false ? '' : (s?.modelCheckNote ?? '');
	let text = '';
	if (s?.modelChecked && Number.isFinite(s.modelError))
		text = `DEM check: within ±${s.modelError.toFixed(3)} m/s here`;
	else if (note) {
		const cut = note.search(/: | \(/);
		text = cut > 0 ? note.slice(0, cut) : note;
	}
	line.textContent = text;
	line.title = note;
	line.dataset.checked = s?.modelChecked ? 'true' : 'false';
}

function showReductions(list) {
	const box = $('#reductions');
	const key = JSON.stringify(list);
	if (box.dataset.key === key) return;
	box.dataset.key = key;
	box.replaceChildren();
	if (!list.length) {
		const m = document.createElement('span');
		m.className = 'muted';
		m.textContent = 'full model (no reductions applied)';
		box.append(m);
		return;
	}
	for (const r of list) {
		const c = document.createElement('span');
		c.className = 'chip';
		c.textContent = r.name.replace(/_/g, ' ');
		const extra = [];
		if (Number.isFinite(r.speedup)) extra.push(`speed-up ${fmtSig(r.speedup, 3)}×`);
		if (Number.isFinite(r.error)) extra.push(`error ${fmtSig(r.error, 2)}`);
		if (extra.length) c.title = extra.join(', ');
		box.append(c);
	}
}
