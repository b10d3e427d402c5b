// SPDX-License-Identifier: GPL-3.0-or-later
// Helpers for the HTTP tests: start the real daemon on an ephemeral port,
// talk JSON to it, and read its SSE / NDJSON streams record by record.
// CONVSIMD names the binary (build/convsimd or build-san/convsimd); the
// sanitizer build is slower, so timeouts scale with SLOW.
import assert from 'node:assert/strict';
import { execFileSync, spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, readdirSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { fileURLToPath } from 'node:url';
import '../tether.mjs'; // nothing started here outlives the test

export const BIN = process.env.CONVSIMD ||
  fileURLToPath(new URL('../../build/convsimd', import.meta.url));
// the command line of the same build (CONVSIM: another one)
export const CLI = process.env.CONVSIM ||
  fileURLToPath(new URL('../../build/convsim', import.meta.url));
export const SLOW = Number(process.env.CONVSIM_TEST_SLOW ||
  (BIN.includes('build-san') ? 4 : 1));
export const WEB_ROOT = fileURLToPath(new URL('../../web', import.meta.url));

// A scene that is cheap to integrate but still transports feed.
export const CHEAP = { scene: { drive: 'ideal', columns: 1, layers: 2 } };
export const NO_FEED = { scene: { drive: 'ideal', feed: false } };

// opts.wrap: a command the daemon is started under (its arguments follow),
// opts.tail: arguments after the usual ones (persistence.test.mjs).
export async function startDaemon(args = [], opts = {}) {
  const daemonArgs = ['--port', '0', '--log-level', 'warn', '--web-root', WEB_ROOT,
    ...args, ...(opts.tail || [])];
  const [cmd, ...pre] = opts.wrap ? opts.wrap : [BIN];
  const proc = spawn(cmd, [...pre, ...daemonArgs], { stdio: ['ignore', 'pipe', 'pipe'] });
  let stderr = '';
  proc.stderr.on('data', (d) => { stderr += d; });
  const exited = new Promise((resolve) => proc.on('exit', (code, sig) => resolve({ code, sig })));
  const port = await new Promise((resolve, reject) => {
    let out = '';
    const timer = setTimeout(() => reject(new Error(`no port line; stderr: ${stderr}`)), 10000 * SLOW);
    proc.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/^listening on http:\/\/\S+:(\d+)$/m);
      if (m) { clearTimeout(timer); resolve(Number(m[1])); }
    });
    exited.then(({ code }) => { clearTimeout(timer); reject(new Error(`daemon exited ${code}: ${stderr}`)); });
  });
  const base = `http://127.0.0.1:${port}`;
  return {
    proc, port, base, exited,
    stderr: () => stderr,
    async stop(signal = 'SIGTERM') {
      if (proc.exitCode === null && proc.signalCode === null) proc.kill(signal);
      const timer = setTimeout(() => proc.kill('SIGKILL'), 20000 * SLOW);
      const r = await exited;
      clearTimeout(timer);
      return r;
    },
  };
}

// A token file (mode 0600 unless told) in a fresh temporary directory.
export function tokenFile(token, mode = 0o600) {
  const file = join(mkdtempSync(join(tmpdir(), 'convsim-token-')), 'token');
  writeFileSync(file, token + '\n', { mode });
  return file;
}

// fetch with a JSON body; returns {status, headers, body (parsed when JSON), text}.
// POST, PATCH, PUT and DELETE carry Content-Type: application/json (the
// daemon refuses them without it) unless headers name another or null.
export async function req(base, method, path, body, headers = {}) {
  const init = { method, headers: { ...headers } };
  if (body !== undefined) init.body = typeof body === 'string' ? body : JSON.stringify(body);
  if ((body !== undefined || /^(POST|PATCH|PUT|DELETE)$/.test(method)) &&
      !('Content-Type' in init.headers)) init.headers['Content-Type'] = 'application/json';
  if (init.headers['Content-Type'] === null) delete init.headers['Content-Type'];
  const res = await fetch(base + path, init);
  const text = await res.text();
  let parsed = null;
  const ct = res.headers.get('content-type') || '';
  if (ct.includes('json') && text) parsed = JSON.parse(text);
  return { status: res.status, headers: res.headers, body: parsed, text };
}

// store.c's frame header: 32 bytes, the payload's checksum at 24.
export const STORE_FRAME = 32;
// A file of the data directory with its frame's checksum made right again
// after an edit: core/checkpoint.c's sim_checksum (FNV-1a 64 with its
// starting value) of the payload.
export function reframe(buf) {
  let h = 1469598103934665603n;
  for (let i = STORE_FRAME; i < buf.length; i++) {
    h ^= BigInt(buf[i]);
    h = (h * 0x100000001b3n) & 0xffffffffffffffffn;
  }
  buf.writeBigUInt64LE(h, 24);
  return buf;
}

// A session re-created from its spec at the last start (its checkpoint
// unusable) once its replay is over: its document.
export async function untilReplayed(base, id, ms = 20000) {
  return until(async () => {
    const r = await req(base, 'GET', `/api/v1/sessions/${id}`);
    return r.status === 200 && r.body.replay_seconds !== null && r.body;
  }, ms, `session ${id}'s replay over`);
}

// GET path once it is not 503: a session restored with controls to
// replay answers 503 (Retry-After) until it is back where it was
// (docs/durability.md). The answer {status, headers, body, text}.
export async function getReady(base, path, ms = 20000) {
  return until(async () => {
    const r = await req(base, 'GET', path);
    return r.status !== 503 && r;
  }, ms, `${path} answering`);
}

// |actual - expected| <= tol, with both in the message.
export function near(actual, expected, tol, what = 'value') {
  if (!(Math.abs(actual - expected) <= tol)) {
    throw new Error(`${what}: ${actual} is not within ${tol} of ${expected}`);
  }
}

export const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// Poll fn until it returns a truthy value or the time runs out.
export async function until(fn, ms, what = 'condition') {
  const end = Date.now() + ms * SLOW;
  for (;;) {
    const v = await fn();
    if (v) return v;
    if (Date.now() > end) throw new Error(`timed out waiting for ${what}`);
    await sleep(50);
  }
}

// Parse SSE text blocks into {id, event, data} records; comments are
// returned as {comment}.
export function parseSse(block) {
  const rec = { event: 'message' };
  const data = [];
  for (const line of block.split('\n')) {
    if (line.startsWith(':')) return { comment: line.slice(1).trim() };
    const i = line.indexOf(':');
    const field = i < 0 ? line : line.slice(0, i);
    const value = i < 0 ? '' : line.slice(i + 1).replace(/^ /, '');
    if (field === 'data') data.push(value);
    else if (field === 'id') rec.id = Number(value);
    else if (field === 'event') rec.event = value;
    else if (field === 'retry') rec.retry = Number(value);
  }
  if (data.length) rec.data = JSON.parse(data.join('\n'));
  return rec;
}

// Open a stream and yield records: SSE blocks as {id, event, data}, NDJSON
// lines as parsed objects. The caller breaks out to close it.
export async function* openStream(base, path, headers = {}, signal) {
  const res = await fetch(base + path, { headers, signal });
  if (res.status !== 200) throw new Error(`stream ${path}: ${res.status} ${await res.text()}`);
  const ndjson = (res.headers.get('content-type') || '').includes('ndjson');
  const sep = ndjson ? '\n' : '\n\n';
  const dec = new TextDecoder();
  let buf = '';
  for await (const chunk of res.body) {
    buf += dec.decode(chunk, { stream: true });
    let at;
    while ((at = buf.indexOf(sep)) >= 0) {
      const block = buf.slice(0, at);
      buf = buf.slice(at + sep.length);
      if (!block) continue;
      yield ndjson ? JSON.parse(block) : parseSse(block);
    }
  }
}

// The first record of the session id's NDJSON stream that pick(record,
// records so far) returns; fails after ms, naming the first records.
export async function streamUntil(base, id, pick, ms = 10000 * SLOW) {
  const ac = new AbortController();
  const timer = setTimeout(() => ac.abort(), ms);
  const seen = [];
  try {
    for await (const rec of openStream(base, `/api/v1/sessions/${id}/stream?format=ndjson`, {}, ac.signal)) {
      seen.push(rec);
      const hit = pick(rec, seen);
      if (hit) return hit;
    }
  } catch (e) {
    if (!ac.signal.aborted) throw e;
  } finally {
    clearTimeout(timer);
    ac.abort();
  }
  assert.fail(`no such record in ${JSON.stringify(seen.slice(0, 5))}`);
}

// Value of one Prometheus sample, e.g. metric(text, 'convsim_sessions') or
// metric(text, 'convsim_http_requests_total{status="201"}'); 0 if absent.
export function metric(text, key) {
  const line = text.split('\n').find((l) => l.startsWith(key + ' '));
  return line ? Number(line.slice(key.length + 1)) : 0;
}

// One request written byte for byte on a fresh socket (any Host, Origin or
// invalid UTF-8 a browser or fetch would not send); the answer is read until
// the daemon closes. head: the request line and headers as a string or
// Buffer, without the blank line; "Connection: close" is added. Returns
// {status, headers (lower-case names; repeated ones joined by ", "), body
// (Buffer), raw (Buffer)}.
export async function rawRequest(port, head, body = '') {
  const { connect } = await import('node:net');
  const raw = await new Promise((resolve, reject) => {
    const sock = connect(port, '127.0.0.1');
    const parts = [];
    sock.setTimeout(15000 * SLOW, () => { sock.destroy(); reject(new Error('raw request timed out')); });
    sock.on('data', (b) => parts.push(b));
    sock.on('end', () => resolve(Buffer.concat(parts)));
    sock.on('error', reject);
    sock.write(Buffer.concat([Buffer.from(head), Buffer.from('\r\nConnection: close\r\n\r\n'),
      Buffer.from(body)]));
  });
  const at = raw.indexOf('\r\n\r\n');
  const lines = raw.subarray(0, at).toString('latin1').split('\r\n');
  const headers = {};
  for (const l of lines.slice(1)) {
    const i = l.indexOf(':');
    const k = l.slice(0, i).toLowerCase();
    const v = l.slice(i + 1).trim();
    headers[k] = k in headers ? `${headers[k]}, ${v}` : v;
  }
  return { status: Number(lines[0].split(' ')[1]), headers, body: raw.subarray(at + 4), raw };
}

// n distinct free loopback ports (held open together, then released).
export async function freePorts(n) {
  const net = await import('node:net');
  const servers = await Promise.all(Array.from({ length: n }, () => new Promise((resolve) => {
    const s = net.createServer();
    s.listen(0, '127.0.0.1', () => resolve(s));
  })));
  const ports = servers.map((s) => s.address().port);
  await Promise.all(servers.map((s) => new Promise((r) => s.close(r))));
  return ports;
}

export const CLUSTER_SCRIPT = fileURLToPath(new URL('../../server/cluster.sh', import.meta.url));

// Replicas behind HAProxy, as `make cluster N=n` starts them
// (server/cluster.sh run), on free ports in the directory dir; env adds to
// the script's environment. Returns {base, env, pids: {n1.., haproxy},
// runner, output(), stop()}: stop() sends SIGTERM to the script, which
// stops everything it started.
export async function startCluster(n, dir, env = {}) {
  const [proxy, ...ports] = await freePorts(n + 1);
  const fullEnv = {
    ...process.env, N: String(n), PROXY_PORT: String(proxy), PORTS: ports.join(' '), DIR: dir,
    CONVSIMD: BIN, DAEMON_FLAGS: `--log-level warn --web-root ${WEB_ROOT}`, ...env,
  };
  const runner = spawn('bash', [CLUSTER_SCRIPT, 'run'], { env: fullEnv, stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  runner.stderr.on('data', (d) => { output += d; });
  const exited = new Promise((resolve) => runner.on('exit', (code) => resolve(code)));
  const base = await new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`no cluster line: ${output}`)), 20000 * SLOW);
    runner.stdout.on('data', (d) => {
      output += d;
      const m = output.match(/^cluster: (http:\/\/127\.0\.0\.1:\d+)\//m);
      if (m) { clearTimeout(timer); resolve(m[1]); }
    });
    exited.then((code) => { clearTimeout(timer); reject(new Error(`cluster.sh exited ${code}: ${output}`)); });
  });
  const { readFileSync } = await import('node:fs');
  const pids = {};
  for (let k = 1; k <= n; k++) pids[`n${k}`] = Number(readFileSync(`${dir}/n${k}.pid`, 'utf8'));
  pids.haproxy = Number(readFileSync(`${dir}/haproxy.pid`, 'utf8'));
  return {
    base, env: fullEnv, pids, runner, ports, output: () => output,
    async stop() {
      if (runner.exitCode === null) runner.kill('SIGTERM');
      return exited;
    },
  };
}

// printf's %.3g for the magnitudes the budgets' answers carry (1e-4 .. 1e3)
export const g3 = (x) => String(Number(x.toPrecision(3)));
// a need in cores as a detail words it: "1 core" where %.3g reads 1
export const cores = (x) => `${g3(x)} core${g3(x) === '1' ? '' : 's'}`;

// The 503 a creation gets when the cores for paced sessions cannot take it
// (server/admit/budget.c's words): it needs `need` cores, `cpu` CPU s a
// simulated s at `pace`, while running paced sessions hold `sum` of `limit`.
export const pacedBusy = (need, cpu, pace, sum, limit) => ({
  type: '/api/v1/problems/unavailable',
  title: 'Service unavailable',
  status: 503,
  detail: `this session needs ${cores(need)} (${g3(1e3 * cpu)} ms of CPU per simulated s at pace ${pace}) ` +
    `and running paced sessions hold ${g3(sum)} of the ${limit} cores for paced sessions ` +
    '(--max-paced-cores); nothing was created, retry when paced sessions have ended, paused or slowed down',
  instance: '/api/v1/sessions',
  field: 'pace',
  budget: 'cpu',
  limit,
});

// Each kind's hold at pace 1 (CPU s per simulated s), kinds {name: body}, as
// a daemon of its own takes it from the scene's estimate (--cpu-probe 0),
// before a worker has measured it: each created (pace 1, until 600), read,
// deleted and given back, one at a time. {name: hold}.
export async function pacedEstimates(kinds) {
  const d = await startDaemon(['--cpu-probe', '0']);
  const held = async () => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_paced_cpu_cores');
  const out = {};
  try {
    for (const [name, body] of Object.entries(kinds)) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', { ...body, pace: 1, until: 600 });
      assert.equal(r.status, 201, r.text);
      out[name] = await held();
      assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${r.body.id}`)).status, 204);
      assert.equal(await held(), 0, 'given back');
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  return out;
}

// Default sessions at pace 1 (until 600) created on d until as many as
// --max-paced-cores `limit` takes run; held() reads what they hold. The
// first one's hold is a session's cost. {ids, cost, fit}.
export async function fillPaced(d, limit, held, least = 1e-4) {
  const create = () => req(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 600 });
  const first = await create();
  assert.equal(first.status, 201, first.text);
  const cost = await held();
  assert.ok(cost > least && cost < limit / 2, `a default session's estimate: ${cost}`);
  const fit = Math.floor(limit / cost);
  const ids = [first.body.id];
  while (ids.length < fit) {
    const r = await create();
    assert.equal(r.status, 201, `session ${ids.length + 1} of ${fit} fits: ${r.text}`);
    ids.push(r.body.id);
  }
  return { ids, cost, fit };
}

// Process pid's children now (a daemon's bed processes), from every
// thread's /proc list.
export function children(pid) {
  const out = [];
  for (const task of readdirSync(`/proc/${pid}/task`)) {
    const text = readFileSync(`/proc/${pid}/task/${task}/children`, 'utf8').trim();
    if (text) out.push(...text.split(/\s+/).map(Number));
  }
  return out;
}

// A process's state letter (Z: a zombie), or null when it is gone.
export function procState(pid) {
  try { return readFileSync(`/proc/${pid}/stat`, 'utf8').replace(/^.*\) /, '')[0]; } catch { return null; }
}

// The user + system CPU seconds process pid has spent (its every thread;
// /proc/PID/stat in clock ticks, CLK_TCK a second): what a request cost the
// daemon, which the machine's other load does not stretch as it does the
// wall time.
const TICK = Number(execFileSync('getconf', ['CLK_TCK'], { encoding: 'utf8' }));
export function processCpu(pid) {
  const stat = readFileSync(`/proc/${pid}/stat`, 'utf8');
  const f = stat.slice(stat.lastIndexOf(')') + 2).split(' ');
  return (Number(f[11]) + Number(f[12])) / TICK;
}

// A POST to the daemon d that is refused 422 with a problem+json body:
// the answer and the daemon's CPU seconds over the request.
export async function postRefusedCpu(d, path, body) {
  const cpu0 = processCpu(d.proc.pid);
  const r = await req(d.base, 'POST', path, body);
  const cpu = processCpu(d.proc.pid) - cpu0;
  assert.equal(r.status, 422, r.text);
  assert.equal(r.headers.get('content-type'), 'application/problem+json');
  return { r, cpu };
}

// A POST to the daemon d whose work in the request's thread an adaptive
// method (dopri5) ran past --max-cpu-seconds (limit): 422 out-of-range
// naming field with the methods of a fixed step as its choices, budget cpu
// at limit (settle_stop.test.mjs, measure_stop.test.mjs). Returns the
// detail, for the caller's own pattern, and the daemon's CPU seconds over
// the request.
export async function postStoppedAdaptive(d, path, body, field, limit) {
  const { r, cpu } = await postRefusedCpu(d, path, body);
  const { detail, ...rest } = r.body;
  assert.deepEqual(rest, {
    type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422,
    instance: path, field, budget: 'cpu', limit, choices: ['rk4', 'euler', 'dem'],
  });
  return { detail, cpu };
}
