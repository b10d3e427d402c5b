// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * api-normalize.js - the daemon's JSON as the dashboard's plain objects.
 *
 * Every JSON field name of the daemon's /api/v1 answers lives here: the
 * normalize* functions return plain objects (units: SI, beta in degrees,
 * rotation "cw"/"ccw") and the rest of the page sees only those. When the
 * API renames a field, change the lookup lists in FIELDS below; nothing
 * else should need to move. No DOM, no network; node:test covers it
 * (through api.js, which re-exports it).
 */

/* Alternative names for each normalized field, first match wins. A dotted
 * name looks inside nested objects ("status.t" = raw.status.t). */
export const FIELDS = {
	session: {
		id: ['id', 'session_id'],
		t: ['status.t', 't', 'time', 'status.time'],
		beta: ['status.beta', 'status.beta.now', 'beta.now', 'beta_now', 'status.beta_now', 'beta'],
		betaTarget: ['status.beta_target', 'status.beta.target', 'beta.target', 'beta_target'],
		betaRate: ['status.beta.rate', 'beta.rate', 'status.beta_rate', 'beta_rate', 'spec.params.beta_rate'],
		rotation: ['status.rotation', 'rotation', 'spec.params.rotation', 'params.rotation'],
		rotorSpeed: ['status.rotor_speed', 'rotor_speed', 'status.rotor.speed', 'rotor.speed'],
		omegaSs: ['status.omega_ss', 'omega_ss', 'spec.params.omega_ss', 'params.omega_ss'],
		driveOn: ['status.drive_on', 'drive_on'],
		transportVelocity: ['status.transport_velocity', 'transport_velocity', 'status.transport.velocity', 'transport.velocity'],
		transportUncertainty: ['status.transport_velocity_uncertainty', 'transport_velocity_uncertainty'],
		steady: ['status.steady', 'steady'],
		tol: ['status.tol', 'tol'],
		tolMet: ['status.tol_met', 'tol_met'],
		stepError: ['status.step_error', 'step_error'],
		dt: ['status.dt', 'dt'],
		substeps: ['status.substeps', 'substeps'],
		rotorSpeedMean: ['status.rotor_speed_mean', 'rotor_speed_mean'],
		feedVelocity: ['status.feed_velocity', 'feed_velocity'],
		running: ['status.running', 'running'],
		state: ['state', 'status.state'],
		pauseReason: ['pause_reason'],
		cpuSeconds: ['cpu_seconds'],
		experiment: ['experiment'],
		until: ['until', 'spec.until'],
		sampleRate: ['sample_rate'],
		pace: ['status.pace', 'pace', 'spec.pace'],
		realTimeFactor: ['status.real_time_factor', 'real_time_factor', 'status.rtf', 'rtf'],
		stepsPerSecond: ['status.steps_per_s', 'steps_per_s', 'status.steps_per_second', 'steps_per_second'],
		steps: ['status.steps', 'steps'],
		reductions: ['status.reduction_figures', 'status.reductions', 'reductions', 'model.reductions'],
		columns: ['columns', 'spec.scene.columns', 'scene.columns', 'status.columns'],
		layers: ['layers', 'spec.scene.layers', 'scene.layers', 'status.layers'],
		feed: ['spec.scene.feed', 'scene.feed'],
		modelError: ['status.model_error', 'model_error'],
		modelErrorUncertainty: ['status.model_error_uncertainty', 'model_error_uncertainty'],
		modelChecked: ['status.model_checked', 'model_checked'],
		modelCheckNote: ['status.model_check_note', 'model_check_note'],
		drive: ['spec.scene.drive', 'scene.drive'],
		method: ['spec.integrator.method', 'integrator.method'],
		start: ['spec.scene.start', 'scene.start'],
		preset: ['preset', 'spec.preset'],
		error: ['error', 'status.error'],
	},
	sample: {
		index: ['i', 'index', 'id'],
		t: ['t', 'time'],
		beta: ['beta', 'beta_now'],
		betaTarget: ['beta_target'],
		rotation: ['rotation'],
		deckX: ['deck_x', 'orbit.x', 'deck.x'],
		deckY: ['deck_y', 'orbit.y', 'deck.y'],
		troughX: ['x', 'trough.x'],
		troughY: ['y', 'trough.y'],
		alpha: ['alpha', 'trough.alpha'],
		phi: ['phi', 'rotor.phi'],
		rotorSpeed: ['rotor_speed', 'rotor.speed'],
		motorTorque: ['motor_torque', 'rotor.torque'],
		s1: ['s1', 'eliminators.s1'],
		s2: ['s2', 'eliminators.s2'],
		columns: ['columns', 'feed.columns'],
		feedMean: ['feed_displacement', 'feed.mean'],
		feedVelocity: ['feed_velocity', 'feed.velocity'],
		transportVelocity: ['transport_velocity', 'feed.transport_velocity'],
		transportUncertainty: ['transport_velocity_uncertainty'],
		steady: ['steady'],
	},
	control: {
		t: ['t_effective', 'effective_t', 't', 'time'],
		beta: ['applied.beta', 'beta', 'beta_target'],
		betaRate: ['applied.beta_rate', 'beta_rate'],
		rotation: ['applied.rotation', 'rotation'],
		running: ['applied.running', 'running'],
		omegaSs: ['applied.omega_ss', 'omega_ss'],
		pace: ['applied.pace', 'pace'],
	},
	sweep: {
		id: ['id'],
		state: ['status.state', 'state', 'status'],
		progress: ['progress.fraction', 'progress', 'status.progress'],
		done: ['progress.done', 'done', 'completed'],
		total: ['progress.total', 'total'],
		results: ['results', 'points', 'result', 'data'],
	},
	experiment: {
		id: ['id'],
		state: ['status.state', 'state', 'status'],
		progress: ['progress.fraction', 'progress', 'status.progress'],
		t: ['t', 'status.t', 'progress.t'],
		tStart: ['t_start'],
		tEnd: ['t_end', 'spec.t_end'],
		segments: ['segments', 'results.segments', 'result.segments', 'results'],
		trace: ['trace', 'results.trace', 'feed_velocity'],
		sessionId: ['session', 'session_id', 'session.id'],
	},
};

/* ---- small value helpers ---------------------------------------------- */

function lookup(obj, path) {
	let v = obj;
	for (const key of path.split('.')) {
		if (v === null || typeof v !== 'object' || !(key in v)) return undefined;
		v = v[key];
	}
	return v;
}

/* First value found under any of the paths (undefined if none). */
export function pick(obj, paths) {
	if (obj === null || typeof obj !== 'object') return undefined;
	for (const p of paths) {
		const v = lookup(obj, p);
		if (v !== undefined) return v;
	}
	return undefined;
}

/* A finite number or NaN (JSON null, strings and objects become NaN). */
export function num(v) {
	if (typeof v === 'number') return Number.isFinite(v) ? v : NaN;
	if (typeof v === 'string' && v.trim() !== '') {
		const x = Number(v);
		return Number.isFinite(x) ? x : NaN;
	}
	return NaN;
}

/* "cw"/"ccw" from the API's spellings (strings, or the core's +1/-1: the
 * paper's clockwise is phi' > 0, docs/MODEL.md). */
export function rotationName(v) {
	if (v === 1 || v === 'cw' || v === 'CW' || v === 'clockwise') return 'cw';
	if (v === -1 || v === 'ccw' || v === 'CCW' || v === 'counterclockwise' || v === 'counter-clockwise') return 'ccw';
	return undefined;
}

/* A number list from an array, or from an object's values in key order
 * ({s1, s2} or {x, y}); [] when absent. */
export function numList(v, keys) {
	if (Array.isArray(v)) return v.map(num);
	if (v && typeof v === 'object') {
		if (keys) return keys.map(k => num(v[k]));
		return Object.values(v).filter(x => typeof x === 'number' || x === null).map(num);
	}
	if (typeof v === 'number') return [num(v)];
	return [];
}

/* ---- normalizers ------------------------------------------------------- */

/* true/false, or undefined when the member is absent or null. */
function flag(v) {
	return typeof v === 'boolean' ? v : undefined;
}

function scalar(raw, paths) {
	const v = pick(raw, paths);
	if (v && typeof v === 'object') return NaN;
	return num(v);
}

function reductionList(v) {
	if (!v) return [];
	const list = Array.isArray(v) ? v : Object.entries(v).map(([name, r]) =>
		(r && typeof r === 'object') ? { name, ...r } : (r ? { name } : null)).filter(Boolean);
	return list.map(r => typeof r === 'string' ? { name: r, speedup: NaN, error: NaN } : {
		name: String(r.name ?? r.reduction ?? r.id ?? '?'),
		speedup: num(r.speedup ?? r.speed_up),
		error: num(r.error ?? r.measured_error ?? r.max_error),
	});
}

/* A session resource (POST answer, GET item, list element) as
 * {id, t, beta, betaTarget, rotation, rotorSpeed, transportVelocity, ...}. */
export function normalizeSession(raw) {
	const F = FIELDS.session;
	const state = pick(raw, F.state);
	let running = pick(raw, F.running);
	if (typeof running !== 'boolean')
		running = typeof state === 'string' ? /run/i.test(state) : undefined;
	const pace = pick(raw, F.pace);
	return {
		id: pick(raw, F.id) !== undefined ? String(pick(raw, F.id)) : undefined,
		t: scalar(raw, F.t),
		beta: scalar(raw, F.beta),
		betaTarget: scalar(raw, F.betaTarget),
		betaRate: scalar(raw, F.betaRate),
		rotation: rotationName(pick(raw, F.rotation)),
		rotorSpeed: scalar(raw, F.rotorSpeed),
		omegaSs: scalar(raw, F.omegaSs),
		driveOn: typeof pick(raw, F.driveOn) === 'boolean' ? pick(raw, F.driveOn) : undefined,
		transportVelocity: scalar(raw, F.transportVelocity),
		transportUncertainty: scalar(raw, F.transportUncertainty),
		steady: flag(pick(raw, F.steady)),
		tol: scalar(raw, F.tol),
		tolMet: flag(pick(raw, F.tolMet)),
		stepError: scalar(raw, F.stepError),
		dt: scalar(raw, F.dt),
		substeps: scalar(raw, F.substeps),
		rotorSpeedMean: scalar(raw, F.rotorSpeedMean),
		feedVelocity: scalar(raw, F.feedVelocity),
		running,
		state: typeof state === 'string' ? state : (running === false ? 'paused' : running ? 'running' : ''),
		pace: pace === 'max' ? 'max' : num(pace),
		realTimeFactor: scalar(raw, F.realTimeFactor),
		stepsPerSecond: scalar(raw, F.stepsPerSecond),
		steps: scalar(raw, F.steps),
		reductions: reductionList(pick(raw, F.reductions)),
		columns: scalar(raw, F.columns),
		layers: scalar(raw, F.layers),
		feed: pick(raw, F.feed),
		/* how far the column model is from a DEM bed here (docs/dem.md) */
		modelError: scalar(raw, F.modelError),
		modelErrorUncertainty: scalar(raw, F.modelErrorUncertainty),
		modelChecked: pick(raw, F.modelChecked) === true,
		modelCheckNote: typeof pick(raw, F.modelCheckNote) === 'string' ? pick(raw, F.modelCheckNote) : '',
		drive: pick(raw, F.drive),
		method: pick(raw, F.method),
		start: pick(raw, F.start),
		preset: pick(raw, F.preset),
		error: pick(raw, F.error),
		experiment: pick(raw, F.experiment) ?? null,
		until: scalar(raw, F.until), /* the simulated end time, s (NaN: none) */
		/* why it is paused ("client", "cpu-budget"; '' when it is not) and
		 * the CPU seconds it has used (docs/budgets.md) */
		pauseReason: typeof pick(raw, F.pauseReason) === 'string' ? pick(raw, F.pauseReason) : '',
		cpuSeconds: scalar(raw, F.cpuSeconds),
		sampleRate: scalar(raw, F.sampleRate),
	};
}

/* One stream sample as {index, t, beta, betaTarget, rotation, deck:[x,y],
 * trough:[x,y,alpha], phi, rotorSpeed, motorTorque, strokes:[s1,s2],
 * columns:[...], feedMean, feedVelocity, transportVelocity}; vectors are
 * [] when the stream does not carry them. */
export function normalizeSample(raw, eventId) {
	const F = FIELDS.sample;
	const v = name => scalar(raw, F[name]);
	const pair = (a, b) => {
		const x = v(a), y = v(b);
		return Number.isFinite(x) || Number.isFinite(y) ? [x, y] : [];
	};
	const index = v('index');
	let columns = pick(raw, F.columns);
	columns = Array.isArray(columns) ? columns.map(num) : [];
	let feedMean = v('feedMean');
	if (!Number.isFinite(feedMean) && columns.length)
		feedMean = columns.reduce((a, b) => a + b, 0) / columns.length;
	const trough = pair('troughX', 'troughY');
	if (trough.length) trough.push(v('alpha'));
	return {
		index: Number.isFinite(index) ? index : num(eventId),
		t: v('t'),
		beta: v('beta'),
		betaTarget: v('betaTarget'),
		rotation: rotationName(pick(raw, F.rotation)),
		deck: pair('deckX', 'deckY'),
		trough,
		phi: v('phi'),
		rotorSpeed: v('rotorSpeed'),
		motorTorque: v('motorTorque'),
		strokes: pair('s1', 's2'),
		columns,
		feedMean,
		feedVelocity: v('feedVelocity'),
		transportVelocity: v('transportVelocity'),
		transportUncertainty: v('transportUncertainty'),
		steady: flag(pick(raw, F.steady)),
	};
}

/* A control event (or a PATCH answer) as {t, beta, betaRate, rotation,
 * running, omegaSs, pace}; absent members stay undefined/NaN. */
export function normalizeControl(raw) {
	const F = FIELDS.control;
	const running = pick(raw, F.running);
	return {
		t: scalar(raw, F.t),
		beta: scalar(raw, F.beta),
		betaRate: scalar(raw, F.betaRate),
		rotation: rotationName(pick(raw, F.rotation)),
		running: typeof running === 'boolean' ? running : undefined,
		omegaSs: scalar(raw, F.omegaSs),
		pace: pick(raw, F.pace),
	};
}

function progressOf(raw, F) {
	let p = pick(raw, F.progress);
	if (p && typeof p === 'object') p = p.fraction ?? (p.total ? p.done / p.total : undefined);
	p = num(p);
	if (!Number.isFinite(p) && F.done) {
		const done = num(pick(raw, F.done)), total = num(pick(raw, F.total));
		if (total > 0) p = done / total;
	}
	if (p > 1.0001) p /= 100; /* a percentage */
	return p;
}

function stateOf(raw, F) {
	const s = pick(raw, F.state);
	return typeof s === 'string' ? s : (s && typeof s.state === 'string' ? s.state : '');
}

/* v(beta) points of a sweep, flattened to [{beta, rotation, v}], with u
 * (the error bar, m/s), steady, dt and substeps where the daemon gives them. Accepts a
 * list of points or an object keyed by rotation holding lists or columns.
 * A study's points (vary names other settings) carry `at`: each varied
 * setting's value by name. */
export function sweepPoints(results, vary = ['beta']) {
	const out = [];
	const study = vary.some(n => n !== 'beta');
	const push = (beta, rotation, v, p) => {
		const b = num(beta);
		if (!Number.isFinite(b) && !study) return;
		const point = { beta: b, rotation: rotationName(rotation), v: num(v) };
		/* a study's point: its value of each varied setting */
		if (study && p) point.at = Object.fromEntries(vary.map(n => [n, num(p[n])]));
		if (p && 'uncertainty' in p) point.u = num(p.uncertainty);
		if (p && typeof p.steady === 'boolean') point.steady = p.steady;
		/* the steps it was measured with: machine step (s), feed sub-steps */
		if (p && 'dt' in p) point.dt = num(p.dt);
		if (p && 'substeps' in p) point.substeps = num(p.substeps);
		/* band_from_fit: the 95 % band at the point (m/s) */
		if (p && p.band && typeof p.band === 'object') point.band = [num(p.band.lower), num(p.band.upper)];
		out.push(point);
	};
	const vOf = p => p.transport_velocity ?? p.v ?? p.velocity;
	if (Array.isArray(results)) {
		for (const p of results) if (p && typeof p === 'object') push(p.beta, p.rotation, vOf(p), p);
	} else if (results && typeof results === 'object') {
		for (const [rot, list] of Object.entries(results)) {
			if (Array.isArray(list)) {
				for (const p of list) if (p && typeof p === 'object') push(p.beta, p.rotation ?? rot, vOf(p), p);
			} else if (list && Array.isArray(list.beta)) {
				const vs = list.transport_velocity ?? list.v ?? [];
				list.beta.forEach((b, i) => push(b, rot, vs[i]));
			}
		}
	}
	return out.filter(p => p.rotation);
}

/* The varied settings' names of a sweep (["beta"] for a plain one). */
function sweepVary(raw) {
	const v = raw && Array.isArray(raw.vary) ? raw.vary.map(a => a && a.name).filter(n => typeof n === 'string') : [];
	return v.length ? v : ['beta'];
}

export function normalizeSweep(raw) {
	const F = FIELDS.sweep;
	const state = stateOf(raw, F);
	return {
		id: pick(raw, F.id) !== undefined ? String(pick(raw, F.id)) : undefined,
		state,
		progress: progressOf(raw, F),
		vary: sweepVary(raw),
		points: sweepPoints(pick(raw, F.results), sweepVary(raw)),
		done: isFinished(state),
		failed: isFailed(state),
		error: raw && (raw.error ?? raw.detail),
	};
}

export function normalizeExperiment(raw) {
	const F = FIELDS.experiment;
	const state = stateOf(raw, F);
	let segs = pick(raw, F.segments);
	if (!Array.isArray(segs)) segs = [];
	const segments = segs.filter(s => s && typeof s === 'object').map(s => ({
		beta: num(s.beta ?? s.target),
		until: num(s.until),
		state: typeof s.state === 'string' ? s.state : '',
		tStart: num(s.t_command ?? s.t_start ?? s.from),
		tEnd: num(s.t_end ?? s.to),
		v: num(s.steady_velocity ?? s.transport_velocity ?? s.v),
		meanVelocity: num(s.mean_velocity),
		uncertainty: num(s.uncertainty),
		steady: flag(s.steady),
		startVelocity: num(s.start_velocity),
		reversalTime: num(s.reversal_time ?? s.t_reversal),
	}));
	const trace = pick(raw, F.trace);
	let traceT = [], traceV = [];
	if (trace && Array.isArray(trace.t)) {
		traceT = trace.t.map(num);
		traceV = (trace.v ?? trace.feed_velocity ?? trace.velocity ?? []).map(num);
	} else if (Array.isArray(trace)) {
		for (const p of trace) {
			if (Array.isArray(p)) { traceT.push(num(p[0])); traceV.push(num(p[1])); }
			else if (p && typeof p === 'object') { traceT.push(num(p.t)); traceV.push(num(p.v ?? p.feed_velocity)); }
		}
	}
	const sid = pick(raw, F.sessionId);
	return {
		id: pick(raw, F.id) !== undefined ? String(pick(raw, F.id)) : undefined,
		state,
		progress: progressOf(raw, F),
		t: scalar(raw, F.t),
		tStart: scalar(raw, F.tStart),
		tEnd: scalar(raw, F.tEnd),
		segments,
		trace: { t: traceT, v: traceV },
		sessionId: sid !== undefined && typeof sid !== 'object' ? String(sid) : undefined,
		done: isFinished(state),
		failed: isFailed(state),
		error: raw && (raw.error ?? raw.detail),
	};
}

/* A job's end: done, or ended early (an experiment aborted with its
 * session or interrupted by a restart, a record damaged on disk), which
 * the page reports as a failure instead of waiting on. */
export function isFinished(state) {
	return /^(done|finished|complete|completed|succeeded|success|ok|failed|error|cancel+ed|aborted|interrupted|damaged)$/i.test(state || '');
}
export function isFailed(state) {
	return /^(failed|error|cancel+ed|aborted|interrupted|damaged)$/i.test(state || '');
}

/* A preset list from {presets:[...]}, [...] of names, or [...] of objects. */
export function normalizePresets(raw) {
	let list = Array.isArray(raw) ? raw : (raw && (raw.presets ?? raw.items)) ?? [];
	if (!Array.isArray(list) && typeof list === 'object') list = Object.keys(list);
	return list.map(p => typeof p === 'string' ? { name: p, doc: '' }
		: { name: String(p.name ?? p.id), doc: String(p.doc ?? p.description ?? p.title ?? ''), params: p.params, scene: p.scene, integrator: p.integrator });
}

/* Integrators as [{name, order, adaptive, doc}] from names or objects. */
export function normalizeMethods(list) {
	if (!Array.isArray(list)) return [];
	return list.map(m => typeof m === 'string' ? { name: m, order: NaN, adaptive: false, doc: '' }
		: { name: String(m.name), order: num(m.order), adaptive: !!m.adaptive, doc: String(m.doc ?? '') })
		.filter(m => m.name && m.name !== 'undefined');
}

/* The recorded history of a session ({fields, rows} of its trajectory) as
 * columns by field name, {t: [...], beta: [...], feed_velocity: [...], ...}. */
export function trajectoryColumns(d) {
	const fields = Array.isArray(d?.fields) ? d.fields.map(String) : [];
	const rows = Array.isArray(d?.rows) ? d.rows : [];
	const out = {};
	fields.forEach((f, i) => { out[f] = rows.map(r => num(Array.isArray(r) ? r[i] : undefined)); });
	return out;
}

/* Integrator names: the enum of a "method" property anywhere in the
 * daemon's OpenAPI document; [] if it has none. */
export function methodEnum(doc) {
	const seen = new Set();
	const walk = v => {
		if (!v || typeof v !== 'object' || seen.has(v)) return undefined;
		seen.add(v);
		const m = v.properties?.method;
		if (m && Array.isArray(m.enum)) return m.enum.map(String);
		for (const x of Object.values(v)) {
			const r = walk(x);
			if (r) return r;
		}
		return undefined;
	};
	return walk(doc) ?? [];
}
