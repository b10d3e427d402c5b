// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * sweep.js - the sweep panel: runs v(beta) for both rotations on the
 * new-session form's model, follows its progress, and shows the plot (with
 * each point's error bar), the table (v, its error bar u, steady or
 * settling) and the CSV link.
 */

import * as api from './api.js';
import { fmt, steadyLabel } from './format.js';
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
	const by = rot => j.points.filter(p => p.rotation === rot).sort((a, b) => a.beta - b.beta);
	const cw = by('cw'), ccw = by('ccw');
	app.plots.sweep.setData([[cw.map(p => p.beta), cw.map(p => p.v)], [ccw.map(p => p.beta), ccw.map(p => p.v)]],
		[cw.map(p => p.u), ccw.map(p => p.u)]);
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
			const mark = row.insertCell();
			mark.textContent = steadyLabel(Number.isFinite(p?.v) ? p.steady : undefined);
			mark.className = 'steady-mark';
			mark.dataset.steady = mark.textContent;
		}
	}
}
