/*
 * sweep.js - the sweep panel: runs v(beta) for both rotations on the
 * new-session form's model, follows its progress, and shows the plot, the
 * table and the CSV link.
 */

import * as api from './api.js';
import { fmt } from './format.js';
import { app, $, message, report, setOnline, numberOf, busy, progress, poll } from './ui.js';
import { readSessionForm } from './session.js';

export async function runSweep(ev) {
	ev.preventDefault();
	const f = $('#sweep-form').elements;
	const base = readSessionForm();
	const form = { ...base, from: numberOf(f.from), to: numberOf(f.to), step: numberOf(f.step), tEnd: numberOf(f.t_end) };
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
			'the run time per point must exceed the scene\'s transient (the transport velocity ignores t < transient).');
		else message('ok', `Sweep ${end.id} finished: ${end.points.length} points.`);
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
	const by = rot => j.points.filter(p => p.rotation === rot).sort((a, b) => a.beta - b.beta);
	const cw = by('cw'), ccw = by('ccw');
	app.plots.sweep.setData([[cw.map(p => p.beta), cw.map(p => p.v)], [ccw.map(p => p.beta), ccw.map(p => p.v)]]);
	const table = $('#sweep-table');
	table.replaceChildren();
	const head = table.createTHead().insertRow();
	for (const h of ['β / °', 'v clockwise / (m/s)', 'v counter-clockwise / (m/s)']) head.append(Object.assign(document.createElement('th'), { textContent: h }));
	const betas = [...new Set(j.points.map(p => p.beta))].sort((a, b) => a - b);
	const body = table.createTBody();
	for (const b of betas) {
		const row = body.insertRow();
		row.insertCell().textContent = fmt(b, 1);
		row.insertCell().textContent = fmt(cw.find(p => p.beta === b)?.v, 4);
		row.insertCell().textContent = fmt(ccw.find(p => p.beta === b)?.v, 4);
	}
}
