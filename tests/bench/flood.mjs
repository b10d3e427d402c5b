// SPDX-License-Identifier: GPL-3.0-or-later
// Connection floods from many loopback addresses against one daemon, and
// an active client meanwhile (run by hand or by `make flood`; about a
// minute for the three scenarios; loopback only, every socket and the
// daemon end with it):
//   idle       FLOOD (2,000) sockets from ADDRESSES (500) source addresses
//              127.2.x.y that connect and send nothing,
//   slow-get   the same sockets each send `GET /api/v1/health` with
//              Content-Length: 1000, then one byte of the body every 2 s,
//   slow-post  the same with `POST /api/v1/sessions` (a route that reads
//              its body): one byte every 2 s.
// Each scenario starts its own daemon (DAEMON_FLAGS adds flags), opens the
// flood in batches of 100, holds it HOLD seconds (default 12: past
// --request-timeout, so slow bodies meet their deadline), closes it,
// and measures 3 s more. Throughout, an active client from 127.0.0.4 asks
// GET /api/v1/health back to back (20 ms apart), each on a fresh
// connection, and counts an answer only if it is 200 with status "ok"
// within 5 s, in the phase in which it ends. The active client runs in a
// worker thread of its own, so that its times are the daemon's, not the
// wait for this process's event loop busy with the flood. It prints one table (markdown): the active
// client's answers and p50 / p99 / max latency while the flood's sockets
// connect, while they are held and after they closed, whether
// /api/v1/health answers after it, and the daemon's counters of
// connections closed at the cap, at a deadline and at accept; exit 1 if
// the active client or /api/v1/health was not answered every time.
// Environment: CONVSIMD (the binary), FLOOD, ADDRESSES, HOLD (s),
// SCENARIOS (comma-separated, default idle,slow-get,slow-post),
// DAEMON_FLAGS.
import net from 'node:net';
import http from 'node:http';
import os from 'node:os';
import { fileURLToPath } from 'node:url';
import { Worker, isMainThread, parentPort, workerData } from 'node:worker_threads';
import { startDaemon } from '../http/lib.mjs';
import { quantile, fmt } from './streamlag.mjs';

const FLOOD = Number(process.env.FLOOD || 2000);
const ADDRESSES = Number(process.env.ADDRESSES || 500);
const HOLD = Number(process.env.HOLD || 12);
const SCENARIOS = (process.env.SCENARIOS || 'idle,slow-get,slow-post').split(',');
const FLAGS = (process.env.DAEMON_FLAGS || '').split(/\s+/).filter(Boolean);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// GET path on a fresh connection from localAddress: {ok, status, ms, error}.
export function health(port, localAddress, timeoutMs = 5000) {
  return new Promise((resolve) => {
    const t0 = performance.now();
    const r = http.request({ host: '127.0.0.1', port, path: '/api/v1/health', agent: false, localAddress }, (res) => {
      let text = '';
      res.setEncoding('utf8');
      res.on('data', (c) => { text += c; });
      res.on('end', () => {
        let body = null;
        try { body = JSON.parse(text); } catch { /* not JSON */ }
        const ok = res.statusCode === 200 && body !== null && body.status === 'ok';
        resolve({ ok, status: res.statusCode, ms: performance.now() - t0 });
      });
    });
    r.on('error', (e) => resolve({ ok: false, status: 0, error: e.code || e.message, ms: performance.now() - t0 }));
    r.setTimeout(timeoutMs, () => r.destroy(new Error('timeout')));
    r.end();
  });
}

// The daemon's connection counters from /metrics: closed at the cap, at
// their deadline, at accept.
async function metrics(port) {
  const text = await new Promise((resolve) => {
    const r = http.get({ host: '127.0.0.1', port, path: '/metrics', agent: false }, (res) => {
      let t = '';
      res.setEncoding('utf8');
      res.on('data', (c) => { t += c; });
      res.on('end', () => resolve(t));
    });
    r.on('error', () => resolve(''));
    r.setTimeout(5000, () => r.destroy(new Error('timeout')));
  });
  const value = (name) => {
    const m = text.match(new RegExp(`^${name} (\\S+)$`, 'm'));
    return m ? Number(m[1]) : NaN;
  };
  return {
    evicted: value('convsim_connections_evicted_total'),
    timedOut: value('convsim_connections_timed_out_total'),
    dropped: value('convsim_connections_dropped_total'),
  };
}

// The request head a flood socket of this scenario sends (null: none).
function head(scenario, port) {
  const host = `Host: 127.0.0.1:${port}\r\n`;
  if (scenario === 'slow-get') return `GET /api/v1/health HTTP/1.1\r\n${host}Content-Length: 1000\r\n\r\n`;
  if (scenario === 'slow-post') {
    return `POST /api/v1/sessions HTTP/1.1\r\n${host}Content-Type: application/json\r\nContent-Length: 1000\r\n\r\n`;
  }
  return null;
}

// n sockets from `addresses` source addresses PREFIX.x.y (127.2 unless
// told), opened in batches of 100; a slow scenario sends its head, then
// one body byte every 2 s. closeFlood ends them.
export async function openFlood(port, scenario, n, addresses, prefix = '127.2') {
  const st = { socks: [], connected: 0, closedByDaemon: 0, answered: 0, failed: 0, pending: 0, open: true };
  const text = head(scenario, port);
  const one = (i) => new Promise((resolve) => {
    const a = i % addresses;
    const s = net.connect({ port, host: '127.0.0.1', localAddress: `${prefix}.${Math.floor(a / 250)}.${1 + (a % 250)}` });
    st.socks.push(s);
    let answered = false;
    const timer = setTimeout(() => { st.pending++; resolve(); }, 5000);
    s.on('connect', () => {
      clearTimeout(timer);
      st.connected++;
      if (text) s.write(text);
      resolve();
    });
    s.on('data', () => { if (!answered) { answered = true; st.answered++; } });
    s.on('close', () => { if (st.open) st.closedByDaemon++; });
    s.on('error', () => { clearTimeout(timer); st.failed++; resolve(); });
  });
  const opened = [];
  for (let i = 0; i < n; i += 100) {
    for (let k = i; k < Math.min(n, i + 100); k++) opened.push(one(k));
    await sleep(5);
  }
  await Promise.all(opened);
  // the trickle: each socket one byte every 2 s, spread over 100 ticks
  let tick = 0;
  st.trickle = text && setInterval(() => {
    for (let k = tick % 100; k < st.socks.length; k += 100) {
      const s = st.socks[k];
      if (!s.destroyed && s.writable) s.write(' ');
    }
    tick++;
  }, 20);
  return st;
}

export function closeFlood(st) {
  st.open = false;
  if (st.trickle) clearInterval(st.trickle);
  for (const s of st.socks) s.destroy();
}

// The active client (in a worker thread): GET /api/v1/health back to
// back until told "stop"; "after" starts the second tally.
function activeClient() {
  const tally = () => ({ n: 0, ok: 0, ms: [], bad: {} });
  const phases = { opening: tally(), held: tally(), after: tally() };
  let phase = phases.opening;
  let running = true;
  parentPort.on('message', (m) => {
    if (m in phases) phase = phases[m];
    if (m === 'stop') running = false;
  });
  (async () => {
    while (running) {
      const r = await health(workerData.port, '127.0.0.4');
      const p = phase;
      p.n++;
      if (r.ok) { p.ok++; p.ms.push(r.ms); } else {
        const k = r.status || r.error;
        p.bad[k] = (p.bad[k] || 0) + 1;
      }
      await sleep(20);
    }
    parentPort.postMessage(phases);
  })();
}

async function scenario(name) {
  const d = await startDaemon(FLAGS);
  // the daemon ends with this script, however it ends
  const kill = () => { if (d.proc.exitCode === null && d.proc.signalCode === null) d.proc.kill('SIGKILL'); };
  process.on('exit', kill);
  for (const sig of ['SIGINT', 'SIGTERM', 'SIGHUP']) process.once(sig, () => { kill(); process.exit(1); });
  const worker = new Worker(fileURLToPath(import.meta.url), { workerData: { port: d.port } });
  const tallies = new Promise((resolve) => worker.once('message', resolve));
  const load = os.loadavg()[0];
  const t0 = performance.now();
  const st = await openFlood(d.port, name, FLOOD, ADDRESSES);
  const openS = (performance.now() - t0) / 1000;
  worker.postMessage('held');
  await sleep(HOLD * 1000);
  const closedByDaemon = st.closedByDaemon;
  const answeredFlood = st.answered;
  closeFlood(st);
  worker.postMessage('after');
  await sleep(3000);
  worker.postMessage('stop');
  const { opening, held, after } = await tallies;
  await worker.terminate();
  const final = await health(d.port, '127.0.0.5');
  const counters = await metrics(d.port);
  const stop = await d.stop();
  return {
    name, connected: st.connected, pending: st.pending, failed: st.failed, closedByDaemon, answeredFlood,
    openS, opening, held, after, final, counters, load, exit: stop.code,
  };
}

async function main() {
  const rows = [];
  for (const name of SCENARIOS) {
    console.error(`flood: ${name}: ${FLOOD} sockets from ${ADDRESSES} addresses, held ${HOLD} s`);
    const r = await scenario(name);
    rows.push(r);
    console.error(`flood: ${name}: active ${r.opening.ok}/${r.opening.n} while opening, ${r.held.ok}/${r.held.n} held, ` +
      `${r.after.ok}/${r.after.n} after, health after: ${r.final.ok ? 'ok' : r.final.status || r.final.error}`);
  }

  const cmdEnv = [`FLOOD=${FLOOD}`, `ADDRESSES=${ADDRESSES}`, `HOLD=${HOLD}`]
    .concat(FLAGS.length ? [`DAEMON_FLAGS="${FLAGS.join(' ')}"`] : []).join(' ');
  console.log(`\`CONVSIMD=$PWD/build/convsimd ${cmdEnv} node tests/bench/flood.mjs\`\n`);
  console.log('| flood | sockets connected / closed by the daemon / answered | active client while the flood opens: answered, p50 / p99 / max ms | while it is held: answered, p50 / p99 / max ms | after it: answered, p99 ms | /health after | closed at the cap / at a deadline / at accept |');
  console.log('|---|---|---|---|---|---|---|');
  let failed = false;
  const q = (v, x) => fmt(quantile(v, x), 1);
  const cell = (t) => {
    const bad = Object.entries(t.bad).map(([k, v]) => `${v}x ${k}`).join(', ');
    return `${t.ok} of ${t.n}, ${q(t.ms, 0.5)} / ${q(t.ms, 0.99)} / ${fmt(Math.max(...t.ms), 1)}${bad ? ` (${bad})` : ''}`;
  };
  for (const r of rows) {
    console.log(`| ${r.name} | ${r.connected} / ${r.closedByDaemon} / ${r.answeredFlood}${r.pending ? ` (${r.pending} not taken in 5 s)` : ''} ` +
      `| ${cell(r.opening)} (${fmt(r.openS, 1)} s) | ${cell(r.held)} | ${r.after.ok} of ${r.after.n}, ${q(r.after.ms, 0.99)} ` +
      `| ${r.final.ok ? '200 ok' : `no (${r.final.status || r.final.error})`} ` +
      `| ${r.counters.evicted} / ${r.counters.timedOut} / ${r.counters.dropped} |`);
    for (const t of [r.opening, r.held, r.after]) if (t.ok !== t.n) failed = true;
    if (!r.final.ok || r.exit !== 0) failed = true;
  }
  console.log(`\n(${os.cpus().length} cores; load average over the last minute at each flood's start: ` +
    `${rows.map((r) => fmt(r.load, 1)).join(', ')})`);
  if (failed) {
    console.log('\nflood: FAILED: the active client or /api/v1/health was not answered every time');
    process.exit(1);
  }
}

if (!isMainThread) activeClient();
else if (process.argv[1] === fileURLToPath(import.meta.url)) await main();
