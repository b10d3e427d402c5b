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
//   CONVSIMD=build/convsimd [ROUNDS=100] [SESSIONS=8] [INFLIGHT=2] node tests/bench/kill_probe.mjs
import { spawn } from 'node:child_process';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // the daemons end with this script, however it ends

const BIN = process.env.CONVSIMD || 'build/convsimd';
const ROUNDS = Number(process.env.ROUNDS || 100);
const SESSIONS = Number(process.env.SESSIONS || 8);
const INFLIGHT = Number(process.env.INFLIGHT || 2);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));

async function start(dir) {
  const p = spawn(BIN, ['--port', '0', '--log-level', 'warn', '--data-dir', dir,
    '--checkpoint-interval', '0.5'], { stdio: ['ignore', 'pipe', 'ignore'] });
  const port = await new Promise((resolve, reject) => {
    let out = '';
    const t = setTimeout(() => reject(new Error('no port')), 30000);
    p.stdout.on('data', (d) => {
      out += d;
      const m = out.match(/listening on http:\/\/\S+:(\d+)/);
      if (m) { clearTimeout(t); resolve(Number(m[1])); }
    });
    p.on('exit', (c) => reject(new Error(`exited ${c}`)));
  });
  return { p, base: `http://127.0.0.1:${port}/api/v1` };
}

const json = (method, body) => ({ method, headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(body) });
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
    try {
      if (round === 0) {
        for (let i = 0; i < SESSIONS; i++) {
          const r = await fetch(`${d.base}/sessions`, json('POST', { pace: 1, scene: { drive: 'ideal', columns: 1, layers: 2 } }));
          const id = (await r.json()).id;
          ids.push(id);
          acked[id] = [];
          if (i % 4 === 0) await (await fetch(`${d.base}/sessions/${id}`, json('PATCH', { running: false }))).arrayBuffer();
        }
      } else {
        for (const id of ids) {
          let g;
          for (let k = 0; k < 600; k++) {
            const r = await fetch(`${d.base}/sessions/${id}`);
            const b = await r.json();
            if (r.status === 200) { g = b; break; }
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
      const client = async (id) => {
        while (!killed) {
          const beta = (2000 + (n++ % 4000)) / 100; // two decimals, printed as sent
          try {
            const r = await fetch(`${d.base}/sessions/${id}`, json('PATCH', { beta }));
            await r.arrayBuffer();
            if (r.status === 200) { acked[id].push(beta); ok++; }
          } catch { return; /* cut by the kill: not acknowledged */ }
        }
      };
      const clients = ids.flatMap((id) => Array.from({ length: INFLIGHT }, () => client(id)));
      await sleep(150 + Math.random() * 250);
      killed = true;
      d.p.kill('SIGKILL');
      loadSeconds += (Date.now() - loadStart) / 1000;
      await Promise.all(clients);
      ackTotal += ok;
      rounds++;
    } finally {
      d.p.kill('SIGKILL');
      await new Promise((r) => (d.p.exitCode !== null || d.p.signalCode !== null ? r() : d.p.on('exit', r)));
    }
  }
} finally {
  rmSync(dir, { recursive: true, force: true });
}
console.log(`    CONVSIMD=${BIN} ROUNDS=${ROUNDS} SESSIONS=${SESSIONS} INFLIGHT=${INFLIGHT} node tests/bench/kill_probe.mjs\n`);
console.log('| kill -9 rounds | sessions | PATCH/s under load (acknowledged / s of load) | controls acknowledged | acknowledged lost | wrong target after restart | GET showing an unlogged target | wall s |');
console.log('|---|---|---|---|---|---|---|---|');
console.log(`| ${rounds} | ${SESSIONS} | ${(ackTotal / loadSeconds).toFixed(0)} | ${ackTotal} | ${lost} | ${wrong} | ${past} | ${((Date.now() - t0) / 1000).toFixed(0)} |`);
