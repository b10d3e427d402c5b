// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * api.js - the dashboard's one link to the convsimd daemon: the HTTP
 * client (one function an endpoint) and its errors.
 *
 * Everything that knows a URL, a request body or a JSON field name of the
 * daemon's /api/v1 lives in api*.js: request bodies in api-requests.js,
 * the answers' field names in api-normalize.js (FIELDS), the live stream in
 * api-stream.js. This module re-exports all three, so the rest of the page
 * (and node:test) imports api.js only. The rest of the page sees only the
 * plain objects the normalize* functions return (units: SI, beta in
 * degrees, rotation "cw"/"ccw").
 *
 * Every request carries the daemon's bearer token when the tab has one
 * (setToken, api-requests.js).
 *
 * Errors: a refused request throws ApiError carrying the problem+json body
 * (RFC 9457: type, title, status, detail and any extension members such as
 * the offending field and its range); an unreachable daemon throws
 * NetworkError. This module touches no DOM and runs under node:test.
 */

import { loopRequest, normalizeLoop } from './api-loop.js';
import { BASE, authHeaders, sessionRequest, sweepRequest, experimentRequest, fitRequest } from './api-requests.js';
import { normalizeSession, normalizeControl, normalizeSweep, normalizeExperiment,
	normalizePresets, normalizeMethods, trajectoryColumns, methodEnum, isFinished, isFailed } from './api-normalize.js';

export * from './api-normalize.js';
export * from './api-requests.js';
export * from './api-loop.js';
export { openStream } from './api-stream.js';

/* ---- errors ------------------------------------------------------------ */

export class ApiError extends Error {
	constructor(status, problem) {
		const p = problem && typeof problem === 'object' ? problem : {};
		const detail = p.detail || p.title || (typeof problem === 'string' && problem) || `HTTP ${status}`;
		super(detail);
		this.name = 'ApiError';
		this.status = status;
		this.problem = p;
		this.title = p.title || '';
		this.detail = detail;
		this.field = p.field ?? p.name ?? p.parameter ?? p.pointer;
	}
}

export class NetworkError extends Error {
	constructor(cause) {
		super('The convsim daemon does not answer. Is build/convsimd running, and is this page served by it?');
		this.name = 'NetworkError';
		this.cause = cause;
	}
}

/* ---- HTTP -------------------------------------------------------------- */

/* fetch with the token; an unreachable daemon throws NetworkError. */
async function send(url, init) {
	try {
		return await fetch(url, { ...init, headers: { ...init.headers, ...authHeaders() } });
	} catch (e) {
		throw new NetworkError(e);
	}
}

/* Every mutating request says Content-Type: application/json, even
 * without a body: the daemon refuses it otherwise (415). */
async function request(method, path, body) {
	const init = { method, headers: { Accept: 'application/json, application/problem+json' } };
	if (method !== 'GET') init.headers['Content-Type'] = 'application/json';
	if (body !== undefined) init.body = JSON.stringify(body);
	const res = await send(BASE + path, init);
	const text = await res.text().catch(() => '');
	let data = null;
	if (text) {
		try { data = JSON.parse(text); } catch { data = text; }
	}
	if (!res.ok) throw new ApiError(res.status, data);
	return { data, status: res.status, location: res.headers.get('Location') };
}

const enc = encodeURIComponent;

export async function health() {
	return (await request('GET', '/health')).data;
}
/* GET /presets: {presets: [{name, doc, params, scene, integrator}],
 * methods: [{name, order, adaptive, doc}]}. */
export async function catalog() {
	const d = (await request('GET', '/presets')).data;
	return { presets: normalizePresets(d), methods: normalizeMethods(d && d.methods) };
}
export async function listSessions() {
	const d = (await request('GET', '/sessions')).data;
	const list = Array.isArray(d) ? d : (d && (d.sessions ?? d.items)) ?? [];
	const out = list.map(normalizeSession);
	/* a cluster's replicas (--peers) that did not answer: [{peer, reason}];
	 * their sessions are missing from the list */
	out.unreachable = Array.isArray(d?.unreachable) ? d.unreachable : [];
	return out;
}
export async function createSession(form) {
	const r = await request('POST', '/sessions', sessionRequest(form));
	const s = normalizeSession(r.data);
	if (s.id === undefined && r.location) s.id = r.location.split('/').pop();
	return s;
}
export async function getSession(id) {
	return normalizeSession((await request('GET', `/sessions/${enc(id)}`)).data);
}
/* patch: any of {beta, beta_rate, rotation, omega_ss, motor_on, running, pace}. */
export async function patchSession(id, patch) {
	const d = (await request('PATCH', `/sessions/${enc(id)}`, patch)).data;
	return { raw: d, control: normalizeControl(d), session: normalizeSession(d) };
}
/* Where the daemon serves a sweep's results as CSV. */
export function sweepCsvUrl(id) {
	return `${BASE}/sweeps/${enc(id)}?format=csv`;
}
/* Where the daemon serves a session's recorded trajectory (format csv or
 * json) and an experiment's segments as CSV. */
export function trajectoryUrl(id, format) {
	return `${BASE}/sessions/${enc(id)}/trajectory?format=${format}`;
}
export function experimentCsvUrl(id) {
	return `${BASE}/experiments/${enc(id)}?format=csv`;
}
/* GET url (one of the *Url functions) with the token, as a Blob: what a
 * download link fetches when a plain link could not carry the header. */
export async function fetchBlob(url) {
	const res = await send(url, { method: 'GET', headers: {} });
	if (!res.ok) {
		const text = await res.text().catch(() => '');
		let data = text;
		try { data = JSON.parse(text); } catch { /* keep the text */ }
		throw new ApiError(res.status, data);
	}
	return res.blob();
}
export async function deleteSession(id) {
	await request('DELETE', `/sessions/${enc(id)}`);
}
/* GET /sessions/ID/trajectory as columns (trajectoryColumns); from/to in s. */
export async function trajectory(id, { from, to } = {}) {
	const q = new URLSearchParams({ format: 'json' });
	if (Number.isFinite(from)) q.set('from', String(from));
	if (Number.isFinite(to)) q.set('to', String(to));
	return trajectoryColumns((await request('GET', `/sessions/${enc(id)}/trajectory?${q}`)).data);
}
export async function createSweep(form) {
	return normalizeSweep((await request('POST', '/sweeps', sweepRequest(form))).data);
}
export async function getSweep(id) {
	return normalizeSweep((await request('GET', `/sweeps/${enc(id)}`)).data);
}
export async function createExperiment(form) {
	return normalizeExperiment((await request('POST', '/experiments', experimentRequest(form))).data);
}
export async function getExperiment(id) {
	return normalizeExperiment((await request('GET', `/experiments/${enc(id)}`)).data);
}
/* A closed loop or an identification (api-loop.js): the experiment as
 * normalizeExperiment gives it, with its kind, control and identify. */
const loopExperiment = d => ({ ...normalizeExperiment(d), ...normalizeLoop(d) });
export async function createLoopExperiment(form) {
	return loopExperiment((await request('POST', '/experiments', loopRequest(form))).data);
}
export async function getLoopExperiment(id) {
	return loopExperiment((await request('GET', `/experiments/${enc(id)}`)).data);
}
/* DELETE stops a running experiment and forgets it, running or ended;
 * its fresh session goes with it unless kept (keep_session). No body, as
 * deleteFit. onlyRunning: only while it runs (?only=running; an ended one
 * is kept and answered 409). */
export async function deleteExperiment(id, onlyRunning = false) {
	await request('DELETE', `/experiments/${enc(id)}${onlyRunning ? '?only=running' : ''}`);
}

export async function integratorNames() {
	return methodEnum((await request('GET', '/openapi.json')).data);
}

/* ---- fits ---------------------------------------------------------------- */

/* A fit job as the page uses it: progress, and the daemon's result object
 * (fields as docs/calibration.md "Calibration" lists them) once over. */
export function normalizeFit(raw) {
	const r = raw || {};
	return {
		id: r.id, state: r.state, phase: r.phase, iteration: r.iteration ?? 0,
		maxIter: r.max_iter ?? 1, evaluations: r.evaluations ?? 0, values: r.values || {},
		result: r.result || null,
		error: r.error || null, /* state "error": its record could not be written */
		done: isFinished(r.state),
		failed: isFailed(r.state),
		progress: r.state === 'done' ? 1 : Math.min(1, (r.iteration ?? 0) / (r.max_iter || 1)),
	};
}
export async function createFit(form) {
	return normalizeFit((await request('POST', '/fits', fitRequest(form))).data);
}
export async function getFit(id) {
	return normalizeFit((await request('GET', `/fits/${enc(id)}`)).data);
}
/* DELETE cancels a running fit. Content-Type: application/json as on
 * every mutating request, but no body: the daemon refuses a DELETE that
 * carries one (400). */
export async function deleteFit(id, onlyRunning = false) {
	await request('DELETE', `/fits/${enc(id)}${onlyRunning ? '?only=running' : ''}`);
}
export function fitCsvUrl(id) {
	return `${BASE}/fits/${enc(id)}?format=csv`;
}
