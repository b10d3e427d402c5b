// SPDX-License-Identifier: GPL-3.0-or-later
// The figures of docs/cluster.md "Running on several machines" (not part of `make
// bench`; loopback only, bounded: about 1 minute for latency, 20 s per
// count and replica number for capacity). Replicas behind HAProxy are
// started as `make cluster` starts them (server/cluster.sh run).
//
//   node tests/bench/cluster.mjs latency [PATCHES]
//     2 replicas, 10 default sessions at pace 1 as background load, one
//     cheap target session with two NDJSON streams, one read directly from
//     its replica and one through the proxy. PATCH beta is sent PATCHES
//     times (default 300), alternately direct and through the proxy, each
//     with its own beta; per path: p50/p99 of the PATCH's answer time and of
//     the stream lag (from sending the PATCH to its control record arriving
//     on that path's stream), and HAProxy's CPU time per request.
//   node tests/bench/cluster.mjs capacity [N ...]
//     for 1, 2 and 3 replicas on this machine: N default sessions at pace 1
//     created through the proxy (spread by leastconn), 10 s of wall time,
//     how many keep a real-time factor >= 0.95 (heldInRealTime of
//     realtime.mjs); CPU of the replicas and of HAProxy over the run, and
//     the replicas' CPU per simulated second (sessions' t summed), which the
//     other loads on a shared machine do not change much.
//   node tests/bench/cluster.mjs idle
//     3 idle replicas and HAProxy (health checks every second) for 10 s:
//     each one's CPU and resident memory.
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { startCluster, req, openStream, sleep, CHEAP, processCpu as cpuSeconds } from '../http/lib.mjs';
import { heldInRealTime } from './realtime.mjs';

const cpuOf = (pids) => pids.reduce((s, p) => s + cpuSeconds(p), 0);

const quantile = (xs, q) => {
  const s = [...xs].sort((a, b) => a - b);
  return s[Math.min(s.length - 1, Math.floor(q * s.length))];
};

async function withCluster(n, fn) {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'convsim-bench-'));
  const c = await startCluster(n, dir, { DAEMON_FLAGS: '--log-level warn --max-sessions 400' });
  try {
    return await fn(c);
  } finally {
    await c.stop();
    fs.rmSync(dir, { recursive: true, force: true });
  }
}

// Arrival times (ms, performance.now) of control records by beta, on one stream.
function watchControls(base, id, signal) {
  const seen = new Map();
  const done = (async () => {
    try {
      for await (const rec of openStream(base, `/api/v1/sessions/${id}/stream?format=ndjson&fields=trough&rate=10`, {}, signal)) {
        if (rec.type === 'control' && rec.beta !== undefined) seen.set(rec.beta, performance.now());
      }
    } catch (e) { if (e.name !== 'AbortError') throw e; }
  })();
  return { seen, done };
}

async function latency(patches) {
  return withCluster(2, async (c) => {
    for (let i = 0; i < 10; i++) await req(c.base, 'POST', '/api/v1/sessions', { pace: 1 });
    const t = await req(c.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1, sample_rate: 50 });
    const id = t.body.id;
    const direct = `http://127.0.0.1:${c.ports[Number(id[1]) - 1]}`;
    const ac = new AbortController();
    const paths = { direct: { base: direct }, proxy: { base: c.base } };
    for (const p of Object.values(paths)) {
      p.watch = watchControls(p.base, id, ac.signal);
      p.patch = [];
      p.lag = [];
      p.sent = new Map();
    }
    await sleep(1000);
    const cpu0 = cpuSeconds(c.pids.haproxy);
    for (let i = 0; i < patches; i++) {
      const p = i % 2 ? paths.proxy : paths.direct;
      const beta = 30 + i * 0.25;
      const t0 = performance.now();
      const r = await req(p.base, 'PATCH', `/api/v1/sessions/${id}`, { beta });
      if (r.status !== 200) throw new Error(`PATCH: ${r.status} ${r.text}`);
      p.patch.push(performance.now() - t0);
      p.sent.set(beta, t0);
      await sleep(20);
    }
    const proxyCpu = cpuSeconds(c.pids.haproxy) - cpu0;
    await sleep(500);
    ac.abort();
    const rows = [];
    for (const [name, p] of Object.entries(paths)) {
      for (const [beta, t0] of p.sent) {
        const at = p.watch.seen.get(beta);
        if (at !== undefined) p.lag.push(at - t0);
      }
      rows.push(`| ${name} | ${p.patch.length} | ${quantile(p.patch, 0.5).toFixed(2)} | ${quantile(p.patch, 0.99).toFixed(2)} | `
        + `${p.lag.length} | ${quantile(p.lag, 0.5).toFixed(2)} | ${quantile(p.lag, 0.99).toFixed(2)} |`);
    }
    console.log(`Command: \`node tests/bench/cluster.mjs latency ${patches}\` (2 replicas, 10 default sessions at pace 1 `
      + 'as load, loopback, 2 cores shared with other builds)\n');
    console.log('| path | PATCHes | PATCH p50 / ms | PATCH p99 / ms | control records seen | stream lag p50 / ms | stream lag p99 / ms |');
    console.log('|---|---|---|---|---|---|---|');
    for (const r of rows) console.log(r);
    // the proxy also relays both streams' records: its CPU is an upper bound per request
    console.log(`\nHAProxy CPU (user+sys) over the ${patches / 2} proxied PATCHes and one proxied stream: `
      + `${(proxyCpu * 1000).toFixed(0)} ms, ${(proxyCpu * 1e6 / (patches / 2)).toFixed(0)} µs per request`);
  });
}

async function capacity(counts) {
  const rows = [];
  for (const n of [1, 2, 3]) {
    await withCluster(n, async (c) => {
      const replicas = Object.entries(c.pids).filter(([k]) => k !== 'haproxy').map(([, v]) => v);
      for (const N of counts) {
        const w0 = performance.now(), r0 = cpuOf(replicas), h0 = cpuSeconds(c.pids.haproxy);
        const load = os.loadavg()[0];
        const { ok, min, median, simulated } = await heldInRealTime(c.base, N);
        const wall = (performance.now() - w0) / 1000;
        const rc = cpuOf(replicas) - r0, hc = cpuSeconds(c.pids.haproxy) - h0;
        rows.push(`| ${n} | ${N} | ${ok} | ${min.toFixed(2)} | ${median.toFixed(2)} | `
          + `${(rc / wall).toFixed(2)} | ${(1000 * rc / simulated).toFixed(1)} | ${(100 * hc / wall).toFixed(2)} % | ${load.toFixed(1)} |`);
        console.error(rows[rows.length - 1]);
      }
    });
  }
  console.log(`Command: \`node tests/bench/cluster.mjs capacity ${counts.join(' ')}\` (czubak2016 defaults, pace 1, `
    + '10 s of wall time, created through HAProxy; 2 cores shared with other builds)\n');
  console.log('| replicas | sessions | at >= 0.95 of real time | slowest rtf | median rtf | replicas\' CPU / cores '
    + '| replicas\' CPU ms per simulated s | HAProxy CPU | load average |');
  console.log('|---|---|---|---|---|---|---|---|---|');
  for (const r of rows) console.log(r);
}

const rssMB = (pid) => Number(fs.readFileSync(`/proc/${pid}/status`, 'utf8').match(/VmRSS:\s+(\d+)/)[1]) / 1024;

async function idle() {
  await withCluster(3, async (c) => {
    await sleep(1000);
    const pids = Object.entries(c.pids);
    const before = pids.map(([, p]) => cpuSeconds(p));
    await sleep(10000);
    console.log('Command: `node tests/bench/cluster.mjs idle` (3 replicas, no session, 10 s)\n');
    console.log('| process | CPU (% of one core) | resident memory / MB |');
    console.log('|---|---|---|');
    pids.forEach(([name, p], i) => {
      console.log(`| ${name} | ${(10 * (cpuSeconds(p) - before[i])).toFixed(2)} | ${rssMB(p).toFixed(1)} |`);
    });
  });
}

const [what, ...rest] = process.argv.slice(2);
if (what === 'latency') await latency(Number(rest[0]) || 300);
else if (what === 'idle') await idle();
else if (what === 'capacity') await capacity(rest.length ? rest.map(Number) : [100, 125, 150]);
else {
  console.error('usage: node tests/bench/cluster.mjs latency [PATCHES] | capacity [N ...] | idle');
  process.exit(2);
}
