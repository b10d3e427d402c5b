// SPDX-License-Identifier: GPL-3.0-or-later
// convsim run --set feed_model=auto (docs/feed-models.md "feed_model=auto"):
// the cheapest feed model whose model error is within model_tol, said on
// stderr before the run and in the summary (feed_model_pick):
//  - at a checked point of the DEM map within model_tol: the column model;
//  - not checked (or over model_tol): a LIGGGHTS bed (convsim-mpi, a
//    one-layer bed of 92 grains for 0.1 s), its expected CPU cost stated
//    before it starts: dem_bed_spec_cost's estimate, computed here;
//  - over --max-dem-cost, without LIGGGHTS (the NO_MPI build), or without
//    model_tol: refused, exit 2, with why.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync } from 'node:fs';
import '../tether.mjs'; // nothing started here outlives the test

const ROOT = new URL('../..', import.meta.url).pathname;
const BUILD = process.env.BUILD || 'build';
const CONVSIM = process.env.CONVSIM || `${ROOT}${BUILD}/convsim`;
const NOMPI = process.env.CONVSIM_NOMPI || `${ROOT}${BUILD}/nompi/convsim`;
// (leak detection off under ASan: the MPI stack's own leaks at exit, as in tests/dem/)
const env = { ...process.env, ASAN_OPTIONS: [process.env.ASAN_OPTIONS, 'detect_leaks=0'].filter(Boolean).join(':') };
const run = (args, bin = CONVSIM) => {
  const r = spawnSync(bin, ['run', '-q', ...args], { encoding: 'utf8', timeout: 300000, env });
  return { code: r.status, out: r.stdout, err: r.stderr };
};
const set = (...s) => s.flatMap((x) => ['--set', x]);

test('auto: at a checked point within model_tol the column model, and why', () => {
  const r = run(['-d', '0.2', '-p', 'liggghts-bed4', ...set('beta=137', 'feed_model=auto', 'model_tol=0.003')]);
  assert.equal(r.code, 0, r.err);
  const why = 'column: DEM check within ±0.001 m/s here, uncertain by ±0.001 m/s, within model_tol 0.003 m/s';
  assert.equal(r.err, `convsim run: feed_model auto: ${why}\n`);
  const s = JSON.parse(r.out);
  assert.deepEqual(s.feed_model_pick, { model: 'column', why, expected_cpu_s_per_s: null });
  assert.equal(s.model_checked, true);
  assert.ok(s.model_error + s.model_error_uncertainty <= 0.003);
  // the same scene asked for column: the same run to the last bit
  const c = JSON.parse(run(['-d', '0.2', '-p', 'liggghts-bed4', ...set('beta=137', 'feed_model=column')]).out);
  assert.equal(s.transport_velocity, c.transport_velocity);
  assert.equal(c.feed_model_pick, undefined);
});

// dem_bed_spec_default's bed (dem/dem.h): spheres 3.6-4.4 mm at 2500
// kg/m^3, a step of pi / sqrt(k / m_min) / 50 with k = k_c/m_n times the
// mean grain's mass, 3.2e-7 CPU s a grain's step
function bedCost(grains, kOverM) {
  const dMin = 0.0036, dMax = 0.0044, rho = 2500;
  const mMean = rho * Math.PI / 6 * (dMax ** 4 - dMin ** 4) / (4 * (dMax - dMin));
  const mMin = rho * Math.PI / 6 * dMin ** 3;
  const dt = Math.PI / Math.sqrt(kOverM * mMean / mMin) / 50;
  return 3.2e-7 * grains / dt;
}

const UNCHECKED = ['-d', '0.1', ...set('layers=1', 'k_c=10000', 'm_n=0.005', 'feed_model=auto', 'model_tol=0.01')];
const NOTE = 'not checked against DEM with this contact (m_n differs): nearest checked is 1 layers, czubak2016 against glass';

test('auto: not checked, a LIGGGHTS bed, its expected cost on stderr before it runs', { skip: !existsSync(`${ROOT}${BUILD}/convsim-dem`) && 'built without LIGGGHTS' }, () => {
  const r = run(UNCHECKED);
  assert.equal(r.code, 0, r.err);
  const s = JSON.parse(r.out);
  assert.equal(s.feed_model, 'liggghts');
  assert.equal(s.grains, 92);
  const cost = bedCost(92, 10000 / 0.005);
  assert.ok(Math.abs(s.feed_model_pick.expected_cpu_s_per_s - cost) < 1e-9 * cost,
    `${s.feed_model_pick.expected_cpu_s_per_s} against ${cost}`);
  const why = `liggghts: the column model is not within model_tol 0.01 m/s here (${NOTE}); a LIGGGHTS bed is ` +
    'the DEM itself, expected to cost about 0.78 CPU s a simulated second';
  assert.equal(s.feed_model_pick.model, 'liggghts');
  assert.equal(s.feed_model_pick.why, why);
  // the first thing on stderr, so before the bed was built
  assert.equal(r.err.split('\n')[0],
    `convsim run: feed_model auto: ${why}; for the 0.1 s asked about 0.078 CPU s (and the bed's settling)`);
});

test('auto: a LIGGGHTS bed over --max-dem-cost is refused, exit 2, nothing run', { skip: !existsSync(`${ROOT}${BUILD}/convsim-dem`) && 'built without LIGGGHTS' }, () => {
  const r = run([...UNCHECKED, '--max-dem-cost', '0.5']);
  assert.equal(r.code, 2);
  assert.equal(r.out, '');
  assert.equal(r.err, 'convsim run: --set feed_model=auto: no feed model within model_tol 0.01 m/s here: ' +
    `the column model: ${NOTE}; a LIGGGHTS bed would cost about 0.78 CPU s a simulated second, over --max-dem-cost 0.5\n`);
});

test('auto: without LIGGGHTS (the NO_MPI build) and not checked: refused, exit 2', () => {
  if (!process.env.CONVSIM_NOMPI || !existsSync(NOMPI)) {
    const b = spawnSync('make', ['-j2', 'NO_MPI=1', `BUILD=${BUILD}/nompi`, `${BUILD}/nompi/convsim`],
      { cwd: ROOT, encoding: 'utf8', timeout: 600000 });
    assert.equal(b.status, 0, b.stderr);
  }
  const r = run(UNCHECKED, NOMPI);
  assert.equal(r.code, 2);
  assert.equal(r.out, '');
  assert.equal(r.err, 'convsim run: --set feed_model=auto: no feed model within model_tol 0.01 m/s here: ' +
    `the column model: ${NOTE}; a LIGGGHTS bed cannot run: this convsim was built without LIGGGHTS ` +
    '(`make deps`, then `make`)\n');
  // and at a checked point within model_tol it runs the column model
  const c = run(['-d', '0.1', '-p', 'liggghts-bed4', ...set('beta=137', 'feed_model=auto', 'model_tol=0.003')], NOMPI);
  assert.equal(c.code, 0, c.err);
  assert.equal(JSON.parse(c.out).feed_model_pick.model, 'column');
});

test('auto: without model_tol, refused; feed_model auto elsewhere than run is refused by the core', () => {
  const r = run(['-d', '0.1', ...set('feed_model=auto')]);
  assert.equal(r.code, 2);
  assert.equal(r.err, 'convsim run: --set feed_model=auto: feed_model auto needs model_tol > 0 m/s: ' +
    'the largest model error the feed model may have\n');
  const b = run(['-d', '0.1', ...set('feed_model=auto', 'model_tol=2')]);
  assert.equal(b.code, 2);
  assert.match(b.err, /model_tol must be a finite number in \[0, 1\] m\/s/);
  const sw = spawnSync(CONVSIM, ['sweep', '--beta', '30', '--rotation', 'cw', '-d', '0.1',
    ...set('feed_model=auto', 'model_tol=0.01')], { encoding: 'utf8', env });
  assert.equal(sw.status, 1);
  assert.match(sw.stderr, /beta=30 deg, cw: feed_model auto picks the model of one run \(convsim run, a session\): give column here\n$/);
});
