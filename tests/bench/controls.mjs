// SPDX-License-Identifier: GPL-3.0-or-later
// PATCH throughput with a durable control log (docs/hardening.md): SESSIONS
// sessions on a data directory, each with INFLIGHT clients sending PATCH
// {"beta": ...} back to back for WINDOW seconds; acknowledged controls a
// second, answer latency p50 / p99 and the control log's syncs (metric
// convsim_control_log_syncs_total: one a group-commit round). OLD=path runs
// another build (an earlier daemon) on the same load in the same run, for
// comparison. Loopback and temporary directories only; bounded in time.
//
//   CONVSIMD=build/convsimd [OLD=old/convsimd] [SESSIONS=8] [INFLIGHT=1,4] [WINDOW=5] node tests/bench/controls.mjs
import { spawn } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import '../tether.mjs'; // the daemons end with this script, however it ends

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const SESSIONS = Number(process.env.SESSIONS || 8);
const INFLIGHT = (process.env.INFLIGHT || '1,4').split(',').map(Number);
const WINDOW = Number(process.env.WINDOW || 5);

async function start(bin, dir) {
  const p = spawn(bin, ['--port', '0', '--log-level', 'warn', '--data-dir', dir,
    '--max-sessions', String(SESSIONS + 4)], { stdio: ['ignore', 'pipe', 'pipe'] });
  const port = await new Promise((resolve, reject) => {
    let out = '';
    const t = setTimeout(() => reject(new Error('no port')), 10000);
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

async function syncs(base) {
  const t = await (await fetch(base.replace('/api/v1', '/metrics'))).text();
  const m = t.match(/^convsim_control_log_syncs_total (\d+)/m);
  return m ? Number(m[1]) : NaN;
}

async function run(bin, inflight) {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-bench-controls-'));
  const d = await start(bin, dir);
  try {
    const ids = [];
    for (let i = 0; i < SESSIONS; i++) {
      const r = await fetch(`${d.base}/sessions`, json('POST', { pace: 1, scene: { drive: 'ideal', columns: 1, layers: 2 } }));
      ids.push((await r.json()).id);
    }
    const s0 = await syncs(d.base);
    const lat = [];
    let ok = 0, bad = 0, n = 0;
    const end = Date.now() + WINDOW * 1000;
    const client = async (id) => {
      while (Date.now() < end) {
        const t0 = process.hrtime.bigint();
        const r = await fetch(`${d.base}/sessions/${id}`, json('PATCH', { beta: 20 + (n++ % 400) / 10 }));
        await r.arrayBuffer();
        lat.push(Number(process.hrtime.bigint() - t0) / 1e6);
        if (r.status === 200) ok++; else bad++;
      }
    };
    const t0 = Date.now();
    await Promise.all(ids.flatMap((id) => Array.from({ length: inflight }, () => client(id))));
    const secs = (Date.now() - t0) / 1000;
    const s1 = await syncs(d.base);
    lat.sort((a, b) => a - b);
    const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))];
    return { ok, bad, rate: ok / secs, p50: q(0.5), p99: q(0.99), syncs: s1 - s0 };
  } finally {
    d.p.kill('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
}

const builds = [['this build', NEW], ...(OLD ? [['old build', OLD]] : [])];
const cmd = `CONVSIMD=${NEW}${OLD ? ` OLD=${OLD}` : ''} SESSIONS=${SESSIONS} INFLIGHT=${INFLIGHT.join(',')} WINDOW=${WINDOW} node tests/bench/controls.mjs`;
console.log(`PATCH throughput, ${SESSIONS} sessions on a data directory, ${WINDOW} s a row\n\n    ${cmd}\n`);
console.log('| build | clients per session | acknowledged PATCH/s | p50 ms | p99 ms | refused | log syncs | controls per sync |');
console.log('|---|---|---|---|---|---|---|---|');
for (const inflight of INFLIGHT) {
  for (const [name, bin] of builds) {
    const r = await run(bin, inflight);
    const per = Number.isFinite(r.syncs) && r.syncs > 0 ? (r.ok / r.syncs).toFixed(1) : 'n/a';
    console.log(`| ${name} | ${inflight} | ${r.rate.toFixed(0)} | ${r.p50.toFixed(1)} | ${r.p99.toFixed(1)} | ${r.bad} | ${Number.isFinite(r.syncs) ? r.syncs : 'n/a (no log sync)'} | ${per} |`);
  }
}
