// SPDX-License-Identifier: GPL-3.0-or-later
// PATCH throughput with a durable control log (docs/hardening.md): SESSIONS
// sessions on a data directory, each with INFLIGHT clients sending PATCH
// {"beta": ...} back to back for WINDOW seconds; acknowledged controls a
// second, answer latency p50 / p99 and the control log's syncs (metric
// convsim_control_log_syncs_total: one a group-commit round). OLD=path runs
// another build (an earlier daemon) on the same load in the same run, for
// comparison. CLIENT=lean (patch_client.mjs, the default), fetch, or
// both (lean,fetch): the client's and the daemon's CPU per PATCH are in
// the table. Loopback and temporary directories only; bounded in time.
//
//   CONVSIMD=build/convsimd [OLD=old/convsimd] [SESSIONS=8] [INFLIGHT=1,4] [WINDOW=5] [CLIENT=lean,fetch] node tests/bench/controls.mjs
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { startDaemon, processCpu } from '../http/lib.mjs'; // its tether: the daemons end with this script
import { client } from './patch_client.mjs';

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const SESSIONS = Number(process.env.SESSIONS || 8);
const INFLIGHT = (process.env.INFLIGHT || '1,4').split(',').map(Number);
const WINDOW = Number(process.env.WINDOW || 5);
const CLIENTS = (process.env.CLIENT || 'lean').split(',');

async function syncs(base) {
  const t = await (await fetch(`${base}/metrics`)).text();
  const m = t.match(/^convsim_control_log_syncs_total (\d+)/m);
  return m ? Number(m[1]) : NaN;
}

// The daemon's CPU seconds so far (Linux /proc; NaN once it has ended).
function cpuSeconds(pid) {
  try {
    return processCpu(pid);
  } catch { return NaN; }
}

async function run(bin, inflight, kind) {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-bench-controls-'));
  const d = await startDaemon(['--data-dir', dir, '--max-sessions', String(SESSIONS + 4)],
    { wrap: [resolve(bin)] });
  try {
    const ids = [];
    for (let i = 0; i < SESSIONS; i++) {
      const r = await fetch(`${d.base}/api/v1/sessions`, { method: 'POST', headers: { 'Content-Type': 'application/json' },
        body: JSON.stringify({ pace: 1, scene: { drive: 'ideal', columns: 1, layers: 2 } }) });
      ids.push((await r.json()).id);
    }
    const s0 = await syncs(d.base);
    const lat = [];
    let ok = 0, bad = 0, n = 0;
    const end = Date.now() + WINDOW * 1000;
    const one = async (id) => {
      const c = client(d.port, kind);
      while (Date.now() < end) {
        const t0 = process.hrtime.bigint();
        const r = await c.request('PATCH', `/api/v1/sessions/${id}`, { beta: 20 + (n++ % 400) / 10 });
        lat.push(Number(process.hrtime.bigint() - t0) / 1e6);
        if (r.status === 200) ok++; else bad++;
      }
      c.close();
    };
    const t0 = Date.now(), cpu0 = cpuSeconds(d.proc.pid), own0 = process.cpuUsage();
    await Promise.all(ids.flatMap((id) => Array.from({ length: inflight }, () => one(id))));
    const secs = (Date.now() - t0) / 1000;
    const cpu = cpuSeconds(d.proc.pid) - cpu0, own = process.cpuUsage(own0);
    const s1 = await syncs(d.base);
    lat.sort((a, b) => a - b);
    const q = (p) => lat[Math.min(lat.length - 1, Math.floor(p * lat.length))];
    return { ok, bad, rate: ok / secs, p50: q(0.5), p99: q(0.99), syncs: s1 - s0,
      daemonUs: cpu / ok * 1e6, clientUs: (own.user + own.system) / ok };
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
}

const builds = [['this build', NEW], ...(OLD ? [['old build', OLD]] : [])];
const cmd = `CONVSIMD=${NEW}${OLD ? ` OLD=${OLD}` : ''} SESSIONS=${SESSIONS} INFLIGHT=${INFLIGHT.join(',')} WINDOW=${WINDOW} CLIENT=${CLIENTS.join(',')} node tests/bench/controls.mjs`;
console.log(`PATCH throughput, ${SESSIONS} sessions on a data directory, ${WINDOW} s a row\n\n    ${cmd}\n`);
console.log('| build | client | clients per session | acknowledged PATCH/s | p50 ms | p99 ms | refused | log syncs | controls per sync | daemon CPU us / PATCH | client CPU us / PATCH |');
console.log('|---|---|---|---|---|---|---|---|---|---|---|');
for (const inflight of INFLIGHT) {
  for (const kind of CLIENTS) {
    for (const [name, bin] of builds) {
      const r = await run(bin, inflight, kind);
      const per = Number.isFinite(r.syncs) && r.syncs > 0 ? (r.ok / r.syncs).toFixed(1) : 'n/a';
      console.log(`| ${name} | ${kind} | ${inflight} | ${r.rate.toFixed(0)} | ${r.p50.toFixed(1)} | ${r.p99.toFixed(1)} | ${r.bad} | ${Number.isFinite(r.syncs) ? r.syncs : 'n/a (no log sync)'} | ${per} | ${r.daemonUs.toFixed(0)} | ${r.clientUs.toFixed(0)} |`);
    }
  }
}
