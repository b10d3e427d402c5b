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
// within 5 s, in the phase in which it ends. The active client is a
// process of its own (not a thread of the one that opens the flood), and
// each request's time is also taken from its socket's connect: the part
// the daemon answers for (the kernel completes the handshake before the
// daemon accepts; the wait for the client's own turn on a busy machine
// comes before it). It prints one table (markdown): the active client's
// answers, p50 / p99 / max latency and p99 from connect while the flood's
// sockets connect, while they are held and after they closed, whether
// /api/v1/health answers after it, and the daemon's counters of
// connections closed at the cap, at a deadline and at accept; exit 1 if
// the active client or /api/v1/health was not answered every time.
// Environment: CONVSIMD (the binary), FLOOD, ADDRESSES, HOLD (s),
// SCENARIOS (comma-separated, default idle,slow-get,slow-post),
// DAEMON_FLAGS; BASELINE (another convsimd: each scenario runs on it and
// on CONVSIMD in turn, ROUNDS times, default 1); LOAD (that many busy
// processes at the bench's own niceness during each scenario, so that two
// builds meet the same contention).
import net from 'node:net';
import http from 'node:http';
import os from 'node:os';
import { fileURLToPath } from 'node:url';
import { fork, execFileSync } from 'node:child_process';
import { startDaemon } from '../http/lib.mjs';
import { quantile, fmt } from './streamlag.mjs';

const FLOOD = Number(process.env.FLOOD || 2000);
const ADDRESSES = Number(process.env.ADDRESSES || 500);
const HOLD = Number(process.env.HOLD || 12);
const SCENARIOS = (process.env.SCENARIOS || 'idle,slow-get,slow-post').split(',');
const FLAGS = (process.env.DAEMON_FLAGS || '').split(/\s+/).filter(Boolean);
const BASELINE = process.env.BASELINE || '';
const ROUNDS = Number(process.env.ROUNDS || 1);
const LOAD = Number(process.env.LOAD || 0);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// GET path on a fresh connection from localAddress: {ok, status, ms, error}.
export function health(port, localAddress, timeoutMs = 5000) {
  return new Promise((resolve) => {
    const t0 = performance.now();
    let tc = NaN;
    const r = http.request({ host: '127.0.0.1', port, path: '/api/v1/health', agent: false, localAddress }, (res) => {
      let text = '';
      res.setEncoding('utf8');
      res.on('data', (c) => { text += c; });
      res.on('end', () => {
        let body = null;
        try { body = JSON.parse(text); } catch { /* not JSON */ }
        const ok = res.statusCode === 200 && body !== null && body.status === 'ok';
        const t1 = performance.now();
        resolve({ ok, status: res.statusCode, ms: t1 - t0, fromConnect: t1 - tc });
      });
    });
    r.on('socket', (sock) => sock.once('connect', () => { tc = performance.now(); }));
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

// The active client (a process of its own, FLOOD_ACTIVE_PORT set): GET
// /api/v1/health back to back until told "stop"; "held" and "after"
// start the next tallies. It ends with its parent.
function activeClient(port) {
  const tally = () => ({ n: 0, ok: 0, ms: [], fromConnect: [], bad: {} });
  const phases = { opening: tally(), held: tally(), after: tally() };
  let phase = phases.opening;
  let running = true;
  process.on('message', (m) => {
    if (m in phases) phase = phases[m];
    if (m === 'stop') running = false;
  });
  process.on('disconnect', () => process.exit(0));
  (async () => {
    process.send('ready');
    while (running) {
      const r = await health(port, '127.0.0.4');
      const p = phase;
      p.n++;
      if (r.ok) { p.ok++; p.ms.push(r.ms); p.fromConnect.push(r.fromConnect); } else {
        const k = r.status || r.error;
        p.bad[k] = (p.bad[k] || 0) + 1;
      }
      await sleep(20);
    }
    process.send(phases, () => process.exit(0));
  })();
}

// LOAD busy processes (each a spinning node), ended by the returned call.
function busy(n) {
  const procs = Array.from({ length: n }, () => fork('-e', ['for (;;) {}'], { execArgv: [], stdio: 'ignore' }));
  return () => { for (const p of procs) p.kill('SIGKILL'); };
}

async function scenario(name, bin) {
  const d = await startDaemon(FLAGS, bin ? { wrap: [bin] } : {});
  // the daemon and the helpers end with this script, however it ends
  const unload = busy(LOAD);
  const kill = () => { unload(); if (d.proc.exitCode === null && d.proc.signalCode === null) d.proc.kill('SIGKILL'); };
  process.on('exit', kill);
  for (const sig of ['SIGINT', 'SIGTERM', 'SIGHUP']) process.once(sig, () => { kill(); process.exit(1); });
  const client = fork(fileURLToPath(import.meta.url), [], { env: { ...process.env, FLOOD_ACTIVE_PORT: String(d.port) } });
  process.on('exit', () => client.kill('SIGKILL'));
  await new Promise((resolve) => client.once('message', resolve)); // ready
  const tallies = new Promise((resolve) => client.once('message', resolve));
  const load = os.loadavg()[0];
  const t0 = performance.now();
  const st = await openFlood(d.port, name, FLOOD, ADDRESSES);
  const openS = (performance.now() - t0) / 1000;
  client.send('held');
  await sleep(HOLD * 1000);
  const closedByDaemon = st.closedByDaemon;
  const answeredFlood = st.answered;
  closeFlood(st);
  client.send('after');
  await sleep(3000);
  client.send('stop');
  const { opening, held, after } = await tallies;
  unload();
  const final = await health(d.port, '127.0.0.5');
  const counters = await metrics(d.port);
  const stop = await d.stop();
  return {
    name, connected: st.connected, pending: st.pending, failed: st.failed, closedByDaemon, answeredFlood,
    openS, opening, held, after, final, counters, load, exit: stop.code,
  };
}

// The build of a binary: the commit this checkout is at for CONVSIMD,
// the file's name for BASELINE.
function buildName(bin) {
  if (bin) return bin.split('/').pop();
  try {
    return execFileSync('git', ['rev-parse', '--short', 'HEAD'], { encoding: 'utf8' }).trim() +
      (execFileSync('git', ['status', '--porcelain', '--untracked-files=no'], { encoding: 'utf8' }).trim() ? '+' : '');
  } catch { return 'this build'; }
}

async function main() {
  const rows = [];
  const builds = BASELINE ? [BASELINE, ''] : [''];
  const loadBefore = os.loadavg().map((x) => fmt(x, 2)).join(' ');
  for (let round = 0; round < ROUNDS; round++) {
    for (const name of SCENARIOS) {
      for (const bin of builds) {
        console.error(`flood: ${name} on ${buildName(bin)}: ${FLOOD} sockets from ${ADDRESSES} addresses, held ${HOLD} s`);
        const r = { build: buildName(bin), ...(await scenario(name, bin)) };
        rows.push(r);
        console.error(`flood: ${name}: active ${r.opening.ok}/${r.opening.n} while opening, ${r.held.ok}/${r.held.n} held, ` +
          `${r.after.ok}/${r.after.n} after, health after: ${r.final.ok ? 'ok' : r.final.status || r.final.error}`);
      }
    }
  }

  const env = [`FLOOD=${FLOOD}`, `ADDRESSES=${ADDRESSES}`, `HOLD=${HOLD}`]
    .concat(FLAGS.length ? [`DAEMON_FLAGS="${FLAGS.join(' ')}"`] : [])
    .concat(BASELINE ? [`BASELINE=.../${buildName(BASELINE)}`, `ROUNDS=${ROUNDS}`] : [])
    .concat(LOAD ? [`LOAD=${LOAD}`] : []).join(' ');
  const cpu = os.cpus();
  console.log('# Connection floods: the active client\n');
  console.log(`Command: \`CONVSIMD=$PWD/build/convsimd ${env} node tests/bench/flood.mjs\`, ` +
    `${new Date().toISOString().slice(0, 16).replace('T', ' ')} UTC, build ${buildName('')}, ` +
    `${cpu.length} cores (${cpu[0] ? cpu[0].model.trim() : 'unknown'}), load average ${loadBefore} before.\n`);
  console.log('Each row a fresh daemon with default flags unless told; times in ms; "from connect": from the active client\'s connect to its answer\'s end (the part the daemon answers for).\n');
  console.log('| build | flood | sockets connected / closed by the daemon / answered | active client while the flood opens: answered, p50 / p99 / max (p99 from connect) | while it is held: answered, p50 / p99 / max (p99 from connect) | after it: answered, p99 | /health after | closed at the cap / at a deadline / at accept | load average |');
  console.log('|---|---|---|---|---|---|---|---|---|');
  let failed = '';
  const q = (v, x) => fmt(quantile(v, x), 1);
  const cell = (t) => {
    const bad = Object.entries(t.bad).map(([k, v]) => `${v}x ${k}`).join(', ');
    return `${t.ok} of ${t.n}, ${q(t.ms, 0.5)} / ${q(t.ms, 0.99)} / ${fmt(Math.max(...t.ms), 1)} (${q(t.fromConnect, 0.99)})${bad ? ` (${bad})` : ''}`;
  };
  for (const r of rows) {
    console.log(`| ${r.build} | ${r.name} | ${r.connected} / ${r.closedByDaemon} / ${r.answeredFlood}${r.pending ? ` (${r.pending} not taken in 5 s)` : ''} ` +
      `| ${cell(r.opening)}, ${fmt(r.openS, 1)} s | ${cell(r.held)} | ${r.after.ok} of ${r.after.n}, ${q(r.after.ms, 0.99)} ` +
      `| ${r.final.ok ? '200 ok' : `no (${r.final.status || r.final.error})`} ` +
      `| ${r.counters.evicted} / ${r.counters.timedOut} / ${r.counters.dropped} | ${fmt(r.load, 1)} |`);
    let bad = false;
    for (const t of [r.opening, r.held, r.after]) if (t.ok !== t.n) bad = true;
    if (!r.final.ok || r.exit !== 0) bad = true;
    if (bad) failed = failed ? `${failed}, ${r.build} ${r.name}` : `${r.build} ${r.name}`;
  }
  if (BASELINE) {
    // each build over its rows: the opening phase's p50 / p99 (the
    // flood's connect), the active client's answers in every phase, the
    // connections closed at accept; the build last (its name may hold digits)
    console.log('\n| while the floods open, every request: p50 / p99 ms | from connect: p50 / p99 ms | the active client, every phase: answered of asked | closed at accept | build |');
    console.log('|---|---|---|---|---|');
    for (const [i, b] of builds.map(buildName).entries()) {
      const mine = rows.filter((r) => r.build === b);
      const all = (key) => mine.flatMap((r) => r.opening[key]);
      const sum = (f) => mine.reduce((a, r) => a + f(r), 0);
      const asked = sum((r) => r.opening.n + r.held.n + r.after.n);
      const ok = sum((r) => r.opening.ok + r.held.ok + r.after.ok);
      console.log(`| ${q(all('ms'), 0.5)} / ${q(all('ms'), 0.99)} | ${q(all('fromConnect'), 0.5)} / ${q(all('fromConnect'), 0.99)} ` +
        `| ${ok} of ${asked} | ${sum((r) => r.counters.dropped)} | ${i === 0 ? 'baseline' : 'this build'}: ${b} |`);
    }
  }
  if (failed) {
    console.log(`\nflood: FAILED (${failed}): the active client or /api/v1/health was not answered every time`);
    process.exit(1);
  }
}

if (process.env.FLOOD_ACTIVE_PORT && process.send) activeClient(Number(process.env.FLOOD_ACTIVE_PORT));
else if (process.argv[1] === fileURLToPath(import.meta.url)) await main();
