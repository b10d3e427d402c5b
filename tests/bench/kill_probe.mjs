// SPDX-License-Identifier: GPL-3.0-or-later
// The durability probe (docs/durability.md), run by hand: ROUNDS rounds of
// SESSIONS sessions (one in four paused) under back-to-back PATCHes
// (INFLIGHT clients each), the daemon killed with SIGKILL at a random
// moment of each round (150 to 400 ms in) while PATCHes are in flight.
// After each restart every acknowledged control must be in its session's
// controls.ndjson, in order, and the last logged beta in force; a GET
// that answers 200 must never show an older target than one already
// acknowledged. Prints one table row. Loopback and a temporary directory
// only; bounded (ROUNDS x about 1 s).
//
// CLIENT=lean (patch_client.mjs, the default) or fetch.
//
//   CONVSIMD=build/convsimd [ROUNDS=100] [SESSIONS=8] [INFLIGHT=2] [CLIENT=lean] node tests/bench/kill_probe.mjs
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { startDaemon } from '../http/lib.mjs'; // its tether: the daemons end with this script
import { client } from './patch_client.mjs';

const BIN = process.env.CONVSIMD || 'build/convsimd';
const ROUNDS = Number(process.env.ROUNDS || 100);
const SESSIONS = Number(process.env.SESSIONS || 8);
const INFLIGHT = Number(process.env.INFLIGHT || 2);
const KIND = process.env.CLIENT || 'lean';
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

const start = (dir) => startDaemon(['--data-dir', dir, '--checkpoint-interval', '0.5'],
  { wrap: [resolve(BIN)] });

const logged = (dir, id) => {
  let text = '';
  try { text = readFileSync(join(dir, 'sessions', id, 'controls.ndjson'), 'utf8'); } catch { /* none */ }
  return text.split('\n').filter((l) => l).map((l) => JSON.parse(l).beta).filter((b) => b !== undefined);
};

const dir = mkdtempSync(join(tmpdir(), 'convsim-kill-probe-'));
const acked = {}, logBase = {};
let ids = [], lost = 0, wrong = 0, past = 0, ackTotal = 0, loadSeconds = 0, n = 0, rounds = 0;
const t0 = Date.now();
try {
  for (let round = 0; round < ROUNDS; round++) {
    const d = await start(dir);
    const c0 = client(d.port, KIND);
    try {
      if (round === 0) {
        for (let i = 0; i < SESSIONS; i++) {
          const r = await c0.request('POST', '/api/v1/sessions', { pace: 1, scene: { drive: 'ideal', columns: 1, layers: 2 } });
          const id = JSON.parse(r.body).id;
          ids.push(id);
          acked[id] = [];
          if (i % 4 === 0) await c0.request('PATCH', `/api/v1/sessions/${id}`, { running: false });
        }
      } else {
        for (const id of ids) {
          let g;
          for (let k = 0; k < 600; k++) {
            const r = await c0.request('GET', `/api/v1/sessions/${id}`);
            if (r.status === 200) { g = JSON.parse(r.body); break; }
            await sleep(50);
          }
          const want = acked[id], log = logged(dir, id).slice(logBase[id] || 0);
          // concurrent clients of one session: the log's order is the
          // order applied, not the order the answers arrived in
          const inLog = new Set(log);
          const at = want.filter((b) => inLog.has(b)).length;
          lost += want.length - at;
          if (want.length - at && process.env.DEBUG) console.error(`round ${round} ${id}: acked ${JSON.stringify(want.slice(-8))} log ${JSON.stringify(log.slice(-8))} (${want.length} / ${log.length})`);
          acked[id] = []; // checked: the next round checks what it adds after the log so far
          logBase[id] = log.length;
          const all = logged(dir, id);
          if (all.length && (!g || g.status.beta_target !== all[all.length - 1])) {
            wrong++;
            if (process.env.DEBUG) console.error(`round ${round} ${id}: in force ${g && g.status.beta_target} (${g && g.state}, t ${g && g.status.t}), log ends ${JSON.stringify(all.slice(-3))}`);
          }
          if (g && all.length && !all.includes(g.status.beta_target)) past++;
        }
      }
      // back-to-back PATCHes, killed at a random moment
      let killed = false, ok = 0;
      const loadStart = Date.now();
      const patcher = async (id) => {
        const c = client(d.port, KIND);
        while (!killed) {
          const beta = (2000 + (n++ % 4000)) / 100; // two decimals, printed as sent
          try {
            const r = await c.request('PATCH', `/api/v1/sessions/${id}`, { beta });
            if (r.status === 200) { acked[id].push(beta); ok++; }
          } catch { break; /* cut by the kill: not acknowledged */ }
        }
        c.close();
      };
      const clients = ids.flatMap((id) => Array.from({ length: INFLIGHT }, () => patcher(id)));
      await sleep(150 + Math.random() * 250);
      killed = true;
      d.proc.kill('SIGKILL');
      loadSeconds += (Date.now() - loadStart) / 1000;
      await Promise.all(clients);
      ackTotal += ok;
      rounds++;
    } finally {
      c0.close();
      await d.stop('SIGKILL');
    }
  }
} finally {
  rmSync(dir, { recursive: true, force: true });
}
console.log(`    CONVSIMD=${BIN} ROUNDS=${ROUNDS} SESSIONS=${SESSIONS} INFLIGHT=${INFLIGHT} CLIENT=${KIND} node tests/bench/kill_probe.mjs\n`);
console.log('| kill -9 rounds | sessions | PATCH/s under load (acknowledged / s of load) | controls acknowledged | acknowledged lost | wrong target after restart | GET showing an unlogged target | wall s |');
console.log('|---|---|---|---|---|---|---|---|');
console.log(`| ${rounds} | ${SESSIONS} | ${(ackTotal / loadSeconds).toFixed(0)} | ${ackTotal} | ${lost} | ${wrong} | ${past} | ${((Date.now() - t0) / 1000).toFixed(0)} |`);
