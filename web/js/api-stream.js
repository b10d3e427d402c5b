/*
 * api-stream.js - the session's live stream: the daemon's server-sent
 * events (samples, control changes, missed-sample counts, the end) read
 * through the browser's EventSource and handed on normalized.
 */

import { BASE, streamQuery } from './api-requests.js';
import { num, normalizeSample, normalizeControl } from './api-normalize.js';

/* Open the session's SSE stream. handlers: sample(s), control(c, raw),
 * dropped(n), open(), error(), end(). Returns {close()}. The browser's
 * EventSource resumes by itself with Last-Event-ID after a drop. */
export function openStream(id, opts, handlers) {
	const url = `${BASE}/sessions/${encodeURIComponent(id)}/stream?${streamQuery(opts)}`;
	const es = new EventSource(url);
	const h = handlers;
	const dispatch = (type, ev) => {
		let d;
		try { d = JSON.parse(ev.data); } catch { return; }
		const kind = (d && typeof d === 'object' && !Array.isArray(d) && (d.type ?? d.event)) || type;
		if (/control|change|command/i.test(kind)) {
			h.control?.(normalizeControl(d.control ?? d), d);
		} else if (/drop|miss|lag/i.test(kind)) {
			h.dropped?.(num(d.missed ?? d.dropped ?? d.count ?? d.n));
		} else if (/end|close|stop|done|error/i.test(kind) && !/sample/i.test(kind)) {
			/* the daemon closes the stream after "end": do not reconnect */
			es.close();
			h.end?.(d);
		} else if (Array.isArray(d)) {
			for (const s of d) h.sample?.(normalizeSample(s));
		} else if (d && Array.isArray(d.samples)) {
			for (const s of d.samples) h.sample?.(normalizeSample(s));
		} else {
			h.sample?.(normalizeSample(d.sample ?? d, ev.lastEventId));
			if (typeof d.dropped === 'number' && d.dropped > 0) h.dropped?.(d.dropped);
		}
	};
	for (const type of ['message', 'sample', 'samples', 'control', 'dropped', 'missed', 'end', 'status'])
		es.addEventListener(type, ev => dispatch(type, ev));
	es.onopen = () => h.open?.();
	es.onerror = () => h.error?.(es.readyState);
	return { close: () => es.close(), source: es };
}
