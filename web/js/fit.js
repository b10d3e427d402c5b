// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * fit.js - the calibration panel: measured points pasted or loaded as CSV,
 * free parameters by name, POST /api/v1/fits on the new-session form's
 * model; follows the fit's progress (iteration, evaluations, current
 * values), can stop it (its Stop button: stop.js), and shows the data with
 * their sigma, the fitted and the original curve with the fitted curve's
 * 95 % band shaded, the values with standard errors and the warnings, and
 * the result's CSV link.
 */

import * as api from './api.js';
import { fitProgressText, fitChi2Text, priorText } from './format.js';
import { app, $, message, report, setOnline, numberOf, busy, progress } from './ui.js';
import { readSessionForm } from './session.js';
import { stopButton, stopFit } from './stop.js';

let follow = null; /* polls a fit until it ends or is stopped (stop.js) */

export function wireFit() {
	$('#fit-form').addEventListener('submit', runFit);
	$('#fit-form').elements.file.addEventListener('change', async ev => {
		const file = ev.target.files[0];
		if (file) $('#fit-form').elements.csv.value = await file.text();
	});
	follow = stopButton('#fit-stop', '#fit-progress', stopFit);
}

async function runFit(ev) {
	ev.preventDefault();
	const f = $('#fit-form').elements;
	const form = { ...readSessionForm(), csv: f.csv.value, free: f.free.value, priors: f.priors.value,
		tEnd: numberOf(f.t_end), curveStep: numberOf(f.curve_step) };
	const btn = $('#fit-run'), box = $('#fit-progress');
	for (const el of f) el.removeAttribute?.('aria-invalid');
	busy(btn, true);
	try {
		const j = await api.createFit(form);
		setOnline(true);
		const csv = $('#fit-csv');
		csv.href = api.fitCsvUrl(j.id);
		csv.download = `fit-${j.id}.csv`;
		progress(box, 0, 'started');
		const end = await follow(j, api.getFit, u => progress(box, u.progress, fitProgressText(u)));
		if (!end) return; /* stopped: stop.js said so */
		if (end.result) showFit(end.result);
		if (end.state === 'done') offerBand(end.id);
		csv.hidden = !end.result;
		const r = end.result;
		const why = end.error || r?.error;
		const late = end.endedBeforeStop ? ' (it had already ended: nothing was stopped)' : '';
		if (end.state !== 'done') message('error', `Fit ${end.id} ${end.state}${why ? ': ' + why : ''}${late}`);
		else message(r.warnings.length ? 'warn' : 'ok', `Fit ${end.id} ${r.status} after ${r.iterations} iterations, ` +
			`${r.evaluations} evaluations` + (r.warnings.length ? `: ${r.warnings.length} warning(s) below` : '') + late);
	} catch (err) {
		report(err, 'Fit', $('#fit-form'));
	} finally {
		busy(btn, false);
	}
}

/* The plot (per rotation: the fitted curve's 95 % band shaded, data with
 * sigma, fitted and original curves), the parameters' table and the
 * warnings. The band is symmetric about the fitted curve: drawn as the
 * curve ± the band's half-width. */
function showFit(r) {
	const pairs = [], errs = [];
	for (const rot of ['cw', 'ccw']) {
		const c = r.curve?.[rot];
		pairs.push(c ? [r.curve.beta, c.fit] : [[], []]);
		errs.push(c ? c.band.upper.map((hi, k) => (hi - c.band.lower[k]) / 2) : []);
	}
	for (const rot of ['cw', 'ccw']) {
		const pts = (r.points || []).filter(p => p.rotation === rot);
		pairs.push([pts.map(p => p.beta), pts.map(p => p.v)]);
		errs.push(pts.map(p => p.sigma ?? NaN));
		const c = r.curve?.[rot];
		for (const key of ['fit', 'start']) {
			pairs.push(c ? [r.curve.beta, c[key]] : [[], []]);
			errs.push(key === 'fit' && c ? c.fit_uncertainty : []);
		}
	}
	app.plots.fit.setData(pairs, errs);
	const table = $('#fit-table');
	table.replaceChildren();
	const head = table.createTHead().insertRow();
	for (const h of ['parameter', 'fitted', '± standard error', 'start', 'unit', 'bound', 'prior'])
		head.append(Object.assign(document.createElement('th'), { textContent: h }));
	const body = table.createTBody();
	const sig = (v, n) => (Number.isFinite(v) ? Number(v.toPrecision(n)).toString() : '–');
	for (const p of r.parameters) {
		const row = body.insertRow();
		row.dataset.name = p.name;
		for (const v of [p.name, sig(p.value, 5), sig(p.standard_error, 2), sig(p.start, 5), p.unit, p.at_bound ?? '',
			priorText(p.prior)])
			row.insertCell().textContent = v;
	}
	const note = body.insertRow().insertCell();
	note.colSpan = 7;
	note.className = 'fit-chi2';
	note.textContent = `standard errors from ${r.standard_errors_from}; ${fitChi2Text(r)}`;
	const list = $('#fit-warnings');
	list.replaceChildren(...r.warnings.map(w => Object.assign(document.createElement('li'), { textContent: w })));
}

/* A finished fit's bands for the sweep panel: its checkbox names the fit. */
function offerBand(id) {
	app.lastFit = id;
	const box = $('#sweep-form').elements.band;
	box.disabled = false;
	$('#sweep-band-text').textContent = `band of fit ${id}`;
}
