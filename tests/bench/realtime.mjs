// How many default sessions one daemon holds in real time on this machine
// (`node tests/bench/realtime.mjs [N ...]`, not part of `make bench`: about
// half a minute per N, loopback only, bounded). For each N it starts N
// sessions of the czubak2016 defaults at pace 1 on a fresh daemon, each with
// one NDJSON stream client (trough fields, 10 samples per simulated second),
// lets them run 10 s of wall time, then reads every session's achieved
// real-time factor (`rtf`, over the last half second) and counts those at
// 0.95 or better, and takes the streams' lag (streamlag.mjs: each sample's
// delay against its session's wall clock) after the first 3 s; then it
// deletes them. Prints a markdown table; a row holds when every session kept
// real time and the lag's p99 is under 50 ms.
import http from 'node:http';
import { startDaemon } from '../http/lib.mjs';
import { call, lagStream, quantile, procUsage, fmt } from './streamlag.mjs';

const counts = process.argv.slice(2).map(Number).filter((n) => n > 0);
const Ns = counts.length ? counts : [50, 100, 150, 200];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
console.log('Command: `node tests/bench/realtime.mjs' + (counts.length ? ` ${counts.join(' ')}` : '') +
  '` (czubak2016 defaults, pace 1, one NDJSON stream each, 10 s of wall time, 2 cores)\n');
console.log('| sessions | at >= 0.95 of real time | slowest rtf | median rtf | stream lag p50 / p99, ms | daemon CPU, cores | holds (all real time, p99 < 50 ms) |');
console.log('|---|---|---|---|---|---|---|');
for (const N of Ns) {
  const d = await startDaemon(['--max-sessions', String(Math.max(64, N)),
    '--max-streams', String(Math.max(256, N + 16)), '--max-client-connections', String(N + 64)]);
  const agent = new http.Agent({ keepAlive: true, maxSockets: 4 });
  const ids = [];
  for (let i = 0; i < N; i++) {
    const r = await call(d.base, 'POST', '/api/v1/sessions', { pace: 1, until: 120 }, { agent });
    if (r.status !== 201) throw new Error(`session ${i}: ${r.status} ${JSON.stringify(r.body)}`);
    ids.push(r.body.id);
  }
  const streams = ids.map((id) => lagStream(d.base, id, { ndjson: true, rate: 10, warmup: 3000 }));
  const cpu0 = procUsage(d.proc.pid).cpu;
  await sleep(10000);
  const cpu = procUsage(d.proc.pid).cpu - cpu0;
  const list = (await call(d.base, 'GET', '/api/v1/sessions', undefined, { agent })).body.sessions;
  const lags = streams.flatMap((s) => s.stop().lags);
  const rtf = list.map((s) => s.status.rtf).filter((x) => Number.isFinite(x)).sort((a, b) => a - b);
  const ok = rtf.filter((x) => x >= 0.95).length;
  const p99 = quantile(lags, 0.99);
  const holds = ok === N && p99 < 50;
  console.log(`| ${N} | ${ok} | ${fmt(quantile(rtf, 0), 2)} | ${fmt(quantile(rtf, 0.5), 2)} | ` +
    `${fmt(quantile(lags, 0.5))} / ${fmt(p99)} | ${fmt(cpu / 10, 2)} | ${holds ? 'yes' : 'no'} |`);
  for (const id of ids) await call(d.base, 'DELETE', `/api/v1/sessions/${id}`, undefined, { agent });
  agent.destroy();
  await d.stop();
}
