// SPDX-License-Identifier: GPL-3.0-or-later
// How long a creation takes to be answered on a data directory
// (docs/durability.md "A 201 on a creation means its record is on
// disk"): COUNT creations of each kind one after another, GAP ms apart
// (each deleted before the next where the API allows; at most 12 fits),
// latency p50 / p99 / max, on an idle daemon and beside BUSY paced
// sessions checkpointing every 0.2 s (the store's writer busy). OLD=path
// runs an earlier build on the same load in the same run. Loopback and
// temporary directories only.
//
//   CONVSIMD=build/convsimd [OLD=old/convsimd] [COUNT=30] [BUSY=8] [GAP=100] node tests/bench/create_latency.mjs
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { startDaemon } from '../http/lib.mjs'; // its tether: the daemons end with this script
import { client } from './patch_client.mjs';

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const COUNT = Number(process.env.COUNT || 30);
const BUSY = Number(process.env.BUSY || 8);
const GAP = Number(process.env.GAP ?? 100);
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
const NO_FEED = { scene: { drive: 'ideal', feed: false } };
const KINDS = [
  ['sessions', { pace: 1, scene: { drive: 'ideal', columns: 1, layers: 2 } }, true],
  ['experiments', { session: { ...NO_FEED, pace: 'max' }, schedule: [{ beta: 50, until: 0.05 }] }, false],
  ['sweeps', { ...NO_FEED, beta: [20], rotations: ['cw'], t_end: 0.05 }, true],
  ['fits', { ...NO_FEED, t_end: 0.1, free: ['e'], curve_step: 90,
    points: [{ beta: 20, rotation: 'cw', v: 0.07 }, { beta: 60, rotation: 'cw', v: 0.06 }] }, true],
];

async function run(bin, busy, dataDir) {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-bench-create-'));
  const args = ['--max-sessions', String(busy + 2 * COUNT + 8),
    '--checkpoint-interval', '0.2', ...(dataDir ? ['--data-dir', dir] : [])];
  const d = await startDaemon(args, { wrap: [resolve(bin)] });
  const c = client(d.port, 'lean');
  const rows = {};
  try {
    for (let i = 0; i < busy; i++) await c.request('POST', '/api/v1/sessions', KINDS[0][1]);
    for (const [kind, body, deletable] of KINDS) {
      const lat = [];
      // a deleted fit's slot comes back once its driver stops: 12 of the 16
      for (let i = 0; i < (kind === 'fits' ? Math.min(COUNT, 12) : COUNT); i++) {
        const t0 = process.hrtime.bigint();
        const r = await c.request('POST', `/api/v1/${kind}`, body);
        lat.push(Number(process.hrtime.bigint() - t0) / 1e6);
        if (r.status !== 201 && r.status !== 202) throw new Error(`${kind}: ${r.status} ${r.body}`);
        if (deletable) await fetch(`${d.base}/api/v1/${kind}/${JSON.parse(r.body).id}`, { method: 'DELETE' });
        await sleep(GAP); // the files of the one before written meanwhile (GAP=0: back to back)
      }
      lat.sort((a, b) => a - b);
      const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))];
      rows[kind] = { p50: q(0.5), p99: q(0.99), max: lat[lat.length - 1] };
    }
  } finally {
    c.close();
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
  return rows;
}

const builds = [['this build', NEW], ...(OLD ? [['before', OLD]] : [])];
const cmd = `CONVSIMD=${NEW}${OLD ? ` OLD=${OLD}` : ''} COUNT=${COUNT} BUSY=${BUSY} GAP=${GAP} node tests/bench/create_latency.mjs`;
console.log(`Creation latency, ${COUNT} of each kind one after another, ${GAP} ms apart\n\n    ${cmd}\n`);
console.log('| build | data directory | paced sessions beside | kind | p50 ms | p99 ms | max ms |');
console.log('|---|---|---|---|---|---|---|');
for (const busy of BUSY ? [0, BUSY] : [0]) {
  for (const dataDir of [true, false]) {
    for (const [name, bin] of builds) {
      if (!dataDir && name !== 'this build') continue; // nothing to wait for without one
      const rows = await run(bin, busy, dataDir);
      for (const [kind, r] of Object.entries(rows)) {
        console.log(`| ${name} | ${dataDir ? 'yes' : 'no'} | ${busy} | ${kind} | ${r.p50.toFixed(1)} | ${r.p99.toFixed(1)} | ${r.max.toFixed(1)} |`);
      }
    }
  }
}
