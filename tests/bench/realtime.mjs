// How many default sessions one daemon holds in real time on this machine
// (`node tests/bench/realtime.mjs [N ...]`, not part of `make bench`: about
// 1 minute per N, loopback only, bounded). For each N it starts N sessions of
// the czubak2016 defaults at pace 1 on a fresh daemon, lets them run 10 s of
// wall time, then reads every session's achieved real-time factor (`rtf`,
// over the last half second) and counts those at 0.95 or better; then it
// deletes them. Prints a markdown table. tests/bench/cluster.mjs runs the
// same measurement (heldInRealTime) through HAProxy in front of replicas.
import { pathToFileURL } from 'node:url';
import { startDaemon, req, sleep } from '../http/lib.mjs';

// N default sessions at pace 1 on the daemon (or proxy) at base for
// `seconds` of wall time: {ok: how many at rtf >= 0.95, min, median,
// simulated: the seconds all of them simulated together}.
// The sessions are deleted afterwards.
export async function heldInRealTime(base, N, seconds = 10) {
  const ids = [];
  for (let i = 0; i < N; i++) {
    const r = await req(base, 'POST', '/api/v1/sessions', { pace: 1, until: 120 });
    if (r.status !== 201) throw new Error(`session ${i}: ${r.status} ${r.text}`);
    ids.push(r.body.id);
  }
  await sleep(seconds * 1000);
  const list = (await req(base, 'GET', '/api/v1/sessions')).body.sessions;
  const rtf = list.map((s) => s.status.rtf ?? s.rtf).filter((x) => Number.isFinite(x));
  rtf.sort((a, b) => a - b);
  const p = (q) => rtf[Math.min(rtf.length - 1, Math.floor(q * rtf.length))];
  const simulated = list.reduce((sum, s) => sum + s.status.t, 0);
  for (const id of ids) await req(base, 'DELETE', `/api/v1/sessions/${id}`, '');
  return { ok: rtf.filter((x) => x >= 0.95).length, min: p(0), median: p(0.5), simulated };
}

if (import.meta.url === pathToFileURL(process.argv[1]).href) {
  const counts = process.argv.slice(2).map(Number).filter((n) => n > 0);
  const Ns = counts.length ? counts : [50, 100, 150, 200];
  const rows = [];
  for (const N of Ns) {
    const d = await startDaemon(['--max-sessions', String(Math.max(64, N))]);
    const { ok, min, median } = await heldInRealTime(d.base, N);
    rows.push(`| ${N} | ${ok} | ${min.toFixed(2)} | ${median.toFixed(2)} |`);
    await d.stop();
  }
  console.log('Command: `node tests/bench/realtime.mjs` (czubak2016 defaults, pace 1, 10 s of wall time, 2 cores)\n');
  console.log('| sessions | at >= 0.95 of real time | slowest rtf | median rtf |');
  console.log('|---|---|---|---|');
  for (const r of rows) console.log(r);
}
