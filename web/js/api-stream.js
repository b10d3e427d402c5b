// SPDX-License-Identifier: GPL-3.0-or-later
/*
 * api-stream.js - the session's live stream: the daemon's server-sent
 * events (samples, control changes, missed-sample counts, the end) read
 * with fetch and handed on normalized.
 *
 * Not EventSource: it cannot send headers, and a daemon with a token wants
 * Authorization on the stream as on every route (a token in the query
 * string would land in logs and histories). So the stream is read here: the
 * text/event-stream format parsed block by block, and after a drop the
 * request is made again with Last-Event-ID, as EventSource would.
 */

import { BASE, authHeaders, streamQuery } from './api-requests.js';
import { num, normalizeSample, normalizeControl } from './api-normalize.js';

const CONNECTING = 0, CLOSED = 2; /* EventSource's readyState values */

/* Parse one SSE block into {type, data, lastEventId} (null: a comment or a
 * block without data); retry gets the server's reconnection time. */
function parseBlock(block, retry) {
	const ev = { type: 'message', data: [], lastEventId: '' };
	for (const line of block.split(/\r?\n/)) {
		if (!line || line.startsWith(':')) continue;
		const i = line.indexOf(':');
		const field = i < 0 ? line : line.slice(0, i);
		const value = i < 0 ? '' : line.slice(i + 1).replace(/^ /, '');
		if (field === 'data') ev.data.push(value);
		else if (field === 'event') ev.type = value;
		else if (field === 'id') ev.lastEventId = value;
		else if (field === 'retry' && /^\d+$/.test(value)) retry(Number(value));
	}
	if (!ev.data.length) return ev.lastEventId ? { ...ev, data: null } : null;
	return { ...ev, data: ev.data.join('\n') };
}

/* Read body's events until it ends, calling onEvent for each. */
async function readEvents(body, onEvent, retry) {
	const reader = body.getReader();
	const dec = new TextDecoder();
	let buf = '';
	for (;;) {
		const { value, done } = await reader.read();
		if (done) return;
		buf += dec.decode(value, { stream: true });
		let m;
		while ((m = /\r?\n\r?\n/.exec(buf))) {
			const ev = parseBlock(buf.slice(0, m.index), retry);
			buf = buf.slice(m.index + m[0].length);
			if (ev) onEvent(ev);
		}
	}
}

/* Open the session's SSE stream. handlers: sample(s), control(c, raw),
 * dropped(n), open(), error(readyState: 0 reconnecting, 2 closed), end().
 * Returns {close()}. After a drop, a 503 or the daemon's shutdown it asks
 * again every `retry` ms (the daemon's, default 1 s) and resumes with
 * Last-Event-ID; another refusal (401, 404, 429) or end closes it. */
export function openStream(id, opts, handlers) {
	const url = `${BASE}/sessions/${encodeURIComponent(id)}/stream?${streamQuery(opts)}`;
	const h = handlers;
	let closed = false, lastId = '', wait = 1000, ctrl = null;
	const close = () => { closed = true; ctrl?.abort(); };
	const dispatch = ev => {
		if (ev.lastEventId) lastId = ev.lastEventId;
		if (ev.data === null) return;
		let d;
		try { d = JSON.parse(ev.data); } catch { return; }
		const kind = (d && typeof d === 'object' && !Array.isArray(d) && (d.type ?? d.event)) || ev.type;
		if (kind === 'hello') {
			/* the stream's first record: the session and its model error */
			h.hello?.(d);
		} else if (/control|change|command/i.test(kind)) {
			h.control?.(normalizeControl(d.control ?? d), d);
		} else if (/drop|miss|lag/i.test(kind)) {
			h.dropped?.(num(d.missed ?? d.dropped ?? d.count ?? d.n));
		} else if (/end|close|stop|done|error/i.test(kind) && !/sample/i.test(kind)) {
			/* the daemon closes the stream after "end". A daemon that stops
			 * ("shutdown") restores its sessions when it starts again: ask
			 * again until it answers, as after a drop; any other end is
			 * final */
			if (d?.reason === 'shutdown') return;
			close();
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
	(async () => {
		while (!closed) {
			ctrl = new AbortController();
			const headers = { Accept: 'text/event-stream', ...authHeaders() };
			if (lastId) headers['Last-Event-ID'] = lastId;
			try {
				const res = await fetch(url, { headers, signal: ctrl.signal, cache: 'no-store' });
				/* 503: a daemon stopping, or its budget spent for now
				 * (Retry-After): ask again; any other refusal is final */
				if (res.status === 503) {
					const after = Number(res.headers.get('Retry-After'));
					if (after > 0) wait = 1000 * after;
					throw new Error('unavailable');
				}
				if (!res.ok) {
					closed = true;
					h.error?.(CLOSED);
					return;
				}
				h.open?.();
				await readEvents(res.body, dispatch, ms => { wait = ms; });
			} catch { /* a drop, or close() */ }
			if (closed) return;
			h.error?.(CONNECTING);
			await new Promise(r => setTimeout(r, wait));
		}
	})();
	return { close };
}
