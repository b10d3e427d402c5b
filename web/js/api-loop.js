// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * api-loop.js - the control kinds of experiment (docs/control.md) as the
 * dashboard sends and reads them: the POST /experiments body of a closed
 * loop ("control") or an identification ("identify") from the loop form's
 * values, and the answer's control and identify members as plain
 * objects. No DOM, no network; api.js re-exports it.
 */

import { sessionRequest } from './api-requests.js';

/* "0.10:4, -0.08:8" (v in m/s : until in s, comma or ';' separated) as
 * [{v, until}]. A part that is not two numbers goes as NaN, which the
 * daemon refuses naming the member. */
export function parseSetpoints(text) {
	return String(text || '').split(/[,;]/).map(s => s.trim()).filter(Boolean).map(p => {
		const [v, until] = p.split(':').map(x => (x === undefined || x.trim() === '' ? NaN : Number(x)));
		return { v, until };
	});
}

/* "3: omega_ss=150; 5: m_n=0.75, mu=0.3" as [{at, set: {name: value}}]:
 * each part AT: then NAME=VALUE pairs. */
export function parseDisturbances(text) {
	return String(text || '').split(';').map(s => s.trim()).filter(Boolean).map(p => {
		const colon = p.indexOf(':');
		const at = Number(colon > 0 ? p.slice(0, colon) : NaN);
		const set = {};
		for (const kv of p.slice(colon + 1).split(',').map(s => s.trim()).filter(Boolean)) {
			const [name, value] = kv.split('=').map(s => s.trim());
			set[name] = value === undefined || value === '' ? NaN : Number(value);
		}
		return { at, set };
	});
}

/* "60, 110" as [60, 110]. */
export function parseNumbers(text) {
	return String(text || '').split(/[,;\s]+/).filter(Boolean).map(Number);
}

/* POST /experiments of kind f.kind ("control" or "identify") on a fresh
 * session of the new-session form's model (feed on, pace "max"), kept
 * after the end: its recorded trajectory is the plot's v(t) and beta.
 * control: setpoints text, controller "auto" or kp, ki, disturbances
 * text; identify: beta points text, step, hold (blank: the daemon's
 * defaults). */
export function loopRequest(f) {
	const session = sessionRequest(f);
	session.scene.feed = true;
	delete session.pace;
	const body = { session, keep_session: true };
	if (f.kind === 'identify') {
		const beta = parseNumbers(f.points);
		body.identify = { beta: beta.length === 1 ? beta[0] : beta };
		if (Number.isFinite(f.step)) body.identify.step = f.step;
		if (Number.isFinite(f.hold)) body.identify.hold = f.hold;
		return body;
	}
	body.control = {
		setpoint: parseSetpoints(f.setpoints),
		controller: f.controller === 'pi' ? { kp: f.kp, ki: f.ki } : 'auto',
	};
	const dist = parseDisturbances(f.disturbances);
	if (dist.length) body.disturbances = dist;
	return body;
}

const num = v => (typeof v === 'number' && Number.isFinite(v) ? v : NaN);

function model(m) {
	const r = m || {};
	return {
		beta0: num(r.beta0), step: num(r.step),
		gain: num(r.gain), gainSe: num(r.gain_se),
		timeConstant: num(r.time_constant), timeConstantSe: num(r.time_constant_se),
		deadTime: num(r.dead_time), deadTimeSe: num(r.dead_time_se),
		v0: num(r.v0), rms: num(r.rms), slope: num(r.slope),
		tFrom: num(r.t_from), samples: num(r.samples),
	};
}

/* A curve the loop took up (control.curves[]): when, the scene's rotation
 * and omega_ss, the operating point and the curve's slope there, and the
 * gains in use from then on, re-tuned ("auto") or kept (given gains). */
function curve(k) {
	const r = k || {};
	return {
		t: num(r.t), rotation: r.rotation === 'ccw' ? 'ccw' : 'cw', omegaSs: num(r.omega_ss),
		beta0: num(r.beta0), slope: num(r.slope), retuned: r.retuned === true, kp: num(r.kp), ki: num(r.ki),
	};
}

/* The kind of an experiment answer and its control or identify member:
 * {kind: 'schedule'|'control'|'identify', control, identify}. */
export function normalizeLoop(raw) {
	const r = raw || {};
	const out = { kind: typeof r.kind === 'string' ? r.kind : 'schedule', control: null, identify: null };
	if (r.identify && typeof r.identify === 'object') {
		const id = r.identify;
		out.identify = { step: num(id.step), hold: num(id.hold), models: (Array.isArray(id.models) ? id.models : []).map(model) };
	}
	if (r.control && typeof r.control === 'object') {
		const c = r.control, g = c.controller || {};
		out.control = {
			tuning: typeof g.tuning === 'string' ? g.tuning : '',
			kp: num(g.kp), ki: num(g.ki), tauC: num(g.tau_c),
			identification: g.identification ? model(g.identification) : null,
			period: num(c.period),
			curveChanges: num(c.curve_changes),
			curves: (Array.isArray(c.curves) ? c.curves : []).map(curve),
			setpoints: (Array.isArray(c.setpoints) ? c.setpoints : []).map(s => ({
				v: num(s.v), settlingTime: num(s.settling_time), overshoot: num(s.overshoot),
				iae: num(s.iae), steadyError: num(s.steady_error),
			})),
			disturbances: (Array.isArray(c.disturbances) ? c.disturbances : []).map(d => ({
				at: num(d.at), set: d.set && typeof d.set === 'object' ? d.set : {},
				tApplied: num(d.t_applied), recoveryTime: num(d.recovery_time), maxDeviation: num(d.max_deviation),
			})),
		};
	}
	return out;
}

/* The feed's mean velocity over the excitation period that ends at each
 * row of a recorded trajectory (columns t, feed_displacement,
 * rotor_speed): the change of the feed displacement over one rotor turn
 * (2 pi / rotor speed, its start interpolated between rows) divided by
 * it, as the daemon samples v for these experiments; NaN for a row less
 * than a period after the first. */
export function periodVelocity(traj) {
	const t = traj?.t ?? [], x = traj?.feed_displacement ?? [], w = traj?.rotor_speed ?? [];
	const v = new Array(t.length).fill(NaN);
	let j = 0;
	for (let i = 0; i < t.length; i++) {
		const p = 2 * Math.PI / Math.abs(w[i]);
		const t0 = t[i] - p;
		if (!(p > 0) || !Number.isFinite(p) || t0 < t[0]) continue;
		while (j > 0 && t[j] > t0) j--;
		while (j + 1 < i && t[j + 1] <= t0) j++;
		const f = t[j + 1] > t[j] ? (t0 - t[j]) / (t[j + 1] - t[j]) : 0;
		const x0 = x[j] + f * (x[j + 1] - x[j]);
		v[i] = (x[i] - x0) / p;
	}
	return v;
}

/* An identification model's response at time ts (s, the session's
 * clock): v0 + K sum_j d_j (1 - exp(-(t - t_j - L) / T)) over the steps
 * (t_j: command times, d_j: beta changes in degrees). */
export function fopdtAt(m, steps, ts) {
	let y = m.v0;
	for (const s of steps) {
		const a = ts - s.t - m.deadTime;
		if (a > 0) y += m.gain * s.d * (1 - Math.exp(-a / m.timeConstant));
	}
	return y;
}
