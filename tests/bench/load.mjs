// SPDX-License-Identifier: GPL-3.0-or-later
// `make load`: a bounded load run on loopback that stops by itself (about
// two minutes). It starts its own daemon (with --max-memory 3G, so that
// "memory stayed under the budget" means something) and then:
//   - creates 200 default sessions and runs them at pace 1 (real time) as
//     far as the cores for paced sessions (--max-paced-cores) take them:
//     a pace change beyond is 503 with budget "cpu", counted as correct,
//   - opens 500 stream clients, half SSE and half NDJSON, spread over the
//     source addresses 127.0.1.1-127.0.1.10 (50 each: ten users); a stream
//     its running paced session's budget cannot take is 503 with budget
//     "cpu", counted as correct,
//   - sends a steady stream of PATCH beta from 127.0.0.1 (20 a second),
//   - opens 64 idle sockets from 127.0.0.2 (its per-client budget), sends
//     20 requests from there (429), then 1,936 more idle sockets (8 more
//     held in the grace, the rest closed at accept),
//   - asks GET /api/v1/health and one session from 127.0.0.3 (another
//     client) twice a second throughout,
//   - then opens FLOOD (2,000) idle sockets from FLOOD_ADDRESSES (500)
//     addresses 127.2.x.y, 4 each (within each one's budget: any local
//     user may pick 127.x.y.z), while an active client from 127.0.0.4
//     asks for one session back to back, each on a fresh connection: at
//     --max-connections the daemon closes the idlest connections, so the
//     active client's p99 stays low and it is answered every time,
// measures for WINDOW seconds (default 30) and prints a table: PATCH
// latency, stream lag (see streamlag.mjs), sessions keeping real time,
// 401/429/503 answers, the daemon's resident memory and CPU. It fails
// (exit 1) if the daemon crashed, its memory went over the budget, or the
// other client was not answered every time.
// Environment: CONVSIMD (the binary), WINDOW (s), SESSIONS, STREAMS, IDLE,
// FLOOD, FLOOD_ADDRESSES,
// MEMORY_GIB (--max-memory, default 3: about 290 default sessions),
// DAEMON_FLAGS (more daemon flags, e.g. "--max-paced-cores 64" to measure
// the daemon overloaded).
import { startDaemon } from '../http/lib.mjs';
import net from 'node:net';
import http from 'node:http';
import { call, lagStream, quantile, procUsage, fmt } from './streamlag.mjs';

const SESSIONS = Number(process.env.SESSIONS || 200);
const STREAMS = Number(process.env.STREAMS || 500);
const IDLE = Number(process.env.IDLE || 2000);
const FLOOD = Number(process.env.FLOOD ?? 2000);
const FLOOD_ADDRESSES = Number(process.env.FLOOD_ADDRESSES || 500);
const WINDOW = Number(process.env.WINDOW || 30);
const MEMORY_GIB = Number(process.env.MEMORY_GIB || 3);
const MEMORY = MEMORY_GIB * 1024 ** 3;
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const failures = [];
const check = (ok, what) => { if (!ok) failures.push(what); };

const FLAGS = (process.env.DAEMON_FLAGS || '').split(/\s+/).filter(Boolean);
const d = await startDaemon(['--max-sessions', String(SESSIONS + 16), '--max-streams', String(STREAMS + 16),
  '--max-memory', `${MEMORY_GIB}G`, ...FLAGS]);
const base = d.base;
// bounded: whatever happens, the run and its daemon end within 6 minutes
process.on('exit', () => { if (d.proc.exitCode === null) d.proc.kill('SIGKILL'); });
const deadline = setTimeout(() => {
  console.log('load: FAILED: did not finish within 6 minutes');
  process.exit(1);
}, 360000);
const agent = new http.Agent({ keepAlive: true, maxSockets: 8, localAddress: '127.0.0.1' });
const t0 = performance.now();
const usage0 = procUsage(d.proc.pid);
let peakRss = usage0.rss;
const sampler = setInterval(() => {
  try { peakRss = Math.max(peakRss, procUsage(d.proc.pid).rss); } catch { /* exited */ }
}, 250);

const progress = (what) => console.error(`load: ${fmt((performance.now() - t0) / 1000)} s: ${what}`);

// 1. sessions, four requests at a time: created at pace 0.001, then all
// set to pace 1, so that the first ones running do not slow the creation of
// the last (200 default sessions want more than 2 cores)
const ids = [];
const fourAtATime = (n, fn) => Promise.all(Array.from({ length: 4 }, async (_, w) => {
  for (let i = w; i < n; i += 4) await fn(i);
}));
await fourAtATime(SESSIONS, async (i) => {
  const r = await call(base, 'POST', '/api/v1/sessions', { pace: 0.001 }, { agent });
  if (r.status !== 201) throw new Error(`session ${i}: ${r.status} ${JSON.stringify(r.body)}`);
  ids[i] = r.body.id;
});
// a pace the paced sessions' cores (--max-paced-cores) cannot take is
// refused with 503, budget "cpu", and changes nothing: that session stays
// at pace 0.001 (correct behaviour, counted)
const admitted = new Set();
const admission = { refused: 0, other: [] };
await fourAtATime(SESSIONS, async (i) => {
  const r = await call(base, 'PATCH', `/api/v1/sessions/${ids[i]}`, { pace: 1 }, { agent });
  if (r.status === 200) admitted.add(ids[i]);
  else if (r.status === 503 && r.body && r.body.budget === 'cpu' && r.body.field === 'pace') admission.refused++;
  else throw new Error(`session ${i}: ${r.status} ${JSON.stringify(r.body)}`);
});
const created = performance.now();
progress(`${ids.length} sessions created, ${admitted.size} running at pace 1, ${admission.refused} refused for CPU (503)`);

// 2. the other client, throughout
const other = { n: 0, bad: [], ms: [] };
let running = true;
const otherLoop = (async () => {
  while (running) {
    for (const path of ['/api/v1/health', `/api/v1/sessions/${ids[0]}`]) {
      const r = await call(base, 'GET', path, undefined, { localAddress: '127.0.0.3' });
      other.n++;
      other.ms.push(r.ms);
      if (r.status !== 200) other.bad.push(`${path}: ${r.status || r.error}`);
    }
    await sleep(500);
  }
})();

// 3. streams, ten source addresses
const streams = [];
for (let i = 0; i < STREAMS; i++) {
  streams.push(lagStream(base, ids[i % ids.length], { ndjson: i % 2 === 1, rate: 10,
    localAddress: `127.0.1.${1 + (i % 10)}`, warmup: 5000 }));
  if (i % 50 === 49) await sleep(50);
}

progress(`${streams.length} streams opened`);
// 4. idle sockets from one address: its budget's worth (64), then 20
// requests from it (429 with a body), then the rest (8 more held in the
// grace, the others closed at accept)
const idle = { open: 0, closedEarly: 0, failed: 0, pending: 0, socks: [] };
// A connect the listen queue did not take within 5 s (the kernel retries
// the SYN for minutes) counts as pending and is given up.
const openIdle = (n) => Promise.all(Array.from({ length: n }, () => new Promise((resolve) => {
  const s = net.connect({ port: d.port, host: '127.0.0.1', localAddress: '127.0.0.2' });
  const opened = performance.now();
  const timer = setTimeout(() => { idle.pending++; s.destroy(); resolve(); }, 5000);
  s.on('connect', () => { clearTimeout(timer); idle.open++; idle.socks.push(s); resolve(); });
  s.on('close', () => { if (performance.now() - opened < 5000) idle.closedEarly++; });
  s.on('error', () => { clearTimeout(timer); idle.failed++; resolve(); });
})));
await openIdle(Math.min(64, IDLE));
const fromIdle = {};
for (let i = 0; i < 20; i++) {
  const r = await call(base, 'GET', '/api/v1/health', undefined, { localAddress: '127.0.0.2' });
  const k = r.status || 'closed';
  fromIdle[k] = (fromIdle[k] || 0) + 1;
}
await openIdle(IDLE - Math.min(64, IDLE));

progress(`idle sockets: ${idle.open} connected`);
// 4b. the idle flood from many addresses, and an active client meanwhile
const flood = { open: 0, closed: 0, failed: 0, pending: 0, socks: [] };
const active = { n: 0, bad: [], ms: [] };
let flooding = true;
const activeLoop = (async () => {
  while (flooding) {
    const r = await call(base, 'GET', `/api/v1/sessions/${ids[0]}`, undefined, { localAddress: '127.0.0.4' });
    active.n++;
    active.ms.push(r.ms);
    if (r.status !== 200) active.bad.push(r.status || r.error);
    await sleep(20);
  }
})();
const floodStart = performance.now();
// in batches of 100, so that this process's own event loop (the active
// client's too) is not starved by 2,000 connects at once
const floodSocket = (i) => new Promise((resolve) => {
  const a = i % FLOOD_ADDRESSES;
  const s = net.connect({ port: d.port, host: '127.0.0.1', localAddress: `127.2.${Math.floor(a / 250)}.${1 + (a % 250)}` });
  const timer = setTimeout(() => { flood.pending++; resolve(); }, 5000);
  s.on('connect', () => { clearTimeout(timer); flood.open++; flood.socks.push(s); resolve(); });
  s.on('close', () => { if (flooding) flood.closed++; });
  s.on('error', () => { clearTimeout(timer); flood.failed++; resolve(); });
});
const floodOpened = [];
for (let i = 0; i < FLOOD; i += 100) {
  for (let k = i; k < Math.min(FLOOD, i + 100); k++) floodOpened.push(floodSocket(k));
  await sleep(5);
}
await Promise.all(floodOpened);
await sleep(2000); // the active client goes on while the flood's sockets sit idle
flooding = false;
const floodClosed = flood.closed;
await activeLoop;
const floodS = (performance.now() - floodStart) / 1000;
progress(`idle flood: ${flood.open} connected, ${flood.closed} closed by the daemon`);
// 5. the measurement window: PATCH beta 20 a second
const patchMs = [];
const patchStatus = {};
const windowStart = performance.now();
const usageStart = procUsage(d.proc.pid);
const selfStart = process.cpuUsage();
let k = 0;
while (performance.now() - windowStart < WINDOW * 1000) {
  const id = ids[k++ % ids.length];
  call(base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 20 + (k % 140) }, { agent }).then((r) => {
    patchMs.push(r.ms);
    patchStatus[r.status || r.error] = (patchStatus[r.status || r.error] || 0) + 1;
  });
  await sleep(50);
}
const usageEnd = procUsage(d.proc.pid);
const selfCpu = process.cpuUsage(selfStart);
const windowS = (performance.now() - windowStart) / 1000;

progress('window over');
// 6. read out
const list = (await call(base, 'GET', '/api/v1/sessions', undefined, { agent })).body.sessions;
const paced1 = list.filter((s) => admitted.has(s.id));
const realTime = paced1.filter((s) => s.status.rtf >= 0.95).length;
const metricsText = (await call(base, 'GET', '/metrics', undefined, { agent })).body;
const metric = (key) => {
  const line = metricsText.split('\n').find((l) => l.startsWith(key + ' '));
  return line ? Number(line.slice(key.length + 1)) : 0;
};
const answers = (s) => metric(`convsim_http_requests_total{status="${s}"}`);
running = false;
await otherLoop;
const lags = [];
let streamErrors = 0, streamRecords = 0, streamsRefused = 0;
for (const s of streams) {
  s.stop();
  lags.push(...s.lags);
  streamRecords += s.samples;
  // a stream its running paced session's budget cannot take: 503, budget
  // "cpu" (docs/budgets.md "Streams"), counted as correct
  if (s.status === 503 && /"budget":"cpu"/.test(s.text || '')) streamsRefused++;
  else if (s.status !== 200 || s.error) streamErrors++;
}
for (const s of idle.socks) s.destroy();
for (const s of flood.socks) s.destroy();
clearInterval(sampler);
const alive = d.proc.exitCode === null && d.proc.signalCode === null;
const reserved = metric('convsim_memory_reserved_bytes');
progress('deleting the sessions');
for (const id of ids) await call(base, 'DELETE', `/api/v1/sessions/${id}`, undefined, { agent });
agent.destroy();
const stop = await d.stop();

check(alive, 'the daemon was alive at the end');
check(stop.code === 0, `the daemon exited 0 on SIGTERM (got ${stop.code} ${stop.sig})`);
check(peakRss < MEMORY, `resident memory ${peakRss} stayed under the budget ${MEMORY}`);
check(reserved <= MEMORY, `the reserved memory ${reserved} stayed within the budget`);
check(other.bad.length === 0 && other.n > 0, `the other client was answered every time (${other.bad.slice(0, 3)})`);
check(streamErrors === 0, `${streamErrors} stream clients failed`);
check(FLOOD === 0 || (active.bad.length === 0 && active.n > 0),
  `the active client was answered every time during the idle flood (${active.bad.slice(0, 3)})`);

const mb = (b) => fmt(b / 2 ** 20, 0);
const cpu = usageEnd.cpu - usageStart.cpu;
const lines = [
  `Command: \`make load\` (${SESSIONS} sessions, ${STREAMS} streams, ${IDLE} idle sockets, ${FLOOD} flood sockets, ${fmt(windowS, 0)}-s window` +
    `${FLAGS.length ? `, daemon flags ${FLAGS.join(' ')}` : ''}; ` +
    `setup ${fmt((created - t0) / 1000)} s to create the sessions)`,
  '',
  '| what | measured |',
  '|---|---|',
  `| PATCH beta (${patchMs.length}, ${fmt(patchMs.length / windowS, 0)}/s) latency p50 / p99 | ${fmt(quantile(patchMs, 0.5))} / ${fmt(quantile(patchMs, 0.99))} ms (answers ${JSON.stringify(patchStatus)}) |`,
  `| stream lag p50 / p99 (${lags.length} samples after 5 s, ${STREAMS} streams) | ${fmt(quantile(lags, 0.5))} / ${fmt(quantile(lags, 0.99))} ms |`,
  `| sessions admitted at pace 1 (the others: 503, budget "cpu") | ${admitted.size} of ${ids.length} (${admission.refused} refused) |`,
  `| streams refused (503, budget "cpu": their sessions' budget full) | ${streamsRefused} of ${STREAMS} |`,
  `| admitted sessions keeping real time (rtf >= 0.95) | ${realTime} of ${paced1.length} |`,
  `| cores held by paced sessions (metric) / --max-paced-cores | ${fmt(metric('convsim_paced_cpu_cores'), 3)} / ${fmt(metric('convsim_paced_cpu_budget_cores'), 2)} |`,
  `| answers 401 / 429 / 503 (whole run) | ${answers(401)} / ${answers(429)} / ${answers(503)} |`,
  `| idle sockets from 127.0.0.2 | ${idle.open} connected, ${idle.closedEarly} closed at once by the daemon, ${idle.failed} failed, ${idle.pending} not taken within 5 s; its 20 requests: ${JSON.stringify(fromIdle)} |`,
  `| connections closed at accept (metric) | ${metric('convsim_connections_dropped_total')} |`,
  `| idle flood: ${FLOOD} sockets from ${FLOOD_ADDRESSES} addresses 127.2.x.y | ${flood.open} connected, ${floodClosed} closed by the daemon (idle ones closed at the cap, metric: ${metric('convsim_connections_evicted_total')}), ${flood.failed} failed, ${flood.pending} not taken within 5 s |`,
  `| active client (127.0.0.4) during the idle flood (${fmt(floodS)} s): requests, p50 / p99 latency | ${active.n}, all answered: ${active.bad.length === 0}, ${fmt(quantile(active.ms, 0.5))} / ${fmt(quantile(active.ms, 0.99))} ms |`,
  `| another client (127.0.0.3): requests, p99 latency | ${other.n}, all answered: ${other.bad.length === 0}, ${fmt(quantile(other.ms, 0.99))} ms |`,
  `| daemon resident memory, peak (budget reserved / --max-memory) | ${mb(peakRss)} MiB (${mb(reserved)} / ${mb(MEMORY)} MiB) |`,
  `| daemon CPU (user + sys) in the window | ${fmt(cpu)} s = ${fmt(cpu / windowS, 2)} cores |`,
  `| this load generator's CPU (node, same machine) in the window | ${fmt((selfCpu.user + selfCpu.system) / 1e6 / windowS, 2)} cores |`,
  `| stream records received | ${streamRecords} |`,
];
console.log(lines.join('\n'));
clearTimeout(deadline);
if (failures.length) {
  console.log(`\nload: FAILED: ${failures.join('; ')}`);
  process.exit(1);
}
console.log('\nload: ok (no crash, memory under the budget, the other client answered)');
