// SPDX-License-Identifier: GPL-3.0-or-later
// What the closed loop itself costs (docs/control.md "What a loop command
// costs"): SECONDS simulated seconds of a `control` experiment (PI kp 2,
// ki 800; setpoints +0.10, -0.08, +0.05 m/s) against a plain `schedule`
// of the same betas (the loop's feedforward), both at pace "max" on the
// czubak2016 preset, on a data directory (the control log is written).
// Per run: wall seconds from the 201 to "done", the session's CPU seconds,
// the daemon's CPU seconds (all threads: the control log's writer too),
// the control log's syncs (metric convsim_control_log_syncs_total) and
// its lines. OLD=path runs another build on the same requests in the same
// run, alternating with this one; medians of REPEAT runs.
//
//   CONVSIMD=build/convsimd [OLD=old/convsimd] [REPEAT=5] [SECONDS=60] node tests/bench/control_cost.mjs
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join, resolve } from 'node:path';
import { startDaemon, req, until, processCpu as cpuSeconds } from '../http/lib.mjs';

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const REPEAT = Number(process.env.REPEAT || 5);
const SECONDS = Number(process.env.SECONDS || 60);

const syncs = async (base) => {
  const m = (await req(base, 'GET', '/metrics')).text.match(/^convsim_control_log_syncs_total (\d+)/m);
  return m ? Number(m[1]) : NaN;
};
const setpoint = [0.10, -0.08, 0.05].map((v, i) => ({ v, until: (SECONDS / 3) * (i + 1) }));

// One experiment of body on daemon d (dir: its data directory): its costs.
async function once(d, dir, body) {
  const s0 = await syncs(d.base), c0 = cpuSeconds(d.proc.pid);
  const r = await req(d.base, 'POST', '/api/v1/experiments', { ...body, session: { pace: 'max' }, keep_session: true });
  if (r.status !== 201) throw new Error(r.text);
  const t0 = process.hrtime.bigint();
  const e = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`);
    return g.body.state !== 'running' && g.body.state !== 'waiting' && g.body;
  }, 600000, r.body.id);
  const wall = Number(process.hrtime.bigint() - t0) / 1e9;
  if (e.state !== 'done') throw new Error(JSON.stringify(e));
  const s = (await req(d.base, 'GET', `/api/v1/sessions/${e.session}`)).body;
  // the log's lines nobody waits for are flushed by the store's writer
  await new Promise((ok) => setTimeout(ok, 300));
  const log = join(dir, 'sessions', e.session, 'controls.ndjson');
  const lines = existsSync(log) ? readFileSync(log, 'utf8').split('\n').filter(Boolean).length : 0;
  const out = { wall, session: s.cpu_seconds, daemon: cpuSeconds(d.proc.pid) - c0, syncs: (await syncs(d.base)) - s0, lines, e };
  await req(d.base, 'DELETE', `/api/v1/sessions/${e.session}`);
  return out;
}

const median = (xs) => [...xs].sort((a, b) => a - b)[Math.floor(xs.length / 2)];
const builds = [['this build', NEW], ...(OLD ? [['old build', OLD]] : [])];
const daemons = [];
for (const [name, bin] of builds) {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-bench-loop-'));
  daemons.push({ name, dir, d: await startDaemon(['--data-dir', dir], { wrap: [resolve(bin)] }), runs: { schedule: [], control: [] } });
}
try {
  // the loop's betas for the schedule: its feedforward (the curve, measured once, is cached)
  const probe = await req(daemons[0].d.base, 'POST', '/api/v1/experiments',
    { control: { setpoint: [{ v: 0.1, until: 0.2 }, ...setpoint.slice(1).map((s, i) => ({ ...s, until: 0.2 * (i + 2) }))] } });
  if (probe.status !== 201) throw new Error(probe.text);
  const schedule = probe.body.segments.map((s, i) => ({ beta: s.beta, until: setpoint[i].until }));
  const bodies = { schedule: { schedule }, control: { control: { setpoint, controller: { kp: 2, ki: 800 } } } };
  for (const x of daemons) await once(x.d, x.dir, bodies.control); // the curve into each daemon's cache
  for (let k = 0; k < REPEAT; k++)
    for (const kind of ['schedule', 'control'])
      for (const x of daemons) x.runs[kind].push(await once(x.d, x.dir, bodies[kind]));
  const cmd = `CONVSIMD=${NEW}${OLD ? ` OLD=${OLD}` : ''} REPEAT=${REPEAT} SECONDS=${SECONDS} node tests/bench/control_cost.mjs`;
  console.log(`${SECONDS} simulated seconds at pace "max" on a data directory, median of ${REPEAT}:\n\n    ${cmd}\n`);
  console.log('| build | experiment | wall (s) | session CPU (s) | daemon CPU (s) | log syncs | log lines | overshoot per setpoint | settling (s) per setpoint |');
  console.log('|---|---|---|---|---|---|---|---|---|');
  for (const kind of ['schedule', 'control'])
    for (const x of daemons) {
      const rs = x.runs[kind], m = (f) => median(rs.map(f));
      const last = rs[rs.length - 1].e;
      const sp = last.control ? last.control.setpoints : null;
      const list = (f) => (sp ? sp.map((s) => (s[f] === null ? '–' : Number(s[f]).toPrecision(3))).join(' / ') : '–');
      console.log(`| ${x.name} | ${kind} | ${m((r) => r.wall).toFixed(2)} | ${m((r) => r.session).toFixed(2)} | ` +
        `${m((r) => r.daemon).toFixed(2)} | ${m((r) => r.syncs)} | ${m((r) => r.lines)} | ${list('overshoot')} | ${list('settling_time')} |`);
    }
} finally {
  for (const x of daemons) {
    await x.d.stop();
    rmSync(x.dir, { recursive: true, force: true });
  }
}
