// SPDX-License-Identifier: GPL-3.0-or-later
// Where a daemon of paced default sessions spends its CPU (`make
// profile-daemon`, or `node tests/bench/profile.mjs [N] [SECONDS]`; needs
// perf, linux-perf, and a daemon built with frame pointers for the call
// chains): N sessions of the czubak2016 defaults at pace 1 (200 unless
// told), each with one NDJSON stream client at 10 samples per simulated
// second, as tests/bench/realtime.mjs runs them; 2 s after the last one
// started, `perf record -e cpu-clock -g` samples the daemon for SECONDS (8)
// of wall time. Prints markdown: a creation's CPU (the daemon's over the
// creations less its workers'), the daemon's CPU per session-second over
// those seconds, its CPU by part (table 1: each sample goes to the first
// part its call chain shows, in the order of the table) and the functions
// by their own share (table 2). CONVSIMD names the build (build/convsimd);
// BASELINE another, profiled first in the same minutes, for a column to
// compare with; PERF_DATA the output file (build/perf-daemon.data).
import { spawn, spawnSync } from 'node:child_process';
import http from 'node:http';
import { pathToFileURL } from 'node:url';
import { startDaemon } from '../http/lib.mjs';
import { call, lagStream, procUsage, fmt } from './streamlag.mjs';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// The parts of the daemon's CPU: [name, test of a sample's thread and
// call chain (function names, innermost first)], the first that matches.
const has = (frames, ...names) => frames.some((f) => names.some((n) => f === n || f.startsWith(n)));
const PARTS = [
  ['workers: the simulation (`sim_advance`)', (c, f) => c === 'session' && has(f, 'sim_advance')],
  ['workers: the sample\'s ring record and trajectory row (`srv_ring_sample`)', (c, f) => c === 'session' && has(f, 'srv_ring_sample')],
  ['workers: the feed\'s arrays and the status read out (`srv_ring_gather`, `sim_get_status`)', (c, f) => c === 'session' &&
    has(f, 'srv_ring_gather', 'sim_feed_state', 'sim_column_displacement', 'sim_get_status')],
  ['workers: sleeping, waking and waking the readers (futex, scheduler)', (c, f) => c === 'session' &&
    has(f, '__x64_sys_futex', 'futex_', '__futex', 'pthread_cond', 'schedule', 'finish_task_switch')],
  ['workers: the rest of the loop (clocks, phases, lock)', (c) => c === 'session'],
  ['streams: loopback sends (`sendto`)', (c, f) => c === 'MHD-connection' && has(f, '__x64_sys_sendto', '__send', 'tcp_')],
  ['streams: records formatted (`api_format_record`, printf, strtod)', (c, f) => c === 'MHD-connection' &&
    has(f, 'api_format_record', 'sim_fmt_double', '__vfprintf_internal', '__printf_fp', '____strtod', '__GI_____strtod', 'hack_digit', '__mpn_')],
  ['streams: sleeping and waking (futex, scheduler)', (c, f) => c === 'MHD-connection' &&
    has(f, '__x64_sys_futex', 'futex_', '__futex', 'pthread_cond', 'schedule', 'finish_task_switch')],
  ['streams: the rest (ring reads, polling)', (c) => c === 'MHD-connection'],
  ['other threads', () => true],
];

// perf's samples of data: [{comm, frames}].
function samples(data) {
  const out = spawnSync('perf', ['script', '-i', data, '-F', 'comm,ip,sym'], { encoding: 'utf8', maxBuffer: 1 << 28 }).stdout;
  return out.split('\n\n').map((block) => block.split('\n').filter((l) => l.trim())).filter((l) => l.length)
    .map((l) => ({ comm: l[0].trim().split(/\s+/)[0], frames: l.slice(1).map((x) => x.trim().split(/\s+/).slice(1).join(' ')) }));
}

// Profile the daemon bin (undefined: build/convsimd) with N sessions:
// {n, cpuPerS (ms per session-second), cores, parts: shares, self: [[fn, share]]}.
async function profile(bin, N, seconds, data) {
  const d = await startDaemon(['--max-sessions', String(Math.max(64, N)),
    '--max-streams', String(Math.max(256, N + 16)), '--max-client-connections', String(N + 64)],
  bin ? { wrap: [bin] } : {});
  const agent = new http.Agent({ keepAlive: true, maxSockets: 4 });
  const ids = [];
  const created0 = procUsage(d.proc.pid).cpu;
  for (let i = 0; i < N; i++) {
    const r = await call(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 120 }, { agent });
    if (r.status === 201) ids.push(r.body.id);
  }
  // the creations' CPU, less what the sessions already running spent
  // meanwhile (their measured CPU per session-second over the seconds run)
  const creating = procUsage(d.proc.pid).cpu - created0;
  const running = (await call(d.base, 'GET', '/api/v1/sessions', undefined, { agent })).body.sessions
    .reduce((sum, s) => sum + s.cpu_seconds, 0);
  const streams = ids.map((id) => lagStream(d.base, id, { ndjson: true, rate: 10 }));
  await sleep(2000);
  const t = async () => (await call(d.base, 'GET', '/api/v1/sessions', undefined, { agent })).body.sessions
    .reduce((sum, s) => sum + s.status.t, 0);
  const t0 = await t();
  const cpu0 = procUsage(d.proc.pid).cpu;
  const perf = spawn('perf', ['record', '-e', 'cpu-clock', '-F', '499', '-g', '-o', data,
    '-p', String(d.proc.pid), '--', 'sleep', String(seconds)], { stdio: ['ignore', 'ignore', 'ignore'] });
  await new Promise((r) => perf.on('exit', r));
  const cpu = procUsage(d.proc.pid).cpu - cpu0;
  const simulated = (await t()) - t0;
  streams.forEach((s) => s.stop());
  for (const id of ids) await call(d.base, 'DELETE', `/api/v1/sessions/${id}`, undefined, { agent });
  agent.destroy();
  await d.stop();
  const all = samples(data);
  const parts = PARTS.map(() => 0);
  const self = new Map();
  for (const { comm, frames } of all) {
    parts[PARTS.findIndex(([, test]) => test(comm, frames))]++;
    const fn = frames[0] || '?';
    self.set(fn, (self.get(fn) || 0) + 1);
  }
  return { n: ids.length, create: 1e3 * (creating - running) / ids.length, cpuPerS: 1e3 * cpu / simulated, cores: cpu / seconds, samples: all.length,
    parts: parts.map((k) => k / all.length),
    self: [...self].sort((a, b) => b[1] - a[1]).map(([fn, k]) => [fn, k / all.length]) };
}

if (import.meta.url === pathToFileURL(process.argv[1]).href) {
  const N = Number(process.argv[2]) || 200;
  const seconds = Number(process.argv[3]) || 8;
  const data = process.env.PERF_DATA || 'build/perf-daemon.data';
  const builds = process.env.BASELINE ? [['baseline', process.env.BASELINE], ['this build', process.env.CONVSIMD]]
    : [['this build', process.env.CONVSIMD]];
  const runs = [];
  for (const [name, bin] of builds) runs.push([name, await profile(bin, N, seconds, data)]);
  const pct = (x) => `${(100 * x).toFixed(1)} %`;
  console.log(`| | ${runs.map(([name]) => name).join(' | ')} |`);
  console.log(`|---|${runs.map(() => '---|').join('')}`);
  console.log(`| sessions admitted, of ${N} | ${runs.map(([, r]) => r.n).join(' | ')} |`);
  console.log(`| a creation, daemon CPU less the workers', ms | ${runs.map(([, r]) => fmt(r.create, 2)).join(' | ')} |`);
  console.log(`| daemon CPU, cores | ${runs.map(([, r]) => fmt(r.cores, 2)).join(' | ')} |`);
  console.log(`| daemon CPU per session-second, ms | ${runs.map(([, r]) => fmt(r.cpuPerS, 2)).join(' | ')} |`);
  console.log(`| perf samples | ${runs.map(([, r]) => r.samples).join(' | ')} |`);
  PARTS.forEach(([part], i) => console.log(`| ${part} | ${runs.map(([, r]) => pct(r.parts[i])).join(' | ')} |`));
  console.log('');
  const [, last] = runs[runs.length - 1];
  console.log(`| function (this build) | own share |`);
  console.log('|---|---|');
  for (const [fn, share] of last.self.filter(([, s]) => s >= 0.01)) console.log(`| \`${fn}\` | ${pct(share)} |`);
}
