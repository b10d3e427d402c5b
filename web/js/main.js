/*
 * main.js - the dashboard page: wires the forms and controls to the daemon
 * (through api.js), feeds the live stream into the traces (series.js) and
 * redraws plots, tiles and the schematic at most every animation frame.
 *
 * One session is "attached" at a time: its stream feeds the plots, and its
 * status is polled every STATUS_MS for the tiles (simulated time, beta now
 * and target, rotor speed, speed). The attached session's id is kept in the
 * URL hash (#session=ID) so that a reload re-attaches.
 */

import * as api from './api.js';
import { Trace, recentVelocity } from './series.js';
import { fmt, fmtSig, fmtTime, fmtVelocity, fmtPace, direction, ARROW, RAD_S_TO_RPM,
	rotationLabel, parsePace, problemText, wrapBeta, DASH } from './format.js';
import { TimePlot, XYPlot, PALETTE } from './plots.js';
import { Schematic } from './schematic.js';

const STATUS_MS = 500;
const HEALTH_MS = 3000;
const JOB_POLL_MS = 500;
const MM = 1000; /* m -> mm */

const $ = sel => document.querySelector(sel);
const $$ = sel => Array.from(document.querySelectorAll(sel));

const app = {
	session: null,        /* normalized status of the attached session */
	id: null,
	stream: null,
	statusTimer: 0,
	samples: 0,
	dropped: 0,
	columns: 0,
	traces: null,
	plots: {},
	dirty: false,
	online: undefined,
	betaEditing: false,   /* the user is dragging the slider */
	lastVelocity: NaN,
	controls: [],         /* control events seen on the stream */
	pending: new Set(),   /* requests in flight, for button states */
};
window.convsim = app;     /* for the console and the browser test */

/* ---- messages ------------------------------------------------------------ */

function message(kind, text, { key, sticky = false } = {}) {
	const box = $('#messages');
	if (key) box.querySelector(`[data-key="${key}"]`)?.remove();
	const m = document.createElement('div');
	m.className = `msg ${kind}`;
	m.setAttribute('role', kind === 'error' ? 'alert' : 'status');
	if (key) m.dataset.key = key;
	const span = document.createElement('span');
	span.className = 'msg-text';
	span.textContent = text;
	const close = document.createElement('button');
	close.className = 'msg-close';
	close.type = 'button';
	close.setAttribute('aria-label', 'Dismiss');
	close.textContent = '×';
	close.onclick = () => m.remove();
	m.append(span, close);
	box.prepend(m);
	while (box.children.length > 5) box.lastChild.remove();
	if (!sticky) setTimeout(() => m.remove(), kind === 'error' ? 20000 : 5000);
	return m;
}

function clearMessage(key) {
	$(`#messages [data-key="${key}"]`)?.remove();
}

/* Report a failed request: a refused input shows the daemon's problem
 * detail and marks the field it names; an unreachable daemon says so. */
function report(err, what, form) {
	if (err instanceof api.NetworkError) {
		setOnline(false);
		message('error', `${what}: ${err.message}`, { key: 'network', sticky: true });
		return;
	}
	if (err instanceof api.ApiError) {
		message('error', `${what} refused: ${problemText(err)}`, { key: `refused-${what}` });
		if (form && err.field) {
			const name = String(err.field).split(/[./]/).pop();
			const input = form.elements[name];
			if (input) {
				input.setAttribute('aria-invalid', 'true');
				input.title = err.detail;
				input.addEventListener('input', () => input.removeAttribute('aria-invalid'), { once: true });
			}
		}
		return;
	}
	message('error', `${what}: ${err?.message ?? err}`);
	console.error(err);
}

function setOnline(on) {
	if (on === app.online) return;
	app.online = on;
	const c = $('#conn');
	c.dataset.state = on ? 'online' : 'offline';
	c.textContent = on ? 'daemon: connected' : 'daemon: unreachable';
	if (on) clearMessage('network');
	else message('error', 'The convsim daemon does not answer. Start it with build/convsimd (make run) and reload; the page retries by itself.', { key: 'network', sticky: true });
}

/* ---- forms ---------------------------------------------------------------- */

function numberOf(input) {
	const s = String(input?.value ?? '').trim();
	return s === '' ? NaN : Number(s);
}

/* Values of the new-session form. Numbers are passed on as typed, so the
 * daemon (not the browser) judges their ranges and names the field. */
function readSessionForm() {
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
		method: f.method.value.trim(),
		dt: numberOf(f.dt),
		pace: pace ?? (Number.isFinite(Number(paceText)) ? Number(paceText) : paceText),
		rate: numberOf(f.rate),
		betaRate: numberOf($('#beta-rate')),
	};
}

function busy(button, on) {
	if (!button) return;
	button.classList.toggle('busy', on);
	button.disabled = on;
}

/* ---- session lifecycle ----------------------------------------------------- */

async function startSession(ev) {
	ev.preventDefault();
	const form = readSessionForm();
	const btn = $('#start');
	busy(btn, true);
	try {
		const s = await api.createSession(form);
		setOnline(true);
		message('ok', `Session ${s.id} started (${form.preset}, β = ${fmt(form.beta, 1)}°, ${rotationLabel(form.rotation)}).`);
		/* the POST answer's status is that of t = 0 before the first step:
		 * let the first poll fill the tiles */
		attach(s.id, null);
		refreshSessionList();
	} catch (err) {
		report(err, 'Start session', $('#session-form'));
	} finally {
		busy(btn, false);
	}
}

function detach() {
	app.stream?.close();
	app.stream = null;
	clearInterval(app.statusTimer);
	app.statusTimer = 0;
	app.id = null;
	app.session = null;
	document.body.dataset.sessionId = '';
	history.replaceState(null, '', location.pathname);
	setControlsEnabled(false);
	$('#beta-now-mark').hidden = true;
	$('#session-label').textContent = 'no session';
	$('#live-state').textContent = 'stream: idle';
	$('#session-select').value = '';
}

function attach(id, initial) {
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
	$('#session-select').value = id;
	setControlsEnabled(true);
	resetTraces(initial?.columns);
	app.stream = api.openStream(id, { since: 0 }, {
		open: () => { setOnline(true); $('#live-state').textContent = `stream: open (${id})`; },
		sample: onSample,
		control: onControl,
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
async function pollStatus() {
	const id = app.id;
	if (!id) return;
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

async function patch(body, what) {
	if (!app.id) return null;
	try {
		const r = await api.patchSession(app.id, body);
		setOnline(true);
		pollStatus();
		return r;
	} catch (err) {
		report(err, what);
		pollStatus();
		return null;
	}
}

async function setBeta(beta) {
	const body = { beta };
	const rate = numberOf($('#beta-rate'));
	if (Number.isFinite(rate) && rate > 0) body.beta_rate = rate;
	const r = await patch(body, 'β change');
	if (r) {
		const t = r.control.t;
		message('ok', `β → ${fmt(beta, 1)}°` + (Number.isFinite(t) ? ` from t = ${fmtTime(t)}` : '') + '.');
	}
	return r;
}

async function removeSession() {
	const id = app.id;
	if (!id) return;
	try {
		await api.deleteSession(id);
		message('ok', `Session ${id} deleted.`);
	} catch (err) {
		if (!(err instanceof api.ApiError && err.status === 404)) { report(err, 'Delete'); return; }
	}
	detach();
	refreshSessionList();
}

async function refreshSessionList() {
	try {
		const list = await api.listSessions();
		setOnline(true);
		const sel = $('#session-select');
		const keep = app.id ?? '';
		sel.replaceChildren(new Option('none', ''));
		for (const s of list) {
			const label = `${s.id} · β ${fmt(s.beta, 0)}° · ${s.rotation ?? ''} · t ${fmt(s.t, 1)} s`;
			sel.append(new Option(label, s.id));
		}
		if (keep && !list.some(s => s.id === keep)) sel.append(new Option(keep, keep));
		sel.value = keep;
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

/* ---- live data ---------------------------------------------------------- */

function resetTraces(columns) {
	const K = Number.isFinite(columns) && columns > 0 ? columns : 0;
	app.columns = K;
	app.traces = {
		orbit: new Trace(2, { policy: 'window', span: 0.12, capacity: 3000 }),
		strokes: new Trace(2, { policy: 'window', span: 0.25, capacity: 4000 }),
		trough: new Trace(2, { policy: 'window', span: 0.25, capacity: 4000 }),
		rotor: new Trace(2, { policy: 'history', capacity: 3000 }),
		feed: new Trace(K, { policy: 'history', capacity: 3000 }),
		feedMean: new Trace(1, { policy: 'window', span: 2, capacity: 20000 }),
	};
	buildFeedPlot(K);
	app.dirty = true;
}

function onSample(s) {
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
	tr.rotor.push(s.t, [s.rotorSpeed, beta]);
	if (s.columns.length) tr.feed.push(s.t, s.columns.map(x => x * MM));
	if (Number.isFinite(s.feedMean)) tr.feedMean.push(s.t, [s.feedMean]);
	if (app.experiment && app.experiment.sessionId === app.id && app.expTrace)
		app.expTrace.push(s.t, [s.feedVelocity, beta]);
	app.lastSample = s;
	app.dirty = true;
}

function onControl(c) {
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
function currentVelocity() {
	if (app.session?.feed === false) return NaN;
	const [ts, xs] = app.traces?.feedMean.data() ?? [[], []];
	const omega = Math.abs(app.lastSample?.rotorSpeed ?? app.session?.rotorSpeed ?? NaN);
	const span = omega > 1 ? Math.max(0.5, 10 * 2 * Math.PI / omega) : 0.5;
	const v = recentVelocity(ts, xs, Math.min(span, 2), 0.2);
	return Number.isFinite(v) ? v : app.session?.transportVelocity ?? NaN;
}

/* ---- status tiles -------------------------------------------------------- */

function showStatus(s) {
	app.session = s;
	$('#t-now').textContent = fmtTime(s.t);
	const state = s.error ? `error: ${s.error}` : s.state || (s.running === false ? 'paused' : s.running ? 'running' : DASH);
	$('#state-now').textContent = state;
	document.body.dataset.running = s.running === false ? 'false' : 'true';
	/* finished and failed sessions can be neither paused nor resumed */
	$('#pause').disabled = !app.id || !/^running$/i.test(s.state || (s.running ? 'running' : ''));
	$('#resume').disabled = !app.id || !/^paused$/i.test(s.state || (s.running === false ? 'paused' : ''));
	$('#rotor-now').textContent = fmt(s.rotorSpeed, 2, 'rad/s');
	$('#rotor-rpm').textContent = Number.isFinite(s.rotorSpeed) ? `${fmt(Math.abs(s.rotorSpeed) * RAD_S_TO_RPM, 0)} rpm` +
		(Number.isFinite(s.omegaSs) ? ` · ω_ss ${fmt(s.omegaSs, 2)} rad/s` : '') : DASH;
	$('#rtf-now').textContent = Number.isFinite(s.realTimeFactor) ? `${fmtSig(s.realTimeFactor, 3)}×` : DASH;
	$('#sps-now').textContent = `${fmtSig(s.stepsPerSecond, 3, 'steps/s')} · pace ${fmtPace(s.pace)}`;
	$('#beta-now').textContent = fmt(s.beta, 1, '°');
	$('#beta-target').textContent = fmt(Number.isFinite(s.betaTarget) ? s.betaTarget : s.beta, 1, '°');
	$('#rotation-now').textContent = rotationLabel(s.rotation);
	$('#drive-now').textContent = s.driveOn === false ? 'off' : s.driveOn ? 'on' : DASH;
	$('#motor').textContent = s.driveOn === false ? 'Switch on' : 'Switch off';
	if (document.activeElement !== $('#omega-ss') && Number.isFinite(s.omegaSs))
		$('#omega-ss').value = String(s.omegaSs);
	if (document.activeElement !== $('#pace-live') && s.pace !== undefined)
		$('#pace-live').value = s.pace === 'max' ? 'max' : Number.isFinite(s.pace) ? String(s.pace) : '';
	$('#v-daemon').textContent = fmtVelocity(s.transportVelocity);
	/* slider follows the target unless the user is moving it */
	const target = Number.isFinite(s.betaTarget) ? s.betaTarget : s.beta;
	if (!app.betaEditing && Number.isFinite(target) && document.activeElement !== $('#beta-number')) {
		$('#beta-slider').value = String(target);
		$('#beta-number').value = String(Math.round(target * 10) / 10);
	}
	const mark = $('#beta-now-mark');
	mark.hidden = !Number.isFinite(s.beta);
	if (Number.isFinite(s.beta)) mark.style.left = `${(wrapBeta(s.beta) / 180) * 100}%`;
	$('#m-preset').textContent = s.preset ?? DASH;
	const scene = [];
	if (Number.isFinite(s.columns)) scene.push(`${s.columns} columns × ${s.layers} layers`);
	if (s.feed === false) scene.push('no feed');
	if (s.drive) scene.push(`${s.drive} drive`);
	$('#m-scene').textContent = scene.join(', ') || DASH;
	$('#m-method').textContent = s.method ?? DASH;
	$('#m-pace').textContent = fmtPace(s.pace);
	showReductions(s.reductions);
	$('#plot-feed').dataset.empty = s.feed === false ? 'this scene has no feed' : 'waiting for stream samples';
	if (!app.columns && Number.isFinite(s.columns) && s.columns > 0 && s.feed !== false) resetTraces(s.columns);
	app.dirty = true;
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

/* ---- plots ----------------------------------------------------------------- */

function makePlots() {
	app.plots.orbit = new XYPlot($('#plot-orbit'), {
		series: [{ label: 'deck point', color: PALETTE[0], width: 1.75 }],
		xLabel: 'horizontal displacement x / mm', yLabel: 'vertical displacement y / mm',
		equal: true, aspect: 0.78,
	});
	app.plots.rotor = new TimePlot($('#plot-rotor'), {
		series: [{ label: 'rotor speed / (rad/s)', color: PALETTE[0] }, { label: 'β / °', color: PALETTE[3], scale: 'y2' }],
		yLabel: 'rotor speed / (rad/s)', y2Label: 'β / °', y2Range: [0, 180],
	});
	app.plots.strokes = new TimePlot($('#plot-strokes'), {
		series: [{ label: 's₁ / mm', color: PALETTE[4] }, { label: 's₂ / mm', color: PALETTE[5] }],
		yLabel: 'stroke / mm',
	});
	app.plots.trough = new TimePlot($('#plot-trough'), {
		series: [{ label: 'x / mm', color: PALETTE[0] }, { label: 'y / mm', color: PALETTE[1] }],
		yLabel: 'displacement / mm',
	});
	buildFeedPlot(0);
	app.schematic = new Schematic($('#schematic'));
	app.schematic.update({ beta: numberOf($('#session-form').elements.beta), rotation: 'cw', columns: 5, layers: 8 });
	app.plots.sweep = new XYPlot($('#plot-sweep'), {
		series: [{ label: 'clockwise', color: PALETTE[0] }, { label: 'counter-clockwise', color: PALETTE[1] }],
		xLabel: 'β / °', yLabel: 'transport velocity v / (m/s)', markers: true, zeroLine: true, aspect: 0.5,
	});
	app.plots.experiment = new TimePlot($('#plot-experiment'), {
		series: [{ label: 'feed velocity / (m/s)', color: PALETTE[0] }, { label: 'β / °', color: PALETTE[3], scale: 'y2' }],
		yLabel: 'v / (m/s)', y2Label: 'β / °', y2Range: [0, 180], aspect: 0.5,
	});
}

function buildFeedPlot(K) {
	const el = $('#plot-feed');
	if (app.plots.feed && app.plots.feedK === K) return;
	app.plots.feed?.destroy();
	const series = K ? Array.from({ length: K }, (_, k) => ({ label: `column ${k + 1}` })) : [{ label: 'columns', color: '#94a3b8' }];
	app.plots.feed = new TimePlot(el, { series, yLabel: 'displacement / mm' });
	app.plots.feedK = K;
}

let lastDraw = 0;
function frame(now) {
	requestAnimationFrame(frame);
	if (!app.dirty || now - lastDraw < 50) return;
	lastDraw = now;
	app.dirty = false;
	draw();
}

function draw() {
	const tr = app.traces;
	if (tr) {
		const o = tr.orbit.data();
		app.plots.orbit.setData([[o[1], o[2]]]);
		app.plots.strokes.setData(tr.strokes.data());
		app.plots.trough.setData(tr.trough.data());
		app.plots.rotor.setData(tr.rotor.data());
		if (app.columns) app.plots.feed.setData(tr.feed.data());
		$('#live-state').dataset.samples = String(app.samples);
		$('#live-state').dataset.dropped = String(app.dropped);
		if (app.stream && app.samples)
			$('#live-state').textContent = `stream: ${app.samples} samples` + (app.dropped ? `, ${app.dropped} missed (slow client)` : '');
	}
	const v = currentVelocity();
	const dir = direction(v);
	app.lastVelocity = v;
	$('#v-value').textContent = fmtVelocity(v);
	const arrow = $('#v-arrow');
	arrow.textContent = ARROW[dir];
	arrow.dataset.direction = dir;
	$('#tile-velocity').dataset.direction = dir;
	$('#v-dir').textContent = dir === 'right' ? 'feed moves right (+x)' : dir === 'left' ? 'feed moves left (−x)' : dir === 'still' ? 'feed at rest' : 'no reading yet';
	const s = app.session;
	const last = app.lastSample;
	const strokes = tr?.strokes.data();
	const range = strokes && strokes[0].length ? [1, 2].map(c => {
		const v = strokes[c].filter(Number.isFinite);
		return v.length ? [Math.min(...v) / MM, Math.max(...v) / MM] : null;
	}) : undefined;
	app.schematic.update({
		beta: Number.isFinite(last?.beta) ? last.beta : s?.beta ?? numberOf($('#session-form').elements.beta),
		betaTarget: s?.betaTarget,
		rotation: last?.rotation ?? s?.rotation ?? $('#session-form').elements.rotation.value,
		strokes: last?.strokes,
		phase: last?.phi,
		strokeRange: range,
		columns: app.columns || (s ? (s.feed === false ? 0 : s.columns) : ($('#session-form').elements.feed.checked ? numberOf($('#session-form').elements.columns) : 0)),
		layers: s?.layers ?? numberOf($('#session-form').elements.layers),
		direction: dir,
	});
}

/* ---- sweeps and experiments ------------------------------------------------ */

function progress(box, frac, text) {
	box.hidden = false;
	box.querySelector('.bar').style.width = `${Math.round((Number.isFinite(frac) ? frac : 0) * 100)}%`;
	box.querySelector('.ptext').textContent = text;
}

async function poll(get, id, onUpdate) {
	for (;;) {
		await new Promise(r => setTimeout(r, JOB_POLL_MS));
		let j;
		try {
			j = await get(id);
			setOnline(true);
		} catch (err) {
			if (err instanceof api.NetworkError) { setOnline(false); continue; }
			throw err;
		}
		onUpdate(j);
		if (j.done) return j;
	}
}

async function runSweep(ev) {
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

async function runExperiment(ev) {
	ev.preventDefault();
	const f = $('#experiment-form').elements;
	const base = readSessionForm();
	const form = { ...base, beta1: numberOf(f.beta1), beta2: numberOf(f.beta2), tSwitch: numberOf(f.t_switch), tEnd: numberOf(f.t_end) };
	const btn = $('#experiment-run');
	const box = $('#experiment-progress');
	busy(btn, true);
	app.experiment = null;
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
		const end = await poll(api.getExperiment, j.id, u => {
			showExperiment(u, form);
			const tText = Number.isFinite(u.t) ? ` · t = ${fmtTime(u.t)}` : '';
			progress(box, Number.isFinite(u.progress) ? u.progress : (u.t / form.tEnd), `${u.state || 'running'}${tText}`);
		});
		if (end.failed) message('error', `Experiment ${end.id} ${end.state}${end.error ? ': ' + end.error : ''}`);
		else message('ok', `Experiment ${end.id} finished.`);
		if (end.sessionId) {
			/* the recorded history gives the whole reversal, whatever the stream saw */
			const traj = await api.trajectory(end.sessionId).catch(() => null);
			showExperiment(end, form, traj);
		}
	} catch (err) {
		report(err, 'Experiment', $('#experiment-form'));
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
	for (const h of ['segment', 'β / °', 'from / s', 'steady v / (m/s)', 'reversal / s']) head.append(Object.assign(document.createElement('th'), { textContent: h }));
	const body = table.createTBody();
	j.segments.forEach((s, i) => {
		const row = body.insertRow();
		row.insertCell().textContent = String(i + 1);
		row.insertCell().textContent = fmt(s.beta, 1);
		row.insertCell().textContent = fmt(s.tStart, 2);
		const vc = row.insertCell();
		vc.textContent = `${fmtVelocity(s.v).replace(' m/s', '')} ${ARROW[direction(s.v)]}`;
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
		marks.push({ x: s.tStart, label: `β → ${fmt(s.beta, 0)}°`, color: '#d97706' });
		if (Number.isFinite(s.reversalTime))
			marks.push({ x: s.tStart + s.reversalTime, label: `90 % after ${fmt(s.reversalTime, 3)} s`, color: '#7c3aed', row: 1 });
	});
	app.plots.experiment.setMarkers(marks);
}

/* ---- wiring ------------------------------------------------------------------ */

function wire() {
	$('#session-form').addEventListener('submit', startSession);
	$('#pause').onclick = () => patch({ running: false }, 'Pause');
	$('#resume').onclick = () => patch({ running: true }, 'Resume');
	$('#delete').onclick = removeSession;
	$('#flip').onclick = () => {
		const now = app.session?.rotation ?? 'cw';
		patch({ rotation: now === 'cw' ? 'ccw' : 'cw' }, 'Rotation change');
	};
	$('#motor').onclick = () => {
		const on = app.session?.driveOn !== false;
		patch({ motor_on: !on }, on ? 'Drive off' : 'Drive on');
	};
	$('#omega-ss').addEventListener('change', () => {
		const w = numberOf($('#omega-ss'));
		if (Number.isFinite(w)) patch({ omega_ss: w }, 'ω_ss change');
	});
	$('#pace-live').addEventListener('change', () => {
		const text = $('#pace-live').value.trim();
		const pace = text === 'max' ? 'max' : Number(text);
		patch({ pace }, 'Pace change');
	});
	const slider = $('#beta-slider'), number = $('#beta-number');
	slider.addEventListener('input', () => { app.betaEditing = true; number.value = slider.value; });
	slider.addEventListener('change', async () => {
		await setBeta(Number(slider.value));
		app.betaEditing = false;
	});
	number.addEventListener('change', () => {
		const v = numberOf(number);
		if (Number.isFinite(v)) { slider.value = String(v); setBeta(v); }
	});
	for (const b of $$('.quick')) b.addEventListener('click', () => {
		const v = Number(b.dataset.beta);
		slider.value = String(v); number.value = String(v);
		setBeta(v);
	});
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
	$('#experiment-form').addEventListener('submit', runExperiment);
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
