// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * main.js - the dashboard page: builds the plots, wires the forms and
 * controls to their modules, fills the preset and integrator lists from
 * the daemon, watches the daemon's health while no session is attached,
 * and re-attaches the session named in the URL hash (#session=ID).
 *
 * One session is "attached" at a time (session.js): its stream feeds the
 * traces (live.js), its polled status the tiles and controls (status.js),
 * and draw.js redraws at most every animation frame. ui.js holds the state
 * they share; figures.js says which plot shows what; controls.js wires the
 * live-control card; sweep.js, experiment.js, loop.js and fit.js are the
 * job panels, and stop.js the experiment panels' Stop button.
 * api.js (with api-normalize.js, api-requests.js, api-stream.js) is the
 * one link to the daemon; auth.js gives it the token from the URL's
 * fragment (#token=...).
 */

import * as api from './api.js';
import { initAuth } from './auth.js';
import { app, $, message, report, setOnline } from './ui.js';
import { startSession, attach, detach, refreshSessionList } from './session.js';
import { makePlots } from './figures.js';
import { frame } from './draw.js';
import { wireControls } from './controls.js';
import { runSweep } from './sweep.js';
import { wireFit } from './fit.js';
import { wireExperiment } from './experiment.js';
import { wireLoop } from './loop.js';

const HEALTH_MS = 3000;

/* ---- wiring ------------------------------------------------------------------ */

function wire() {
	$('#session-form').addEventListener('submit', startSession);
	wireControls();
	$('#session-select').addEventListener('change', async e => {
		const id = e.target.value;
		if (!id) { detach(); return; }
		try {
			attach(id, await api.getSession(id));
		} catch (err) { report(err, 'Attach'); }
	});
	const f = $('#session-form').elements;
	for (const name of ['beta', 'rotation', 'columns', 'layers', 'feed']) f[name].addEventListener('input', () => {
		if (!app.id) app.dirty = true;
	});
	f.preset.addEventListener('change', () => applyPreset(f.preset.value));
	$('#sweep-form').addEventListener('submit', runSweep);
	wireFit();
	wireExperiment();
	wireLoop();
}

let presetList = [];
function applyPreset(name) {
	const p = presetList.find(x => x.name === name);
	if (!p) return;
	const f = $('#session-form').elements;
	const set = (k, v) => { if (v !== undefined && f[k]) f[k].value = String(v); };
	set('beta', p.params?.beta);
	const rot = api.rotationName(p.params?.rotation);
	if (rot) f.rotation.value = rot;
	set('columns', p.scene?.columns);
	set('layers', p.scene?.layers);
	if (typeof p.scene?.feed === 'boolean') f.feed.checked = p.scene.feed;
	if (p.scene?.drive === 'motor' || p.scene?.drive === 'ideal') f.drive.value = p.scene.drive;
	set('method', p.integrator?.method);
	app.dirty = true;
}

async function loadPresets() {
	let methods = [];
	try {
		const cat = await api.catalog();
		setOnline(true);
		presetList = cat.presets;
		methods = cat.methods;
		if (presetList.length) {
			const sel = $('#session-form').elements.preset;
			const keep = sel.value;
			sel.replaceChildren(...presetList.map(p => {
				const o = new Option(p.name, p.name);
				if (p.doc) o.title = p.doc;
				return o;
			}));
			sel.value = presetList.some(p => p.name === keep) ? keep : presetList[0].name;
			applyPreset(sel.value);
		}
	} catch (err) {
		if (err instanceof api.NetworkError) setOnline(false);
		/* a daemon with a token and a page without it */
		else if (err.status === 401)
			message('error', 'The daemon asks for its token: open the address that `make run` printed ' +
				'(it ends in #token=…), or add #token=TOKEN to this page\'s address.', { key: 'token', sticky: true });
	}
	if (!methods.length) methods = (await api.integratorNames().catch(() => [])).map(name => ({ name, doc: '' }));
	if (methods.length) {
		$('#methods').replaceChildren(...methods.map(m => {
			const o = new Option(m.name, m.name);
			o.label = m.doc ? `${m.name} · ${m.doc}` : m.name;
			return o;
		}));
	}
}

async function healthLoop() {
	if (!app.id) {
		try {
			await api.health();
			const was = app.online;
			setOnline(true);
			if (was === false) { loadPresets(); refreshSessionList(); }
		} catch (err) {
			if (err instanceof api.NetworkError) setOnline(false);
			else setOnline(true); /* answered, even if not 200 */
		}
	}
	setTimeout(healthLoop, HEALTH_MS);
}

async function init() {
	initAuth();
	makePlots();
	wire();
	requestAnimationFrame(frame);
	healthLoop();
	await loadPresets();
	await refreshSessionList();
	const m = /session=([^&]+)/.exec(location.hash);
	if (m) {
		const id = decodeURIComponent(m[1]);
		try { attach(id, await api.getSession(id)); } catch (err) { report(err, `Session ${id}`); detach(); }
	}
	document.body.dataset.ready = 'true';
}

init();
