// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * series.js - bounded sample buffers behind the live plots, and the
 * dashboard's own transport-velocity reading.
 *
 * A Trace holds columns of numbers against time (column 0 = t, s). Two
 * policies bound its memory:
 *   - "window": keep the last `span` seconds (orbits, strokes);
 *   - "history": keep everything since t = 0, and when `capacity` points are
 *     reached keep every second point, so a long run still shows its whole
 *     start-up (rotor speed, feed displacement) at half the resolution.
 * No DOM here; node:test covers it.
 */

export class Trace {
	/* width: number of value columns besides t. */
	constructor(width, { policy = 'window', span = 1, capacity = 4000 } = {}) {
		this.width = width;
		this.policy = policy;
		this.span = span;
		this.capacity = Math.max(8, capacity);
		this.stride = 1;      /* history: keep one sample in `stride` */
		this.seen = 0;        /* samples offered since the last clear */
		this.clear();
	}

	clear() {
		this.cols = Array.from({ length: this.width + 1 }, () => []);
		this.stride = 1;
		this.seen = 0;
		this.total = 0;       /* samples accepted since the last clear */
	}

	get length() { return this.cols[0].length; }

	/* Add one sample: t (s) and `width` values. Samples that go back in time
	 * (a resumed stream repeating itself) are ignored. */
	push(t, values) {
		if (!Number.isFinite(t)) return false;
		const ts = this.cols[0];
		if (ts.length && t <= ts[ts.length - 1]) return false;
		this.seen++;
		if (this.policy === 'history' && (this.seen - 1) % this.stride !== 0) return false;
		ts.push(t);
		for (let i = 0; i < this.width; i++) {
			const v = values[i];
			this.cols[i + 1].push(Number.isFinite(v) ? v : null);
		}
		this.total++;
		if (this.policy === 'window') this.trimWindow();
		else if (ts.length >= this.capacity) this.thin();
		return true;
	}

	trimWindow() {
		const ts = this.cols[0];
		const tMin = ts[ts.length - 1] - this.span;
		let n = 0;
		while (n < ts.length && ts[n] < tMin) n++;
		if (ts.length - n > this.capacity) n = ts.length - this.capacity;
		/* splice in chunks: cheap amortized, keeps arrays dense */
		if (n > 0 && (n >= 64 || n > ts.length / 4)) for (const c of this.cols) c.splice(0, n);
	}

	/* Data with the window applied exactly (trimWindow trims lazily). */
	data() {
		if (this.policy !== 'window' || !this.length) return this.cols;
		const ts = this.cols[0];
		const tMin = ts[ts.length - 1] - this.span;
		let n = 0;
		while (n < ts.length && ts[n] < tMin) n++;
		return n ? this.cols.map(c => c.slice(n)) : this.cols;
	}

	thin() {
		this.cols = this.cols.map(c => c.filter((_, i) => i % 2 === 0));
		this.stride *= 2;
	}

	last(col) {
		const c = this.cols[col];
		return c.length ? c[c.length - 1] : NaN;
	}
}

/* Least-squares slope dy/dx of the finite pairs; NaN with fewer than 2. */
export function slope(xs, ys) {
	let n = 0, sx = 0, sy = 0;
	for (let i = 0; i < xs.length; i++) {
		if (!Number.isFinite(xs[i]) || !Number.isFinite(ys[i])) continue;
		n++; sx += xs[i]; sy += ys[i];
	}
	if (n < 2) return NaN;
	const mx = sx / n, my = sy / n;
	let sxx = 0, sxy = 0;
	for (let i = 0; i < xs.length; i++) {
		if (!Number.isFinite(xs[i]) || !Number.isFinite(ys[i])) continue;
		sxx += (xs[i] - mx) ** 2;
		sxy += (xs[i] - mx) * (ys[i] - my);
	}
	return sxx > 0 ? sxy / sxx : NaN;
}

/* Current transport velocity (m/s) from the mean feed displacement: the
 * least-squares slope over the last `span` seconds of (t, xi). Needs at
 * least `minSpan` seconds of data, else NaN. Over several excitation
 * periods the fit averages out the hops within one period. */
export function recentVelocity(ts, xs, span = 0.5, minSpan = 0.2) {
	const n = ts.length;
	if (n < 2) return NaN;
	const tEnd = ts[n - 1];
	let i = n - 1;
	while (i > 0 && ts[i - 1] >= tEnd - span) i--;
	if (tEnd - ts[i] < minSpan) return NaN;
	return slope(ts.slice(i), xs.slice(i));
}
