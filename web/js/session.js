// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * session.js - the attached session: the new-session form, attaching to a
 * session (its stream feeds live.js, its status is polled every STATUS_MS
 * for the tiles, its id is kept in the URL hash #session=ID so that a
 * reload re-attaches), detaching, PATCH requests of the live controls,
 * deleting, and the session list in the header.
 */

import * as api from './api.js';
import { fmt, fmtGiven, fmtTime, rotationLabel, parsePace } from './format.js';
import { app, $, $$, message, report, setOnline, numberOf, busy } from './ui.js';
import { resetTraces, onSample, onControl } from './live.js';
import { showStatus, clearStatus, sessionLabel, showModelCheck, showBetaTarget } from './status.js';

const STATUS_MS = 500;

/* The inputs behind members whose names differ (ui.js report): the
 * session form's Samples, and the live card's slew rate, which a new
 * session takes as its params.beta_rate. */
const SESSION_INPUT = [[/^sample_rate$/, 'rate'], [/^params\.beta_rate$/, '#beta-rate']];
const CONTROL_INPUT = [[/^beta$/, '#beta-number'], [/^beta_rate$/, '#beta-rate'], [/^omega_ss$/, '#omega-ss'],
	[/^pace$/, '#pace-live']];

/* Values of the new-session form. Numbers are passed on as typed, so the
 * daemon (not the browser) judges their ranges and names the field. */
export function readSessionForm() {
	const f = $('#session-form').elements;
	const paceText = f.pace.value;
	const pace = parsePace(paceText);
	return {
		preset: f.preset.value,
		beta: numberOf(f.beta),
		rotation: f.rotation.value,
		columns: numberOf(f.columns),
		layers: numberOf(f.layers),
		feed: f.feed.checked,
		drive: f.drive.value,
		start: f.scene_start.value, /* not f.start: the submit button is #start */
		method: f.method.value.trim(),
		dt: numberOf(f.dt),
		pace: pace ?? (Number.isFinite(Number(paceText)) ? Number(paceText) : paceText),
		rate: numberOf(f.rate),
		betaRate: numberOf($('#beta-rate')),
	};
}

export async function startSession(ev) {
	ev.preventDefault();
	const form = readSessionForm();
	const btn = $('#start');
	busy(btn, true);
	try {
		const s = await api.createSession(form);
		setOnline(true);
		message('ok', `Session ${s.id} started (${form.preset}, β = ${fmtGiven(form.beta)}°, ${rotationLabel(form.rotation)}).`);
		/* the POST answer's status is that of t = 0 before the first step:
		 * let the first poll fill the tiles */
		attach(s.id, null);
		refreshSessionList();
	} catch (err) {
		report(err, 'Start session', $('#session-form'), SESSION_INPUT);
	} finally {
		busy(btn, false);
	}
}

export function detach() {
	app.stream?.close();
	app.stream = null;
	clearInterval(app.statusTimer);
	app.statusTimer = 0;
	app.id = null;
	app.session = null;
	document.body.dataset.sessionId = '';
	history.replaceState(null, '', location.pathname);
	setControlsEnabled(false);
	$('#session-downloads').hidden = true;
	$('#beta-now-mark').hidden = true;
	$('#session-label').textContent = 'no session';
	$('#resume').textContent = 'Resume';
	$('#live-state').textContent = 'stream: idle';
	$('#session-select').value = '';
	clearStatus();
}

export function attach(id, initial) {
	detach();
	app.id = id;
	app.session = initial ?? null;
	app.samples = 0;
	app.dropped = 0;
	app.controls = [];
	app.lastVelocity = NaN;
	document.body.dataset.sessionId = id;
	history.replaceState(null, '', `#session=${encodeURIComponent(id)}`);
	$('#session-label').textContent = `session ${id}`;
	/* the picker names the session at once, before the next list refresh
	 * brings it (it stood blank for a refresh's time after "Run experiment") */
	const sel = $('#session-select');
	if (!Array.from(sel.options).some(o => o.value === id))
		sel.append(new Option(initial ? sessionLabel(initial) : id, id));
	sel.value = id;
	setControlsEnabled(true);
	for (const format of ['csv', 'json']) {
		const a = $(`#traj-${format}`);
		a.href = api.trajectoryUrl(id, format);
		a.download = `trajectory-${id}.${format}`;
	}
	$('#session-downloads').hidden = false;
	resetTraces(initial?.columns);
	app.stream = api.openStream(id, { since: 0 }, {
		open: () => { setOnline(true); $('#live-state').textContent = `stream: open (${id})`; },
		sample: onSample,
		control: (c, raw) => {
			onControl(c);
			/* each control's record carries the scene's model error anew */
			if (typeof raw?.model_checked === 'boolean')
				showModelCheck({ feed: app.session?.feed, modelChecked: raw.model_checked,
					modelError: raw.model_error, modelCheckNote: raw.model_check_note ?? '' });
		},
		dropped: n => { if (n > 0) app.dropped += n; },
		end: d => {
			$('#live-state').textContent = `stream: ended${d?.reason ? ` (${d.reason})` : ''}`;
			pollStatus();
		},
		error: state => {
			$('#live-state').textContent = state === 2 ? 'stream: closed' : 'stream: reconnecting…';
		},
	});
	pollStatus();
	app.statusTimer = setInterval(pollStatus, STATUS_MS);
	if (initial) showStatus(initial);
}

let polls = 0;
export async function pollStatus() {
	const id = app.id;
	if (!id || id === app.removing) return;
	if (++polls % 10 === 0) refreshSessionList();
	try {
		const s = await api.getSession(id);
		if (id !== app.id) return;
		setOnline(true);
		showStatus(s);
	} catch (err) {
		if (id !== app.id) return;
		if (err instanceof api.ApiError && err.status === 404) {
			message('warn', `Session ${id} no longer exists on the daemon.`);
			detach();
			refreshSessionList();
		} else if (err instanceof api.NetworkError) {
			setOnline(false);
		}
	}
}

/* refused: called before the refusal's message shows, to put the inputs
 * back on the session as last polled (the refused control changed nothing) */
export async function patch(body, what, refused) {
	if (!app.id) return null;
	try {
		const r = await api.patchSession(app.id, body);
		setOnline(true);
		pollStatus();
		return r;
	} catch (err) {
		/* a refusal changes nothing: the inputs show the session again */
		if (refused && app.session) refused(app.session);
		report(err, what, $('#control-card'), CONTROL_INPUT);
		await pollStatus();
		return null;
	}
}

export async function setBeta(beta) {
	const body = { beta };
	/* a slew typed goes as typed (a negative one for the daemon to refuse) */
	const rate = numberOf($('#beta-rate'));
	if (!Number.isNaN(rate)) body.beta_rate = rate;
	const r = await patch(body, 'β change', showBetaTarget);
	if (r) {
		const t = r.control.t;
		message('ok', `β → ${fmtGiven(beta)}°` + (Number.isFinite(t) ? ` from t = ${fmtTime(t)}` : '') + '.');
	} else if (app.session) {
		/* refused (181, -5): the slider and the number field, focused or
		 * not, show the session's β target again, before its message
		 * (above) and once more as the poll after it found it */
		showBetaTarget(app.session);
	}
	return r;
}

export async function removeSession() {
	const id = app.id;
	if (!id) return;
	/* from here no poll asks for it (the stream's end would, and get a 404) */
	app.removing = id;
	try {
		await api.deleteSession(id);
		message('ok', `Session ${id} deleted.`);
	} catch (err) {
		if (!(err instanceof api.ApiError && err.status === 404)) { app.removing = null; report(err, 'Delete'); return; }
	}
	detach();
	app.removing = null;
	refreshSessionList();
}

/* The replicas of a cluster that did not answer the listing (docs/
 * cluster.md): their sessions are not in the picker, and the note beside
 * it says so; its title names each and why. */
function showUnreachable(peers) {
	const note = $('#peers-note');
	const n = peers.length;
	note.hidden = n === 0;
	note.textContent = n === 0 ? '' : `${n} replica${n > 1 ? 's' : ''} did not answer: ${n > 1 ? 'their' : 'its'} sessions are not listed`;
	note.title = peers.map(p => `${p.peer}: ${p.reason}`).join('\n');
}

export async function refreshSessionList() {
	try {
		const list = await api.listSessions();
		setOnline(true);
		const sel = $('#session-select');
		const keep = app.id ?? '';
		sel.replaceChildren(new Option('none', ''));
		for (const s of list) {
			/* the attached session's label follows its polled status (showStatus) */
			const label = s.id === app.id && app.session?.id === s.id ? sessionLabel(app.session) : sessionLabel(s);
			sel.append(new Option(label, s.id));
		}
		if (keep && !list.some(s => s.id === keep)) sel.append(new Option(keep, keep));
		sel.value = keep;
		showUnreachable(list.unreachable ?? []);
	} catch (err) {
		if (err instanceof api.NetworkError) setOnline(false);
	}
}

function setControlsEnabled(on) {
	for (const e of ['#pause', '#resume', '#delete', '#flip', '#beta-slider', '#beta-number',
		'#motor', '#omega-ss', '#pace-live'])
		$(e).disabled = !on;
	for (const b of $$('.quick')) b.disabled = !on;
}
