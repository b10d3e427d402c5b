// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * format.js - numbers, units and directions as the dashboard shows them.
 * SI throughout (displacements in mm where metres would be all zeros),
 * beta in degrees. No DOM here; node:test covers it.
 */

export const DASH = '–';

/* Fixed-point text with a unit, or a dash for a missing value. */
export function fmt(v, digits = 3, unit = '') {
	if (!Number.isFinite(v)) return DASH;
	const s = v.toFixed(digits);
	const z = /^-0\.?0*$/.test(s) ? s.slice(1) : s; /* no "-0.000" */
	return unit ? `${z} ${unit}` : z;
}

/* A time the page derives from the daemon's (a period's midpoint) on the
 * daemon's nanosecond grid, as the daemon writes times: k·dt reads 0.022,
 * not 0.022000000000000002. */
export function onGrid(t) {
	return Math.round(t * 1e9) / 1e9;
}

/* A number as a person wrote it: the shortest text of at most 15
 * significant digits (every decimal of up to 15 digits comes back from a
 * double as written), so a time on the step grid reads 0.022, not
 * 0.022000000000000002, a ramp's beta 31.4878125, and a setting as given
 * (121.9, not 122; 0.052, not 0.05). A dash for a missing value. */
export function fmtGiven(v, unit = '') {
	if (!Number.isFinite(v)) return DASH;
	const s = String(Number(v.toPrecision(15)));
	return unit ? `${s} ${unit}` : s;
}

/* Significant-digit text for values of any magnitude (steps/s, speed-ups). */
export function fmtSig(v, sig = 3, unit = '') {
	if (!Number.isFinite(v)) return DASH;
	let s;
	const a = Math.abs(v);
	if (a !== 0 && (a >= 1e6 || a < 1e-3)) s = v.toExponential(sig - 1);
	else s = String(Number(v.toPrecision(sig)));
	return unit ? `${s} ${unit}` : s;
}

/* Simulated time as "12.345 s". */
export function fmtTime(t) {
	return fmt(t, 3, 's');
}

/* Transport direction from a velocity (m/s): "right", "left" or "still"
 * when |v| is below `still` (default 1 mm/s), or "" when unknown. */
export function direction(v, still = 1e-3) {
	if (!Number.isFinite(v)) return '';
	if (Math.abs(v) < still) return 'still';
	return v > 0 ? 'right' : 'left';
}

export const ARROW = { right: '→', left: '←', still: '·', '': '' };

/* Velocity with explicit sign, m/s: "+0.123 m/s". */
export function fmtVelocity(v, digits = 3) {
	if (!Number.isFinite(v)) return DASH;
	const s = fmt(v, digits);
	return (v > 0 && Number(s) !== 0 ? '+' : '') + s + ' m/s';
}

/* A velocity with its error bar, m/s: "+0.153 ± 0.002 m/s"; without a
 * finite error bar the velocity alone. */
export function fmtVelocityPm(v, u, digits = 3) {
	if (!Number.isFinite(v) || !Number.isFinite(u)) return fmtVelocity(v, digits);
	return `${fmtVelocity(v, digits).replace(' m/s', '')} ± ${fmt(u, digits)} m/s`;
}

/* The estimate's state: "steady" (no drift beyond its scatter), "settling"
 * (not yet, or drifting), or "" when the daemon gives none. */
export function steadyLabel(steady) {
	return steady === true ? 'steady' : steady === false ? 'settling' : '';
}

/* beta reduced to [0, 180) degrees: beta is periodic with 180 degrees. */
export function wrapBeta(deg) {
	if (!Number.isFinite(deg)) return NaN;
	const r = ((deg % 180) + 180) % 180;
	return r === 180 ? 0 : r;
}

export const RAD_S_TO_RPM = 60 / (2 * Math.PI);

export function rotationLabel(r) {
	return r === 'cw' ? 'clockwise' : r === 'ccw' ? 'counter-clockwise' : DASH;
}

/* Pace as shown: "max" or "1×". */
export function fmtPace(p) {
	if (p === 'max') return 'max';
	return Number.isFinite(p) ? `${fmtSig(p, 3)}×` : DASH;
}

/* Parse the pace field: "max" or a positive number; undefined if neither. */
export function parsePace(text) {
	const s = String(text).trim().toLowerCase();
	if (s === 'max') return 'max';
	const x = Number(s);
	return Number.isFinite(x) && x > 0 ? x : undefined;
}

/* The text of a refused request: the problem's title, detail and the
 * field it names, each once. */
export function problemText(err) {
	if (!err) return '';
	const p = err.problem || {};
	const parts = [];
	const detail = p.detail || err.detail || err.message || '';
	if (p.title && !detail.toLowerCase().startsWith(String(p.title).toLowerCase())) parts.push(p.title + ':');
	parts.push(detail);
	const field = err.field ?? p.field;
	if (field && !detail.includes(String(field))) parts.push(`(field: ${field})`);
	const status = err.status ?? p.status;
	const head = status ? `${status} ` : '';
	return head + parts.join(' ').trim();
}

/* A fit's progress line: its state, the phase while it runs (not "done ·
 * done"), the iteration, evaluations and current values. */
export function fitProgressText(u) {
	const phase = u.phase && u.phase !== u.state ? ` · ${u.phase}` : '';
	const values = Object.entries(u.values ?? {}).map(([k, v]) => `${k} = ${fmt(v, 5)}`).join(', ');
	return `${u.state}${phase} · iteration ${u.iteration} · ${u.evaluations} evaluations` + (values ? ` · ${values}` : '');
}

/* χ² with its unit (none when every datum has its σ, else the data's unit
 * squared: (m/s)² for points, deg² for peaks) and the reduced χ²/dof, at
 * three significant digits so that a small cost is not rounded away. */
export function fitChi2Text(r) {
	const unit = { '(m/s)^2': ' (m/s)²', 'deg^2': ' deg²' }[r.chi2_unit] ?? '';
	const reduced = r.dof > 0 && Number.isFinite(r.chi2) ? `; reduced χ²/dof = ${fmtSig(r.chi2 / r.dof, 3)}${unit}` : '';
	const prior = r.chi2_prior > 0 ? `; the priors' share ${fmtSig(r.chi2_prior, 3)}` : '';
	return `χ² = ${fmtSig(r.chi2, 3)}${unit} with ${r.dof} degrees of freedom${reduced}${prior}`;
}

/* A parameter's prior as the fit's table shows it: "0.02 ± 0.002"
 * (normal), "25600 ×÷ 10" (log-normal), "" without one. */
export function priorText(p) {
	if (!p) return '';
	return p.factor !== undefined ? `${fmtSig(p.mean, 4)} ×÷ ${fmtSig(p.factor, 3)}` : `${fmtSig(p.mean, 4)} ± ${fmtSig(p.sd, 3)}`;
}

/* An axis tick's text: every tick of an axis with as many decimals as its
 * step needs (a 0.0025 step: 157.0250, 157.0275, never 157.028 beside
 * 157.03), and 0 never written -0. */
export function tickText(v, step) {
	let d = 0;
	if (Number.isFinite(step) && step > 0)
		while (d < 12 && Math.abs(Math.round(step * 10 ** d) - step * 10 ** d) > 1e-6 * 10 ** d * step) d++;
	const x = Number.isFinite(step) && Math.abs(v) < step / 2 ? 0 : v;
	return x.toFixed(d);
}

/* A value with its standard error: the error at two significant digits
 * and the value to the same decimal place, "-0.00385 ± 0.00020"; without
 * a finite positive error the value at three significant digits. */
export function fmtPm(v, se, unit = '') {
	if (!Number.isFinite(v)) return DASH;
	if (!(Number.isFinite(se) && se > 0)) return fmtSig(v, 3, unit);
	const d = Math.min(12, Math.max(0, 1 - Math.floor(Math.log10(se))));
	const s = `${fmt(v, d)} ± ${se.toFixed(d)}`;
	return unit ? `${s} ${unit}` : s;
}
