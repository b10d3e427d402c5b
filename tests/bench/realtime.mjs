// SPDX-License-Identifier: GPL-3.0-or-later
// How many default sessions one daemon holds in real time on this machine
// (`node tests/bench/realtime.mjs [N ...]`; `make bench` runs it through
// realtime.sh, against the previous build: about
// half a minute per N, loopback only, bounded). For each N it starts N
// sessions of the czubak2016 defaults at pace 1 on a fresh daemon, each with
// one NDJSON stream client (trough fields, 10 samples per simulated second),
// lets them run 10 s of wall time, then reads every session's achieved
// real-time factor (`rtf`, over the last half second) and counts those at
// 0.95 or better, and takes the streams' lag (streamlag.mjs: each sample's
// delay against its session's wall clock) from 3 s after the last creation; then it
// deletes them. A creation the cores for paced sessions cannot take
// (--max-paced-cores) is 503 with budget "cpu": counted as refused, the run
// goes on with the others; so is a stream (each opened right after its
// session, which the daemon charges with it: the session runs on without
// it, a column of its own). Prints a markdown table; a row holds when every
// session and stream was admitted and kept real time and the lag's p99 is under 50
// ms. tests/bench/cluster.mjs runs the same measurement (heldInRealTime)
// through HAProxy in front of replicas. More daemon flags: DAEMON_FLAGS.
// BASELINE=path/to/another/convsimd runs each N on that build first, in
// the same minutes, for a row to compare with. The daemon's CPU per
// session-second (its user + sys time over the simulated seconds of all
// its sessions) is what the machine's other load distorts least.
import http from 'node:http';
import { pathToFileURL } from 'node:url';
import { startDaemon } from '../http/lib.mjs';
import { call, lagStream, quantile, procUsage, fmt } from './streamlag.mjs';

const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// N default sessions at pace 1 on the daemon (or proxy) at base, one NDJSON
// stream each opened right after its creation, for `seconds` of wall time
// after the last: {admitted: sessions created, refused: creations refused
// for CPU (503, budget "cpu"), streamsRefused: streams of admitted sessions
// refused for CPU (the session runs on without), ok: how many at
// rtf >= 0.95, min, median (rtf), lags (ms, every sample after the
// warm-up), simulated: the seconds all of them simulated together}. The
// sessions are deleted afterwards.
export async function heldInRealTime(base, N, seconds = 10) {
  const agent = new http.Agent({ keepAlive: true, maxSockets: 4 });
  const ids = [], streams = [];
  let refused = 0, streamsRefused = 0;
  for (let i = 0; i < N; i++) {
    const r = await call(base, 'POST', '/api/v1/sessions', { pace: 1, until: 120 }, { agent });
    if (r.status === 503 && r.body && r.body.budget === 'cpu') { refused++; continue; }
    if (r.status !== 201) throw new Error(`session ${i}: ${r.status} ${JSON.stringify(r.body)}`);
    ids.push(r.body.id);
    // its stream before the next creation: a daemon that charges streams
    // in the paced budget counts it there
    const st = lagStream(base, r.body.id, { ndjson: true, rate: 10 });
    const status = await st.ready;
    if (status === 503 && /"budget":"cpu"/.test(st.text || '')) { streamsRefused++; continue; }
    if (status !== 200) throw new Error(`stream ${i}: ${status} ${st.text || st.error || ''}`);
    streams.push(st);
  }
  // the lag from 3 s after the last creation, against each stream's
  // fastest delivery over its whole life (from its session's creation): a
  // session that fell behind while later ones were created, and did not
  // catch up, shows in it
  const from = performance.now() + 3000;
  for (const st of streams) st.collectFrom = from;
  await sleep(seconds * 1000);
  // a fresh connection: a proxy may have closed the kept-alive one while
  // the sessions ran
  const listed = await call(base, 'GET', '/api/v1/sessions');
  if (listed.status !== 200) throw new Error(`list: ${listed.status} ${listed.error || ''}`);
  const list = listed.body.sessions;
  const lags = streams.flatMap((s) => s.stop().lags);
  const rtf = list.map((s) => s.status.rtf).filter((x) => Number.isFinite(x)).sort((a, b) => a - b);
  const simulated = list.reduce((sum, s) => sum + s.status.t, 0);
  agent.destroy();
  const fresh = new http.Agent({ keepAlive: true, maxSockets: 4 });
  for (const id of ids) await call(base, 'DELETE', `/api/v1/sessions/${id}`, undefined, { agent: fresh });
  fresh.destroy();
  return { admitted: ids.length, refused, streamsRefused, ok: rtf.filter((x) => x >= 0.95).length, min: quantile(rtf, 0),
    median: quantile(rtf, 0.5), lags, simulated };
}

if (import.meta.url === pathToFileURL(process.argv[1]).href) {
  const counts = process.argv.slice(2).map(Number).filter((n) => n > 0);
  const Ns = counts.length ? counts : [50, 100, 150, 200];
  console.log('Command: `node tests/bench/realtime.mjs' + (counts.length ? ` ${counts.join(' ')}` : '') +
    '` (czubak2016 defaults, pace 1, one NDJSON stream each, 10 s of wall time, 2 cores)\n');
  const flags = (process.env.DAEMON_FLAGS || '').split(/\s+/).filter(Boolean);
  if (flags.length) console.log(`Daemon flags: ${flags.join(' ')}\n`);
  const builds = process.env.BASELINE ? [['baseline', process.env.BASELINE], ['this build', undefined]]
    : [['', undefined]];
  console.log('| build | sessions | admitted (refused: 503 cpu) | at >= 0.95 of real time | slowest rtf | median rtf | stream lag p50 / p99, ms | daemon CPU, cores | daemon CPU per session-second, ms | holds (all admitted, in real time, p99 < 50 ms) | streams refused (503 cpu) |');
  console.log('|---|---|---|---|---|---|---|---|---|---|---|');
  for (const N of Ns) {
    for (const [name, bin] of builds) {
      const d = await startDaemon(['--max-sessions', String(Math.max(64, N)),
        '--max-streams', String(Math.max(256, N + 16)), '--max-client-connections', String(N + 64), ...flags],
      bin ? { wrap: [bin] } : {});
      const cpu0 = procUsage(d.proc.pid).cpu;
      const t0 = Date.now();
      const { admitted, refused, streamsRefused, ok, min, median, lags, simulated } = await heldInRealTime(d.base, N);
      const cpu = procUsage(d.proc.pid).cpu - cpu0;
      const p99 = quantile(lags, 0.99);
      const holds = admitted === N && !streamsRefused && ok === admitted && p99 < 50;
      console.log(`| ${name} | ${N} | ${admitted} (${refused}) | ${ok} | ${fmt(min, 2)} | ${fmt(median, 2)} | ` +
        `${fmt(quantile(lags, 0.5))} / ${fmt(p99)} | ${fmt(cpu / ((Date.now() - t0) / 1000), 2)} | ` +
        `${fmt(1e3 * cpu / simulated, 2)} | ${holds ? 'yes' : `no${(admitted < N || streamsRefused) && ok === admitted && p99 < 50 ? ': the admitted in real time, the rest 503' : ''}`} | ${streamsRefused} |`);
      await d.stop();
    }
  }
}
