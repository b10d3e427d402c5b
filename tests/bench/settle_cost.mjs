// SPDX-License-Identifier: GPL-3.0-or-later
// What a steady start's settling costs beside its estimate
// (docs/load.md "What settling costs"): scenes from 1 x 2 to 64 x 64
// are created one at a time (pace 0.01, --cpu-probe 0) and deleted; the
// daemon's debug line gives the CPU its request thread spent building and
// settling the instance and the settling's estimate. Each scene REPEAT times, the least CPU kept (a
// loaded machine only adds). OLD=path: the estimate of an earlier build
// for the same scenes, from its refusal at --max-paced-cores 0.0001 (CPU
// per simulated s at pace 1, less the samples', times scene.settle: what
// its settling check used). Loopback only.
//
//   [CONVSIMD=build/convsimd] [OLD=path] [REPEAT=3] node tests/bench/settle_cost.mjs
import { resolve } from 'node:path';
import { startDaemon, req, until } from '../http/lib.mjs';

const NEW = process.env.CONVSIMD || 'build/convsimd';
const OLD = process.env.OLD || '';
const REPEAT = Number(process.env.REPEAT || 3);
// samples a simulated s: a sample of the scenes without the symmetric
// reduction is estimated at more than the second of CPU a creation may ask
// for at one a second (the settling publishes none)
const RATE = 100;
const SETTLE = 0.6; // scene.settle of czubak2016
const MACHINE = 166; // kg: M_r + m + m1 + m2 of czubak2016
const M_N = 0.5;
const SCENES = [
  ['1 x 2', { columns: 1, layers: 2 }],
  ['5 x 8 (default)', {}],
  ['8 x 8', { columns: 8, layers: 8 }],
  ['1 x 64', { columns: 1, layers: 64 }],
  ['8 x 64', { columns: 8, layers: 64 }],
  ['16 x 32', { columns: 16, layers: 32 }],
  ['9 x 64', { columns: 9, layers: 64 }],
  ['64 x 16', { columns: 64, layers: 16 }],
  ['32 x 32', { columns: 32, layers: 32 }],
  ['16 x 64', { columns: 16, layers: 64 }],
  ['32 x 64', { columns: 32, layers: 64 }],
  ['64 x 64', { columns: 64, layers: 64 }],
  ['64 x 64, trough_rotation', { columns: 64, layers: 64, trough_rotation: true }],
  // an adaptive method: estimated at dem's steps (docs/budgets.md)
  ['5 x 8, dopri5', {}, { method: 'dopri5' }],
];
const LINE = /session ([0-9a-f]+): built and settled in ([0-9.e+-]+) CPU s, settling estimated at ([0-9.e+-]+)/g;

async function measure(scene, integrator) {
  const d = await startDaemon(['--log-level', 'debug', '--cpu-probe', '0', '--max-paced-cores', '100',
    '--ring', '16', '--history', '16'], { wrap: [resolve(NEW)] });
  try {
    let least = Infinity, estimate = NaN, status = null;
    for (let i = 0; i < REPEAT; i++) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', { scene, integrator, pace: 0.01, sample_rate: RATE });
      if (r.status !== 201) throw new Error(`${JSON.stringify(scene)}: ${r.status} ${r.text}`);
      status = r.body.status;
      const line = await until(() => [...d.stderr().matchAll(LINE)].find((m) => m[1] === r.body.id), 10000, 'its line');
      least = Math.min(least, Number(line[2]));
      estimate = Number(line[3]);
      await req(d.base, 'DELETE', `/api/v1/sessions/${r.body.id}`);
    }
    return { least, estimate, dt: status.dt, substeps: status.substeps };
  } finally {
    await d.stop();
  }
}

async function before(scene, integrator) {
  const d = await startDaemon(['--cpu-probe', '0', '--max-paced-cores', '0.0001'], { wrap: [resolve(OLD)] });
  try {
    const r = await req(d.base, 'POST', '/api/v1/sessions', { scene, integrator, pace: 1, sample_rate: RATE });
    const m = r.body && r.body.detail && r.body.detail.match(/\(([0-9.e+-]+) ms of CPU per simulated s at pace 1\)/);
    // less the samples' term (5 us a sample), which the settling publishes none of
    return m ? (Number(m[1]) / 1e3 - 5e-6 * RATE) * SETTLE : NaN;
  } finally {
    await d.stop();
  }
}

const f3 = (x) => (Number.isFinite(x) ? String(Number(x.toPrecision(3))) : 'n/a');
const f2 = (x) => (Number.isFinite(x) ? x.toFixed(2) : 'n/a');
console.log('# The settling of a steady start beside its estimate\n');
console.log(`Command: \`${OLD ? 'OLD=path/to/previous/convsimd ' : ''}REPEAT=${REPEAT} node tests/bench/settle_cost.mjs\` ` +
  '(`bash tests/bench/settle_cost.sh`): each scene created at pace 0.01, `--cpu-probe 0`, ' +
  'and deleted; settled: the CPU s the creating request\'s thread spent in `sim_new` ' +
  `(instance, equilibrium, steady start, ${SETTLE} s of settling), the least of ${REPEAT}; estimate: ` +
  'the settling\'s, as the creation is admitted by.\n');
console.log('| scene | feed / machine mass | step s, sub-steps | settled CPU s | estimate CPU s | settled / estimate | estimate before | settled / before |');
console.log('|---|---|---|---|---|---|---|---|');
for (const [name, scene, integrator] of SCENES) {
  const m = await measure(scene, integrator);
  const old = OLD ? await before(scene, integrator) : NaN;
  const ratio = M_N * (scene.columns ?? 5) * (scene.layers ?? 8) / MACHINE;
  console.log(`| ${name} | ${ratio.toFixed(2)} | ${m.dt}, ${m.substeps} | ${f3(m.least)} | ${f3(m.estimate)} | ` +
    `${f2(m.least / m.estimate)} | ${f3(old)} | ${f2(m.least / old)} |`);
}
