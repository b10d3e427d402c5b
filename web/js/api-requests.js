// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * api-requests.js - what the dashboard sends the daemon: the base URL, the
 * bearer token's header, the request bodies of POST /sessions, /sweeps
 * and /experiments built from the forms' values, and the stream's query
 * string. No DOM, no network; node:test covers it (through api.js, which
 * re-exports it).
 */

export const BASE = '/api/v1';

/* The daemon's token for this tab (auth.js sets it from the URL fragment
 * or sessionStorage); '' when the daemon runs without one. */
let token = '';
export function setToken(t) {
	token = typeof t === 'string' ? t.trim() : '';
}
export function hasToken() {
	return token !== '';
}
/* The Authorization header every API request carries (none without a token). */
export function authHeaders() {
	return token ? { Authorization: `Bearer ${token}` } : {};
}

/* The POST /sessions body from the form's values (see session.js readSessionForm):
 * {preset, params: {beta, rotation[, beta_rate]}, scene: {columns, layers,
 * feed, drive[, start]}, integrator: {method[, dt]}, pace[, sample_rate]}. */
export function sessionRequest(f) {
	const body = {
		preset: f.preset,
		params: { beta: f.beta, rotation: f.rotation },
		scene: { columns: f.columns, layers: f.layers, feed: f.feed, drive: f.drive },
		integrator: { method: f.method },
		pace: f.pace,
	};
	if (f.start) body.scene.start = f.start;
	if (typed(f.betaRate)) body.params.beta_rate = f.betaRate;
	if (typed(f.dt)) body.integrator.dt = f.dt;
	if (typed(f.rate)) body.sample_rate = f.rate;
	return body;
}

/* Whether an optional field holds a value: an empty one (NaN) asks for the
 * daemon's default; anything typed goes as typed, 0 and -5 too, for the
 * daemon to refuse naming the member (integrator.dt 0 is the method's
 * default step, docs/api.md). */
function typed(v) {
	return typeof v === 'number' && !Number.isNaN(v);
}

/* The session form's model for a job that sets beta and rotation per
 * point (sweeps, fits): no pace, no sample rate, the feed on. */
function jobModel(f) {
	const body = sessionRequest(f);
	delete body.pace;
	delete body.sample_rate;
	delete body.params.beta;
	delete body.params.rotation;
	body.scene.feed = true;
	return body;
}

/* A study's settings as the form takes them, "mu=0.2:1.2:0.2; beta=0,90":
 * {NAME: {from, to, step}} for a range, {NAME: [v, ...]} for a list, or
 * null when empty. A value that is not a number goes as null, which the
 * daemon refuses naming the member. */
export function parseVary(text) {
	const vary = {};
	for (const part of String(text || '').split(/[;\s]+/).filter(Boolean)) {
		const eq = part.indexOf('=');
		const name = eq > 0 ? part.slice(0, eq) : part;
		const spec = eq > 0 ? part.slice(eq + 1) : '';
		const nums = spec.split(spec.includes(':') ? ':' : ',').map(x => (x.trim() === '' ? NaN : Number(x)));
		vary[name] = spec.includes(':') ? { from: nums[0], to: nums[1], step: nums[2] } : nums;
	}
	return Object.keys(vary).length ? vary : null;
}

/* POST /sweeps: the session form's model, a beta grid (or the study of
 * the form's vary), both rotations, and a fit's bands (bandFit: its id). */
export function sweepRequest(f) {
	const body = jobModel(f);
	const vary = parseVary(f.vary);
	if (vary) body.vary = vary;
	else body.beta = { from: f.from, to: f.to, step: f.step };
	body.rotations = ['cw', 'ccw'];
	body.t_end = f.tEnd;
	if (f.bandFit) body.band_from_fit = f.bandFit;
	return body;
}

/* POST /experiments: a fresh session from the form's model (the daemon
 * runs it at pace "max" unless told otherwise) and the schedule beta1
 * until tSwitch, then beta2 until tEnd. The session is kept after the
 * end (keep_session): the page plots and offers its trajectory. */
export function experimentRequest(f) {
	const session = sessionRequest({ ...f, beta: f.beta1 });
	session.scene.feed = true;
	if (f.experimentPace !== undefined) session.pace = f.experimentPace;
	else delete session.pace;
	const body = {
		session,
		schedule: [{ beta: f.beta1, until: f.tSwitch }, { beta: f.beta2, until: f.tEnd }],
		keep_session: true,
	};
	if (typed(f.betaRate)) body.beta_rate = f.betaRate;
	return body;
}

/* Query string of the stream: which fields, and since=ID to start from
 * that record (0: the oldest the daemon still holds, so the plots fill at
 * once on attach). */
export function streamQuery(opts = {}) {
	const q = new URLSearchParams();
	q.set('fields', (opts.fields ?? ['trough', 'orbit', 'rotor', 'eliminators', 'feed']).join(','));
	if (Number.isInteger(opts.since) && opts.since >= 0) q.set('since', String(opts.since));
	return q.toString();
}

/* POST /fits: the session form's model, the free names (NAME or
 * NAME:MIN:MAX), their priors as the command line writes them
 * (NAME:MEAN:SD, or NAME:MEAN:xFACTOR log-normal; a name not free is sent
 * as its own entry, for the daemon to refuse), the points as CSV text, the
 * time per evaluation and the curve's grid. */
export function fitRequest(f) {
	const body = jobModel(f);
	body.free = String(f.free).split(',').map(s => s.trim()).filter(Boolean).map(s => {
		const [name, min, max] = s.split(':');
		return min === undefined ? name : { name, min: Number(min), max: Number(max) };
	});
	for (const s of String(f.priors ?? '').split(',').map(x => x.trim()).filter(Boolean)) {
		const [name, mean, spread = ''] = s.split(':');
		const prior = spread.startsWith('x') ? { mean: Number(mean), factor: Number(spread.slice(1)) }
			: { mean: Number(mean), sd: Number(spread) };
		const at = body.free.findIndex(x => (x.name ?? x) === name);
		if (at < 0) body.free.push({ name, prior });
		else body.free[at] = { ...(typeof body.free[at] === 'string' ? { name } : body.free[at]), prior };
	}
	body.csv = f.csv;
	if (Number.isFinite(f.tEnd)) body.t_end = f.tEnd;
	if (Number.isFinite(f.curveStep)) body.curve_step = f.curveStep;
	return body;
}
