// SPDX-License-Identifier: GPL-3.0-or-later
// Shared by the load run (load.mjs) and the real-time capacity figure
// (realtime.mjs): plain node:http requests with a chosen source address,
// stream clients that measure each sample's lag, percentiles, and the
// daemon's resident memory and CPU time from /proc.
//
// Stream lag: a sample of simulated time t received at wall time w has the
// offset w - t; a session in real time keeps it constant, so a sample's lag
// is its offset minus the smallest offset its stream saw (the fastest
// delivery). A session that falls behind real time, or a stream that
// delivers late, shows a growing lag.
import http from 'node:http';
import { readFileSync } from 'node:fs';
import { processCpu } from '../http/lib.mjs';

export const JSON_TYPE = { 'Content-Type': 'application/json' };

// One request; resolves {status, body (parsed JSON or text), ms} or
// {status: 0, error} when the connection failed or was closed.
export function call(base, method, path, body, { agent, localAddress } = {}) {
  return new Promise((resolve) => {
    const t0 = performance.now();
    const data = body === undefined ? '' : JSON.stringify(body);
    const headers = method === 'GET' ? {} : { ...JSON_TYPE, 'Content-Length': Buffer.byteLength(data) };
    const r = http.request(base + path, { method, headers, agent: agent || false, localAddress }, (res) => {
      let text = '';
      res.setEncoding('utf8');
      res.on('data', (c) => { text += c; });
      res.on('end', () => {
        let parsed = text;
        try { parsed = text ? JSON.parse(text) : null; } catch { /* CSV, text */ }
        resolve({ status: res.statusCode, body: parsed, ms: performance.now() - t0 });
      });
    });
    r.on('error', (e) => resolve({ status: 0, error: e.code || e.message, ms: performance.now() - t0 }));
    r.setTimeout(30000, () => r.destroy(new Error('no answer within 30 s')));
    r.end(data);
  });
}

// A stream client of session id: NDJSON or SSE, `rate` samples per
// simulated second of the trough group. Collects lags (ms) after `warmup`
// ms (or from st.collectFrom, a performance.now() time, once set); stop()
// closes it. status: the HTTP status once answered; ready: a promise of it
// (0: the connection failed), with the body of a refusal in text.
export function lagStream(base, id, { ndjson, rate = 10, localAddress, warmup = 0 } = {}) {
  const st = { lags: [], samples: 0, status: 0, error: null, minOffset: Infinity, offsets: [] };
  const path = `/api/v1/sessions/${id}/stream?fields=trough&rate=${rate}${ndjson ? '&format=ndjson' : ''}`;
  const started = performance.now();
  let answered;
  st.ready = new Promise((r) => { answered = r; });
  const req = http.get(base + path, { agent: false, localAddress }, (res) => {
    st.status = res.statusCode;
    if (st.status !== 200) {
      st.text = '';
      res.on('data', (c) => { st.text += c; });
      res.on('end', () => answered(st.status));
    } else answered(st.status);
    res.setEncoding('utf8');
    let buf = '';
    const sep = ndjson ? '\n' : '\n\n';
    res.on('data', (chunk) => {
      buf += chunk;
      let at;
      while ((at = buf.indexOf(sep)) >= 0) {
        const block = buf.slice(0, at);
        buf = buf.slice(at + sep.length);
        const isSample = ndjson ? block.startsWith('{"type":"sample"') : block.includes('event: sample');
        if (!isSample) continue;
        const m = block.match(/"t":([-0-9.eE+]+)/);
        if (!m) continue;
        const now = performance.now();
        const offset = now - 1000 * Number(m[1]);
        st.samples++;
        if (offset < st.minOffset) st.minOffset = offset;
        if (now >= (st.collectFrom ?? started + warmup)) st.offsets.push(offset);
      }
    });
    res.on('error', (e) => { st.error = e.code || e.message; });
  });
  req.on('error', (e) => { if (!st.stopped) st.error = e.code || e.message; answered(0); });
  st.stop = () => {
    st.stopped = true;
    req.destroy();
    st.lags = st.offsets.map((o) => o - st.minOffset);
    return st;
  };
  return st;
}

// The q-quantile (0..1) of numbers (sorted here); NaN when empty.
export function quantile(values, q) {
  if (!values.length) return NaN;
  const v = [...values].sort((a, b) => a - b);
  return v[Math.min(v.length - 1, Math.floor(q * v.length))];
}

// Resident memory (bytes) and CPU time (user + system, s) of a process.
export function procUsage(pid) {
  const status = readFileSync(`/proc/${pid}/status`, 'utf8');
  const rss = Number(status.match(/VmRSS:\s+(\d+) kB/)[1]) * 1024;
  return { rss, cpu: processCpu(pid) };
}

export const fmt = (x, digits = 1) => (Number.isFinite(x) ? x.toFixed(digits) : 'n/a');
