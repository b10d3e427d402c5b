// SPDX-License-Identifier: GPL-3.0-or-later
// Where a daemon of paced default sessions spends its CPU (`make
// profile-daemon`, or `node tests/bench/profile.mjs [N] [SECONDS]`; needs
// perf, linux-perf): N sessions of the czubak2016 defaults at pace 1 (200
// unless told), each with one NDJSON stream client at 10 samples per
// simulated second, as tests/bench/realtime.mjs runs them; once all run,
// `perf record -e cpu-clock -g` samples the daemon for SECONDS (8) of wall
// time, then `perf report` prints the functions by their own share
// (--no-children) and the daemon's CPU per session-second over those
// seconds. CONVSIMD names the build (build/convsimd); PERF_DATA the
// output file (build/perf-daemon.data); PERF_CALLERS=1 adds the callers.
import { spawn, spawnSync } from 'node:child_process';
import http from 'node:http';
import { startDaemon } from '../http/lib.mjs';
import { call, lagStream, procUsage, fmt } from './streamlag.mjs';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const N = Number(process.argv[2]) || 200;
const seconds = Number(process.argv[3]) || 8;
const data = process.env.PERF_DATA || 'build/perf-daemon.data';
const bin = process.env.CONVSIMD;

const d = await startDaemon(['--max-sessions', String(Math.max(64, N)),
  '--max-streams', String(Math.max(256, N + 16)), '--max-client-connections', String(N + 64)],
bin ? { wrap: [bin] } : {});
const agent = new http.Agent({ keepAlive: true, maxSockets: 4 });
const ids = [];
for (let i = 0; i < N; i++) {
  const r = await call(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 120 }, { agent });
  if (r.status === 201) ids.push(r.body.id);
}
const streams = ids.map((id) => lagStream(d.base, id, { ndjson: true, rate: 10 }));
await sleep(2000);
const t = (list) => list.reduce((sum, s) => sum + s.status.t, 0);
const before = (await call(d.base, 'GET', '/api/v1/sessions', undefined, { agent })).body.sessions;
const cpu0 = procUsage(d.proc.pid).cpu;
const perf = spawn('perf', ['record', '-e', 'cpu-clock', '-F', '499', '-g', '-o', data,
  '-p', String(d.proc.pid), '--', 'sleep', String(seconds)], { stdio: ['ignore', 'ignore', 'inherit'] });
await new Promise((r) => perf.on('exit', r));
const cpu = procUsage(d.proc.pid).cpu - cpu0;
const after = (await call(d.base, 'GET', '/api/v1/sessions', undefined, { agent })).body.sessions;
streams.forEach((s) => s.stop());
for (const id of ids) await call(d.base, 'DELETE', `/api/v1/sessions/${id}`, undefined, { agent });
agent.destroy();
await d.stop();
console.log(`${ids.length} of ${N} sessions admitted; over ${seconds} s: daemon CPU ${fmt(cpu / seconds, 2)} cores, ` +
  `${fmt(1e3 * cpu / (t(after) - t(before)), 2)} ms per session-second`);
const report = spawnSync('perf', ['report', '-i', data, '--stdio', '--no-children', '--percent-limit', '0.7',
  '--sort', 'symbol', ...(process.env.PERF_CALLERS ? ['-G'] : ['-g', 'none'])], { encoding: 'utf8' });
process.stdout.write(report.stdout.split('\n').filter((l) => l && !l.startsWith('#')).join('\n') + '\n');
