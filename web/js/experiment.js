// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * experiment.js - the beta-change experiment panel: runs a fresh session
 * of the new-session form's model with beta1 then beta2, optionally
 * attaches the plots to it, and shows the reversal time, the segments and
 * the feed velocity against time; its Stop button (stop.js) ends it.
 */

import * as api from './api.js';
import { Trace } from './series.js';
import { fmt, fmtGiven, fmtTime, fmtVelocity, fmtVelocityPm, steadyLabel, direction, ARROW, DASH } from './format.js';
import { app, $, message, report, setOnline, numberOf, busy, progress } from './ui.js';
import { readSessionForm, attach } from './session.js';
import { stopButton, experimentEnded } from './stop.js';

/* The inputs behind the schedule's members (api-requests.js
 * experimentRequest): segment 1 is beta1 until t_switch, segment 2 beta2
 * until t_end. */
const SCHEDULE_INPUT = [[/^schedule\[0\]\.beta/, 'beta1'], [/^schedule\[0\]\.until/, 't_switch'],
	[/^schedule\[1\]\.beta/, 'beta2'], [/^schedule\[1\]\.until/, 't_end']];

let follow = null; /* polls a run until it ends or is stopped (stop.js) */

export function wireExperiment() {
	$('#experiment-form').addEventListener('submit', runExperiment);
	follow = stopButton('#experiment-stop', '#experiment-progress');
}

async function runExperiment(ev) {
	ev.preventDefault();
	const f = $('#experiment-form').elements;
	const base = readSessionForm();
	const form = { ...base, beta1: numberOf(f.beta1), beta2: numberOf(f.beta2), tSwitch: numberOf(f.t_switch), tEnd: numberOf(f.t_end) };
	const btn = $('#experiment-run');
	const box = $('#experiment-progress');
	busy(btn, true);
	app.experiment = null;
	$('#experiment-downloads').hidden = true;
	app.expTrace = new Trace(2, { policy: 'history', capacity: 4000 });
	try {
		const j = await api.createExperiment(form);
		setOnline(true);
		app.experiment = { id: j.id, sessionId: j.sessionId };
		progress(box, j.progress, 'started');
		showExperiment(j, form);
		if (f.watch.checked && j.sessionId) {
			attach(j.sessionId, await api.getSession(j.sessionId).catch(() => null));
			message('ok', `Experiment ${j.id} runs on session ${j.sessionId}; the plots follow it.`);
		}
		const end = await follow(j, api.getExperiment, u => {
			showExperiment(u, form);
			const tText = Number.isFinite(u.t) ? ` · t = ${fmtTime(u.t)}` : '';
			progress(box, Number.isFinite(u.progress) ? u.progress : (u.t / form.tEnd), `${u.state || 'running'}${tText}`);
		});
		if (!end) return; /* stopped: stop.js said so */
		experimentEnded(end);
		const csv = $('#experiment-csv'), traj = $('#experiment-traj');
		csv.href = api.experimentCsvUrl(end.id);
		csv.download = `experiment-${end.id}.csv`;
		if (end.sessionId) {
			traj.href = api.trajectoryUrl(end.sessionId, 'csv');
			traj.download = `experiment-${end.id}-trajectory.csv`;
		}
		traj.hidden = !end.sessionId;
		$('#experiment-downloads').hidden = false;
		if (end.sessionId) {
			/* the recorded history gives the whole reversal, whatever the stream saw */
			const traj = await api.trajectory(end.sessionId).catch(() => null);
			showExperiment(end, form, traj);
		}
	} catch (err) {
		report(err, 'Experiment', $('#experiment-form'), SCHEDULE_INPUT);
	} finally {
		busy(btn, false);
	}
}

function showExperiment(j, form, traj) {
	const rev = j.segments.map(s => s.reversalTime).filter(Number.isFinite);
	$('#reversal-time').textContent = rev.length ? fmt(rev[rev.length - 1], 3, 's') : DASH;
	const table = $('#experiment-table');
	table.replaceChildren();
	const head = table.createTHead().insertRow();
	for (const h of ['segment', 'β / °', 'from / s', 'steady v / (m/s)', 'mean v ± u / (m/s)', 'reversal / s']) head.append(Object.assign(document.createElement('th'), { textContent: h }));
	const body = table.createTBody();
	j.segments.forEach((s, i) => {
		const row = body.insertRow();
		row.insertCell().textContent = String(i + 1);
		row.insertCell().textContent = fmtGiven(s.beta);
		row.insertCell().textContent = fmtGiven(s.tStart);
		const vc = row.insertCell();
		vc.textContent = `${fmtVelocity(s.v).replace(' m/s', '')} ${ARROW[direction(s.v)]}`;
		/* the daemon's estimate over the segment, its error bar, and whether
		 * it had settled by the segment's end */
		const mc = row.insertCell();
		mc.textContent = fmtVelocityPm(s.meanVelocity, s.uncertainty).replace(' m/s', '');
		const mark = steadyLabel(Number.isFinite(s.meanVelocity) ? s.steady : undefined);
		if (mark) {
			const m = Object.assign(document.createElement('span'), { className: 'steady-mark', textContent: mark });
			m.dataset.steady = mark;
			mc.append(' ', m);
		}
		row.insertCell().textContent = fmt(s.reversalTime, 3);
	});
	/* the feed velocity as streamed (when the plots follow the experiment's
	 * session), else the daemon's trace if it gives one, else the segments'
	 * steady velocities as steps; beta on the right axis */
	const betaAt = x => x < form.tSwitch ? form.beta1 : form.beta2;
	let t = j.trace.t, v = j.trace.v, b = t.map(betaAt);
	const live = app.expTrace?.data();
	if (traj?.t?.length > 1 && traj.feed_velocity) [t, v, b] = [traj.t, traj.feed_velocity, traj.beta ?? traj.t.map(betaAt)];
	else if (live && live[0].length > 1) [t, v, b] = live;
	if (!t.length && j.segments.length) {
		t = []; v = []; b = [];
		j.segments.forEach((s, i) => {
			const t0 = Number.isFinite(s.tStart) ? s.tStart : (i ? form.tSwitch : 0);
			const t1 = Number.isFinite(s.tEnd) ? s.tEnd : (j.segments[i + 1]?.tStart ?? form.tEnd);
			const beta = Number.isFinite(s.beta) ? s.beta : betaAt(t0);
			const dt = Math.max(1e-6, (t1 - t0) * 1e-6);
			/* each segment a flat step, so the plot shows no false ramps */
			t.push(t0 + (i ? dt : 0), t1); v.push(s.v, s.v); b.push(beta, beta);
		});
	}
	const gaps = a => a.map(x => Number.isFinite(x) ? x : null); /* uPlot wants null, not NaN */
	if (t.length) app.plots.experiment.setData([t, gaps(v), gaps(b)]);
	const marks = [];
	j.segments.forEach((s, i) => {
		if (i === 0 || !Number.isFinite(s.tStart)) return;
		marks.push({ x: s.tStart, label: `β → ${fmtGiven(s.beta)}°`, color: '#d97706' });
		if (Number.isFinite(s.reversalTime))
			marks.push({ x: s.tStart + s.reversalTime, label: `90 % after ${fmt(s.reversalTime, 3)} s`, color: '#7c3aed', row: 1 });
	});
	app.plots.experiment.setMarkers(marks);
}
