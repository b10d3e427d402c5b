// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * ui.js - what every part of the dashboard page shares: the page state
 * (app, also window.convsim for the console and the browser test), the
 * element lookups, the message bar, the daemon's connection state, reading
 * a number from an input, busy buttons, and the progress bar and polling
 * loop of a sweep or an experiment.
 */

import * as api from './api.js';
import { problemText } from './format.js';

const JOB_POLL_MS = 500;

export const $ = sel => document.querySelector(sel);
export const $$ = sel => Array.from(document.querySelectorAll(sel));

export const app = {
	session: null,        /* normalized status of the attached session */
	id: null,
	stream: null,
	statusTimer: 0,
	samples: 0,
	dropped: 0,
	columns: 0,
	traces: null,
	plots: {},
	lastFit: null,        /* the last finished fit's id: the sweep's band source */
	dirty: false,
	online: undefined,
	betaEditing: false,   /* the user is dragging the slider */
	lastVelocity: NaN,
	controls: [],         /* control events seen on the stream */
	pending: new Set(),   /* requests in flight, for button states */
};
window.convsim = app;     /* for the console and the browser test */

/* ---- messages ------------------------------------------------------------ */

export function message(kind, text, { key, sticky = false } = {}) {
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

/* The input of form behind the member field a problem names: the first
 * of fields ([RegExp, input name] pairs: the form's members whose input
 * has another name, or '#id' for an input outside it, such as the slew
 * rate) that matches, else the member's path read from its end, indices
 * dropped (scene.columns: columns; vary.mu: vary; free[0]: free). */
function fieldInput(form, field, fields = []) {
	const hit = fields.find(([re]) => re.test(field));
	if (hit) return hit[1].startsWith('#') ? $(hit[1]) : form.elements?.[hit[1]] ?? null;
	for (const part of field.split(/[./]/).reverse()) {
		const input = form.elements?.[part.replace(/\[\d*\]$/, '')];
		if (input) return input;
	}
	return null;
}

/* Report a failed request: a refused input shows the daemon's problem
 * detail and marks the input of form behind the member it names
 * (fieldInput: fields maps members to inputs of other names); an
 * unreachable daemon says so. */
export function report(err, what, form, fields) {
	if (err instanceof api.NetworkError) {
		setOnline(false);
		message('error', `${what}: ${err.message}`, { key: 'network', sticky: true });
		return;
	}
	if (err instanceof api.ApiError) {
		message('error', `${what} refused: ${problemText(err)}`, { key: `refused-${what}` });
		if (form && err.field) {
			const input = fieldInput(form, String(err.field), fields);
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

export function setOnline(on) {
	if (on === app.online) return;
	app.online = on;
	const c = $('#conn');
	c.dataset.state = on ? 'online' : 'offline';
	c.textContent = on ? 'daemon: connected' : 'daemon: unreachable';
	if (on) clearMessage('network');
	else message('error', 'The convsim daemon does not answer. Start it with build/convsimd (make run) and reload; the page retries by itself.', { key: 'network', sticky: true });
}

export function numberOf(input) {
	const s = String(input?.value ?? '').trim();
	return s === '' ? NaN : Number(s);
}

export function busy(button, on) {
	if (!button) return;
	button.classList.toggle('busy', on);
	button.disabled = on;
}

/* ---- sweeps and experiments ------------------------------------------------ */

export function progress(box, frac, text) {
	box.hidden = false;
	box.querySelector('.bar').style.width = `${Math.round((Number.isFinite(frac) ? frac : 0) * 100)}%`;
	box.querySelector('.ptext').textContent = text;
}

/* Poll get(id) every JOB_POLL_MS, onUpdate each answer, until the job is
 * over (its last answer) or signal (an AbortSignal, optional) aborts: null,
 * the wait cut short, an answer or an error still on its way dropped. */
export async function poll(get, id, onUpdate, signal) {
	for (;;) {
		await new Promise(r => {
			const wake = () => { clearTimeout(t); signal?.removeEventListener('abort', wake); r(); };
			const t = setTimeout(wake, JOB_POLL_MS);
			signal?.addEventListener('abort', wake);
		});
		if (signal?.aborted) return null;
		let j;
		try {
			j = await get(id);
			setOnline(true);
		} catch (err) {
			if (signal?.aborted) return null;
			if (err instanceof api.NetworkError) { setOnline(false); continue; }
			throw err;
		}
		if (signal?.aborted) return null;
		onUpdate(j);
		if (j.done) return j;
	}
}
