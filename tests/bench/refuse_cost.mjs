// SPDX-License-Identifier: GPL-3.0-or-later
// What a creation refused for CPU costs the daemon (docs/budgets.md
// "What a refusal costs"): the cores for paced sessions are filled with
// default sessions at pace 1 (--max-paced-cores LIMIT, a few fit), then
// COUNT more creations of the same kind ({pace: 1, until: 120}, as
// realtime.mjs asks) come, IN_FLIGHT at once over keep-alive
// connections, and each must be 503 budget "cpu". The daemon's CPU
// (user + sys, /proc) over the flood, less what its running sessions
// spent in as long a quiet window just before, divided by COUNT, is the
// CPU a refusal costs; the client's latency p50 / p99 beside. OLD=path
// runs an earlier build the same way in the same minutes. Loopback only.
//
//   [CONVSIMD=build/convsimd] [OLD=path] [COUNT=2000] [LIMIT=0.01] [IN_FLIGHT=4] node tests/bench/refuse_cost.mjs
import http from 'node:http';
import { resolve } from 'node:path';
import { startDaemon } from '../http/lib.mjs';
import { call, procUsage, quantile, fmt } from './streamlag.mjs';

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const COUNT = Number(process.env.COUNT || 2000);
const LIMIT = Number(process.env.LIMIT || 0.01);
const IN_FLIGHT = Number(process.env.IN_FLIGHT || 4);
const BODY = { pace: 1, until: 120 };
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

// The daemon's CPU s over ms of wall time.
async function cpuOver(pid, ms) {
  const a = procUsage(pid).cpu, t = performance.now();
  await sleep(ms);
  return { cpu: procUsage(pid).cpu - a, ms: performance.now() - t };
}

async function run(bin) {
  const d = await startDaemon(['--max-paced-cores', String(LIMIT)], { wrap: [resolve(bin)] });
  const agent = new http.Agent({ keepAlive: true, maxSockets: IN_FLIGHT });
  try {
    let admitted = 0;
    for (;;) {
      const r = await call(d.base, 'POST', '/api/v1/sessions', BODY, { agent });
      if (r.status === 503 && r.body.budget === 'cpu') break;
      if (r.status !== 201) throw new Error(`filling: ${r.status} ${JSON.stringify(r.body)}`);
      admitted++;
    }
    await sleep(3000); // the workers' first measures settle the holds
    const quiet = await cpuOver(d.proc.pid, 3000);
    const before = procUsage(d.proc.pid).cpu, t0 = performance.now();
    const ms = [];
    let next = 0, other = 0;
    const worker = async () => {
      while (next < COUNT) {
        next++;
        const r = await call(d.base, 'POST', '/api/v1/sessions', BODY, { agent });
        if (r.status === 503 && r.body.budget === 'cpu') ms.push(r.ms);
        else other++;
      }
    };
    await Promise.all(Array.from({ length: IN_FLIGHT }, worker));
    const wall = performance.now() - t0, cpu = procUsage(d.proc.pid).cpu - before;
    const idle = quiet.cpu * (wall / quiet.ms);
    return {
      admitted, refused: ms.length, other, wall: wall / 1e3, cpu, idle,
      perRefusal: (cpu - idle) / COUNT, p50: quantile(ms, 0.5), p99: quantile(ms, 0.99),
    };
  } finally {
    agent.destroy();
    await d.stop();
  }
}

const runs = [...(OLD ? [[process.env.OLD_NAME || 'before', OLD]] : []), ['this', NEW]];
console.log('# What a creation refused for CPU costs the daemon\n');
console.log(`Command: \`${OLD ? 'OLD=path/to/previous/convsimd ' : ''}COUNT=${COUNT} LIMIT=${LIMIT} IN_FLIGHT=${IN_FLIGHT} ` +
  'node tests/bench/refuse_cost.mjs` (`bash tests/bench/refuse_cost.sh`): the cores for paced sessions ' +
  `(--max-paced-cores ${LIMIT}) filled with default sessions at pace 1, then ${COUNT} more default creations, ` +
  `${IN_FLIGHT} at a time, each refused 503 budget "cpu".\n`);
console.log('| build | admitted | refused (503 cpu) | other answers | wall s | daemon CPU s | of it the sessions | CPU per refusal, ms | latency p50 / p99, ms |');
console.log('|---|---|---|---|---|---|---|---|---|');
for (const [name, bin] of runs) {
  const r = await run(bin);
  console.log(`| ${name} | ${r.admitted} | ${r.refused} | ${r.other} | ${fmt(r.wall, 2)} | ${fmt(r.cpu, 2)} | ` +
    `${fmt(r.idle, 2)} | ${fmt(1e3 * r.perRefusal, 3)} | ${fmt(r.p50, 2)} / ${fmt(r.p99, 2)} |`);
}
