// SPDX-License-Identifier: GPL-3.0-or-later
// What a burst of large creations does to a running daemon
// (docs/load.md "Creations that settle"): a default session at pace
// 1 and a 16 x 64 scene at pace 0.5 run, then N creations of a COLUMNS x
// LAYERS scene (pace 0.01, one sample a simulated s) are sent at once.
// Each settles its steady start and runs its probe in its request's
// thread before it is answered. Reported per build: the answers by
// status, the most requests that settled at once (the daemon's request
// threads, named MHD-connection, that used at least 20 ms of CPU in a
// 0.5-s window of /proc; and the daemon's own convsim_settling_max where
// it has it), the burst's wall time (from the first request to the last
// answer), the daemon's CPU over it, the pace the two running sessions
// kept over it and over a quiet window of 5 s before (simulated s per
// wall s over their pace: 1 is their pace), and the latency of a GET of
// the default session asked every 100 ms throughout. OLD=path runs an
// earlier build the same way in the same minutes. Loopback only.
//
//   [CONVSIMD=build/convsimd] [OLD=path] [N=10] [COLUMNS=64] [LAYERS=64] node tests/bench/settle_flood.mjs
import { readFileSync, readdirSync } from 'node:fs';
import { resolve } from 'node:path';
import { startDaemon, req } from '../http/lib.mjs';
import { procUsage, quantile, fmt } from './streamlag.mjs';

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const N = Number(process.env.N || 10);
const COLUMNS = Number(process.env.COLUMNS || 64);
const LAYERS = Number(process.env.LAYERS || 64);
const BODY = { scene: { columns: COLUMNS, layers: LAYERS }, pace: 0.01, sample_rate: 1 };
const PACES = [1, 0.5];
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// CPU s of each request thread of the daemon, by thread id.
function requestThreads(pid) {
  const out = new Map();
  for (const tid of readdirSync(`/proc/${pid}/task`)) {
    try {
      const s = readFileSync(`/proc/${pid}/task/${tid}/stat`, 'utf8');
      if (s.slice(s.indexOf('(') + 1, s.lastIndexOf(')')) !== 'MHD-connection') continue;
      const f = s.slice(s.lastIndexOf(')') + 2).split(' ');
      out.set(tid, (Number(f[11]) + Number(f[12])) / 100);
    } catch { /* the thread ended */ }
  }
  return out;
}

const simulated = async (base, id) => (await req(base, 'GET', `/api/v1/sessions/${id}`)).body.status.t;
const rtfs = async (base, ids, ms) => {
  const t0 = await Promise.all(ids.map((id) => simulated(base, id))), w0 = performance.now();
  await ms();
  const wall = (performance.now() - w0) / 1e3;
  const t1 = await Promise.all(ids.map((id) => simulated(base, id)));
  return { wall, rtf: t0.map((t, i) => (t1[i] - t) / wall / PACES[i]) };
};

async function run(bin) {
  const d = await startDaemon(['--ring', '64'], { wrap: [resolve(bin)] });
  try {
    const ids = [];
    for (const body of [{ pace: 1 }, { scene: { columns: 16, layers: 64 }, pace: 0.5, sample_rate: 10 }]) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', body);
      if (r.status !== 201) throw new Error(`running session: ${r.status} ${r.text}`);
      ids.push(r.body.id);
    }
    await sleep(3000); // their workers' first measures
    const quiet = await rtfs(d.base, ids, () => sleep(5000));
    let done = false, most = 0;
    const sampler = (async () => {
      let prev = requestThreads(d.proc.pid);
      while (!done) {
        await sleep(500);
        const cur = requestThreads(d.proc.pid);
        let busy = 0;
        for (const [tid, cpu] of cur) if (prev.has(tid) && cpu - prev.get(tid) >= 0.02) busy++;
        most = Math.max(most, busy);
        prev = cur;
      }
    })();
    const lat = [];
    const poller = (async () => {
      while (!done) {
        const t = performance.now();
        await req(d.base, 'GET', `/api/v1/sessions/${ids[0]}`);
        lat.push(performance.now() - t);
        await sleep(100);
      }
    })();
    const cpu0 = procUsage(d.proc.pid).cpu;
    const statuses = {};
    const flood = await rtfs(d.base, ids, () => Promise.all(Array.from({ length: N }, async () => {
      const r = await req(d.base, 'POST', '/api/v1/sessions', BODY);
      statuses[r.status] = (statuses[r.status] || 0) + 1;
    })));
    const cpu = procUsage(d.proc.pid).cpu - cpu0;
    done = true;
    await Promise.all([sampler, poller]);
    const m = (await req(d.base, 'GET', '/metrics')).text.match(/^convsim_settling_max (\S+)$/m);
    return { statuses, most, daemonMost: m ? m[1] : 'n/a', wall: flood.wall, cpu, quiet: quiet.rtf, rtf: flood.rtf, lat };
  } finally {
    await d.stop();
  }
}

const runs = [...(OLD ? [[process.env.OLD_NAME || 'before', OLD]] : []), ['this', NEW]];
console.log('# A burst of large creations beside running sessions\n');
console.log(`Command: \`${OLD ? 'OLD=path/to/previous/convsimd ' : ''}N=${N} COLUMNS=${COLUMNS} LAYERS=${LAYERS} ` +
  'node tests/bench/settle_flood.mjs` (`bash tests/bench/settle_flood.sh`): a default session at pace 1 and a ' +
  `16 x 64 scene at pace 0.5 run; ${N} creations of a ${COLUMNS} x ${LAYERS} scene (pace 0.01, sample_rate 1) are sent at once.\n`);
console.log('| build | answers | settling at once (threads) | convsim_settling_max | burst wall s | daemon CPU s | ' +
  'pace kept, default: quiet / burst | pace kept, 16 x 64: quiet / burst | GET latency p50 / p99 / max, ms |');
console.log('|---|---|---|---|---|---|---|---|---|');
for (const [name, bin] of runs) {
  const r = await run(bin);
  const answers = Object.entries(r.statuses).map(([s, n]) => `${n} x ${s}`).join(', ');
  console.log(`| ${name} | ${answers} | ${r.most} | ${r.daemonMost} | ${fmt(r.wall, 2)} | ${fmt(r.cpu, 2)} | ` +
    `${fmt(r.quiet[0], 3)} / ${fmt(r.rtf[0], 3)} | ${fmt(r.quiet[1], 3)} / ${fmt(r.rtf[1], 3)} | ` +
    `${fmt(quantile(r.lat, 0.5), 1)} / ${fmt(quantile(r.lat, 0.99), 1)} / ${fmt(Math.max(...r.lat), 1)} |`);
}
