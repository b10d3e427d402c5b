// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * schematic.js - a side view of the conveyor drawn in SVG: the trough on its
 * suspension, the vibrator with its sense of rotation, the two Frahm
 * eliminators on guides turned to beta (guide direction u(beta) =
 * (-sin beta, cos beta)), the vibration direction n(beta) = (cos beta,
 * sin beta), the feed columns and the measured transport direction.
 *
 * Not to scale except for the angles, which are exact. The geometry helpers
 * at the top are pure (node:test covers them); Schematic touches the DOM.
 */

const NS = 'http://www.w3.org/2000/svg';
const DEG = Math.PI / 180;

/* Drawing frame: model metres to SVG user units (y up becomes y down). */
export const VIEW = { w: 420, h: 258, x0: 210, y0: 186, scale: 150 };
export function toSvg(x, y) {
	return [VIEW.x0 + VIEW.scale * x, VIEW.y0 - VIEW.scale * y];
}

/* Unit vectors of docs/MODEL.md, beta in degrees. */
export function vibrationDirection(betaDeg) {
	return [Math.cos(betaDeg * DEG), Math.sin(betaDeg * DEG)];
}
export function guideDirection(betaDeg) {
	return [-Math.sin(betaDeg * DEG), Math.cos(betaDeg * DEG)];
}

/* End points (model metres) of a guide through p at beta, half-length half. */
export function guideEnds(p, betaDeg, half) {
	const u = guideDirection(betaDeg);
	return [[p[0] - half * u[0], p[1] - half * u[1]], [p[0] + half * u[0], p[1] + half * u[1]]];
}

/* Body-frame layout of the czubak2016 machine (docs/MODEL.md), metres. */
export const LAYOUT = {
	guides: [[-0.3, 0], [0.3, 0]],  /* p_1, p_2 */
	guideHalf: 0.2,
	springs: [-1, 1],               /* spring sets at x = -l2, l1 */
	body: { x0: -1.05, x1: 1.05, y0: -0.13, y1: 0.13 },
	wall: 0.22,                     /* side-wall top, above G */
	span: 0.8,                      /* columns at d_k in [-span, span] */
	ground: -0.34,
	strokeGain: 10,                 /* strokes drawn 10 times enlarged */
};

/* Deck x-positions of K evenly spaced columns. */
export function columnPositions(k, span = LAYOUT.span) {
	if (!(k > 0)) return [];
	if (k === 1) return [0];
	return Array.from({ length: k }, (_, i) => -span + 2 * span * i / (k - 1));
}

function el(name, attrs = {}, parent) {
	const e = document.createElementNS(NS, name);
	for (const [k, v] of Object.entries(attrs)) e.setAttribute(k, String(v));
	if (parent) parent.appendChild(e);
	return e;
}

function pts(list) {
	return list.map(([x, y]) => toSvg(x, y).map(v => v.toFixed(1)).join(',')).join(' ');
}

function zigzag(x, yTop, yBot, n = 6, amp = 0.035) {
	const p = [[x, yTop], [x, yTop - 0.02]];
	const h = (yTop - yBot - 0.04) / n;
	for (let i = 0; i < n; i++) p.push([x + (i % 2 ? -amp : amp), yTop - 0.02 - h * (i + 0.5)]);
	p.push([x, yBot + 0.02], [x, yBot]);
	return pts(p);
}

/* Arc arrow around c (model m) of radius r, for the rotor's sense as it
 * turns in this drawing. The drawing shows the machine in the model's axes
 * (X right, Y up) from the front; the paper's "clockwise" is phi' > 0 in
 * these axes (docs/MODEL.md), i.e. clockwise seen from behind the drawing, so
 * on screen it turns counter-clockwise. */
function rotorArc(c, r, rotation) {
	const [cx, cy] = toSvg(c[0], c[1]);
	const R = r * VIEW.scale;
	const a0 = 200 * DEG, a1 = -60 * DEG; /* screen angles */
	const screenCw = rotation === 'ccw';
	const [s, e] = screenCw ? [a0, a1] : [a1, a0];
	const p = a => [cx + R * Math.cos(a), cy - R * Math.sin(a)];
	const [sx, sy] = p(s), [ex, ey] = p(e);
	const sweep = screenCw ? 1 : 0;
	return `M${sx.toFixed(1)},${sy.toFixed(1)} A${R},${R} 0 1 ${sweep} ${ex.toFixed(1)},${ey.toFixed(1)}`;
}

export class Schematic {
	constructor(svg) {
		this.svg = svg;
		svg.setAttribute('viewBox', `0 0 ${VIEW.w} ${VIEW.h}`);
		svg.setAttribute('role', 'img');
		this.build();
		this.state = {};
	}

	build() {
		const s = this.svg;
		s.replaceChildren();
		const defs = el('defs', {}, s);
		for (const [id, cls] of [['arr-n', 'ah-n'], ['arr-v', 'ah-v'], ['arr-r', 'ah-r']]) {
			const m = el('marker', { id: `${id}`, viewBox: '0 0 10 10', refX: 8, refY: 5, markerWidth: 7, markerHeight: 7, orient: 'auto-start-reverse' }, defs);
			el('path', { d: 'M0,0 L10,5 L0,10 z', class: cls }, m);
		}
		const L = LAYOUT;
		/* ground and springs */
		const [gx0, gy] = toSvg(L.body.x0 - 0.1, L.ground);
		const [gx1] = toSvg(L.body.x1 + 0.1, L.ground);
		el('line', { x1: gx0, y1: gy, x2: gx1, y2: gy, class: 'sch-ground' }, s);
		for (let x = gx0 + 6; x < gx1; x += 10) el('line', { x1: x, y1: gy, x2: x - 6, y2: gy + 6, class: 'sch-hatch' }, s);
		for (const x of L.springs) el('polyline', { points: zigzag(x, L.body.y0, L.ground), class: 'sch-spring' }, s);
		/* trough body and walls */
		const b = L.body;
		el('polygon', { points: pts([[b.x0, L.wall], [b.x0, b.y0], [b.x1, b.y0], [b.x1, L.wall], [b.x1 - 0.03, L.wall], [b.x1 - 0.03, b.y1], [b.x0 + 0.03, b.y1], [b.x0 + 0.03, L.wall]]), class: 'sch-body' }, s);
		/* feed columns (filled in update) */
		this.feed = el('g', { class: 'sch-feed' }, s);
		/* guides: target (dashed) and current, and the eliminator masses */
		this.guideTarget = L.guides.map(() => el('line', { class: 'sch-guide-target' }, s));
		this.guides = L.guides.map(() => el('line', { class: 'sch-guide' }, s));
		this.bands = L.guides.map(() => el('line', { class: 'sch-band' }, s));
		this.masses = L.guides.map(() => el('rect', { width: 16, height: 10, x: -8, y: -5, rx: 2, class: 'sch-mass' }, s));
		L.guides.forEach((p, i) => {
			const [x, y] = toSvg(p[0], p[1] - 0.2);
			el('text', { x, y: y + 12, class: 'sch-label', 'text-anchor': 'middle' }, s).textContent = `eliminator ${i + 1}`;
		});
		/* vibrator */
		const [cx, cy] = toSvg(0, 0);
		el('circle', { cx, cy, r: 0.055 * VIEW.scale, class: 'sch-rotor' }, s);
		this.unbalance = el('circle', { cx, cy, r: 3.2, class: 'sch-unbalance' }, s);
		this.rotorArrow = el('path', { class: 'sch-rotor-arrow', 'marker-end': 'url(#arr-r)' }, s);
		/* beta arc and vibration direction */
		this.betaArc = el('path', { class: 'sch-beta-arc' }, s);
		el('line', { x1: cx, y1: cy, x2: cx + 0.3 * VIEW.scale, y2: cy, class: 'sch-ref' }, s);
		this.nArrow = el('line', { class: 'sch-n', 'marker-end': 'url(#arr-n)', 'marker-start': 'url(#arr-n)' }, s);
		this.betaText = el('text', { class: 'sch-beta', x: 8, y: 18 }, s);
		this.rotText = el('text', { class: 'sch-note', x: 8, y: 34 }, s);
		/* transport direction */
		this.vArrow = el('line', { class: 'sch-v', 'marker-end': 'url(#arr-v)' }, s);
		this.vText = el('text', { class: 'sch-vtext', 'text-anchor': 'middle' }, s);
		/* legend */
		const lg = el('g', { class: 'sch-legend', transform: `translate(${VIEW.w - 128},10)` }, s);
		el('line', { x1: 0, y1: 4, x2: 18, y2: 4, class: 'sch-n' }, lg);
		el('text', { x: 24, y: 8 }, lg).textContent = 'vibration n(β)';
		el('line', { x1: 0, y1: 18, x2: 18, y2: 18, class: 'sch-guide' }, lg);
		el('text', { x: 24, y: 22 }, lg).textContent = 'guide u(β)';
		el('line', { x1: 0, y1: 32, x2: 18, y2: 32, class: 'sch-guide-target' }, lg);
		el('text', { x: 24, y: 36 }, lg).textContent = 'guide at target β';
	}

	/* st: {beta, betaTarget (deg), rotation, strokes [m, m], strokeRange
	 * [[min, max], [min, max]] (m, drawn as a band), phase (rad),
	 * columns, layers, velocity (m/s), direction ("right"|"left"|"still"|"")} */
	update(st) {
		const L = LAYOUT;
		const beta = Number.isFinite(st.beta) ? st.beta : 0;
		const target = Number.isFinite(st.betaTarget) ? st.betaTarget : beta;
		this.svg.dataset.beta = beta.toFixed(2);
		L.guides.forEach((p, i) => {
			const [a, b] = guideEnds(p, beta, L.guideHalf).map(q => toSvg(q[0], q[1]));
			setLine(this.guides[i], a, b);
			const [ta, tb] = guideEnds(p, target, L.guideHalf).map(q => toSvg(q[0], q[1]));
			setLine(this.guideTarget[i], ta, tb);
			this.guideTarget[i].style.display = Math.abs(target - beta) > 0.05 ? '' : 'none';
			const lim = L.guideHalf - 0.03;
			const clampAlong = s => Math.max(-lim, Math.min(lim, s * L.strokeGain));
			const u = guideDirection(beta);
			const at = d => toSvg(p[0] + d * u[0], p[1] + d * u[1]);
			const range = st.strokeRange?.[i];
			if (range && Number.isFinite(range[0]) && Number.isFinite(range[1])) {
				setLine(this.bands[i], at(clampAlong(range[0])), at(clampAlong(range[1])));
				this.bands[i].style.display = '';
			} else {
				this.bands[i].style.display = 'none';
			}
			const along = clampAlong(Number.isFinite(st.strokes?.[i]) ? st.strokes[i] : 0);
			const [mx, my] = toSvg(p[0] + along * u[0], p[1] + along * u[1]);
			/* rect's long side along the guide: the guide makes angle beta+90 with +X */
			this.masses[i].setAttribute('transform', `translate(${mx.toFixed(1)},${my.toFixed(1)}) rotate(${(-(beta + 90)).toFixed(2)})`);
		});
		/* vibration direction through G, both ways */
		const n = vibrationDirection(beta);
		const r = 0.33;
		setLine(this.nArrow, toSvg(-r * n[0], -r * n[1]), toSvg(r * n[0], r * n[1]));
		const [cx, cy] = toSvg(0, 0);
		const ra = 0.2 * VIEW.scale;
		const ex = cx + ra * Math.cos(beta * DEG), ey = cy - ra * Math.sin(beta * DEG);
		this.betaArc.setAttribute('d', `M${cx + ra},${cy} A${ra},${ra} 0 0 0 ${ex.toFixed(1)},${ey.toFixed(1)}`);
		this.betaText.textContent = `β = ${beta.toFixed(1)}°` + (Math.abs(target - beta) > 0.05 ? `  → ${target.toFixed(1)}°` : '');
		this.rotText.textContent = st.rotation === 'ccw' ? 'rotor: counter-clockwise (φ̇ < 0; seen from behind)'
			: st.rotation === 'cw' ? 'rotor: clockwise (φ̇ > 0; seen from behind)' : '';
		this.rotorArrow.dataset.screenSense = st.rotation === 'ccw' ? 'clockwise' : st.rotation === 'cw' ? 'counter-clockwise' : '';
		this.rotorArrow.setAttribute('d', rotorArc([0, 0], 0.085, st.rotation));
		const ph = Number.isFinite(st.phase) ? st.phase : (st.rotation === 'ccw' ? -1 : 1) * 0.8;
		this.unbalance.setAttribute('cx', (cx + 0.035 * VIEW.scale * Math.cos(ph)).toFixed(1));
		this.unbalance.setAttribute('cy', (cy - 0.035 * VIEW.scale * Math.sin(ph)).toFixed(1));
		/* feed columns */
		const key = `${st.columns}x${st.layers}`;
		if (key !== this.feedKey) {
			this.feedKey = key;
			this.feed.replaceChildren();
			const xs = columnPositions(st.columns || 0);
			const layers = Math.max(0, Math.min(st.layers || 0, 40));
			const hl = layers ? Math.min(4, 22 / layers) : 0;
			for (const x of xs) {
				const [px, py] = toSvg(x, L.body.y1);
				for (let j = 0; j < layers; j++)
					el('rect', { x: px - 9, y: py - (j + 1) * hl, width: 18, height: Math.max(1, hl - 0.6), class: 'sch-element' }, this.feed);
			}
		}
		/* transport arrow above the deck */
		const dir = st.direction || '';
		this.svg.dataset.direction = dir;
		const ay = toSvg(0, L.wall + 0.3)[1];
		const len = 0.45 * VIEW.scale;
		if (dir === 'right' || dir === 'left') {
			const sgn = dir === 'right' ? 1 : -1;
			setLine(this.vArrow, [VIEW.x0 - sgn * len / 2, ay], [VIEW.x0 + sgn * len / 2, ay]);
			this.vArrow.style.display = '';
		} else {
			this.vArrow.style.display = 'none';
		}
		this.vText.setAttribute('x', VIEW.x0);
		this.vText.setAttribute('y', ay - 10);
		this.vText.textContent = dir === 'still' ? 'feed at rest' : dir ? `feed moves ${dir}` : 'transport: no reading yet';
	}
}

function setLine(line, a, b) {
	line.setAttribute('x1', a[0].toFixed(1));
	line.setAttribute('y1', a[1].toFixed(1));
	line.setAttribute('x2', b[0].toFixed(1));
	line.setAttribute('y2', b[1].toFixed(1));
}
