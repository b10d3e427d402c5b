// SPDX-License-Identifier: GPL-3.0-or-later
// Experiments (a beta schedule with per-segment steady velocity and
// reversal time) and sweeps (v(beta) for both rotations on the pool).
// Where a job runs the czubak2016 defaults at a clockwise peak, its
// velocity is checked against the converged reference (sessions.test.mjs).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { execFileSync } from 'node:child_process';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, near, metric, processCpu, sleep, CHEAP, NO_FEED, SLOW, CLI } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const scene = { ...CHEAP.scene, transient: 0.5 };
const metrics = async (base) => (await req(base, 'GET', '/metrics')).text;

test('experiment on a fresh session: 38 -> 128 deg reverses the feed', { timeout: 60000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/experiments', {
    session: { scene },
    schedule: [{ beta: 38, until: 3 }, { beta: 128, until: 6 }],
    beta_rate: 180,
  });
  assert.equal(r.status, 201, r.text);
  assert.equal(r.headers.get('location'), `/api/v1/experiments/${r.body.id}`);
  assert.equal(r.body.segments.length, 2);
  const done = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`);
    return g.body.state === 'done' && g.body;
  }, 40000, 'the experiment');
  assert.equal(done.progress, 1);
  const [a, b] = done.segments;
  assert.equal(a.t_command, 0);
  // the integrator's time (a sum of whole steps): 3 s up to round-off
  near(b.t_command, 3, 1e-9, 'second command');
  assert.equal(b.t_end, 6);
  assert.ok(a.steady_velocity > 0.05, `38 deg: ${a.steady_velocity}`);
  assert.ok(b.steady_velocity < -0.05, `128 deg: ${b.steady_velocity}`);
  // the reversal is quick: the ramp at 180 deg/s takes 0.5 s
  assert.ok(b.reversal_time > 0.1 && b.reversal_time < 2.5, `reversal ${b.reversal_time}`);
  for (const seg of done.segments) {
    assert.equal(typeof seg.uncertainty, 'number');
    assert.equal(typeof seg.steady, 'boolean');
  }
  // the mean over the second segment spans the reversal, far from its
  // steady value: its error bar says so
  assert.ok(b.uncertainty > 0.01, `uncertainty over the reversal ${b.uncertainty}`);
  assert.ok(a.uncertainty < 0.005, `uncertainty without a reversal ${a.uncertainty}`);
  const s = await req(d.base, 'GET', `/api/v1/sessions/${done.session}`);
  assert.equal(s.body.state, 'finished');
  assert.equal(s.body.experiment, null);
  const list = await req(d.base, 'GET', '/api/v1/experiments');
  assert.ok(list.body.experiments.some((e) => e.id === r.body.id));
  // the session it created goes within a second of the end (no keep_session)
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${done.session}`)).status === 404,
    3000, 'the experiment\'s session to be removed');
});

test('experiment: a segment too short to settle has no reversal time; the next one starts where it ended', { timeout: 60000 * SLOW }, async () => {
  // 0.052 s is not on the default step grid (a command acts at a step's end)
  const r = await req(d.base, 'POST', '/api/v1/experiments',
    { schedule: [{ beta: 30, until: 0.052 }, { beta: 150, until: 0.104 }] });
  assert.equal(r.status, 201, r.text);
  const done = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`);
    return g.body.state === 'done' && g.body;
  }, 40000, 'the experiment');
  const [a, b] = done.segments;
  // the feed reaches 90 % of its 'steady' value only inside the half that
  // value is averaged over: nothing to time (was 0.052, the whole segment)
  assert.equal(a.reversal_time, null);
  assert.equal(b.reversal_time, null);
  // one time for the boundary: the command's, on the step grid
  assert.ok(b.t_command >= 0.052 && b.t_command < 0.06, `second command ${b.t_command}`);
  assert.equal(a.t_end, b.t_command);
  const csv = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}?format=csv`);
  const rows = csv.text.trim().split('\n').map((l) => l.split(','));
  const col = (name) => rows[0].indexOf(name);
  assert.equal(rows[1][col('t_end')], rows[2][col('t_command')]);
  assert.equal(rows[1][col('reversal_time')], '');
  // the preset's 8-layer bed is in the DEM map: each segment's error at its angle, checked
  for (const [k, s] of [a, b].entries())
    assert.deepEqual(rows[k + 1].slice(col('model_error')), [String(s.model_error), String(s.model_error_uncertainty), 'true']);
  assert.ok(a.model_error > 0 && b.model_error > 0 && a.model_checked && b.model_checked);
});

test('experiment on an existing session; a second one is 409', { timeout: 60000 * SLOW }, async () => {
  const c = await req(d.base, 'POST', '/api/v1/sessions', { scene, pace: 'max', until: 1 });
  const id = c.body.id;
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.state === 'finished', 20000, 'finish');
  const r = await req(d.base, 'POST', '/api/v1/experiments',
    { session: id, schedule: [{ beta: 128, until: 2 }, { beta: 38, until: 4 }] });
  assert.equal(r.status, 201, r.text);
  assert.equal(r.body.session, id);
  const again = await req(d.base, 'POST', '/api/v1/experiments', { session: id, schedule: [{ beta: 90, until: 1 }] });
  if (again.status !== 201) assert.equal(again.status, 409);
  const done = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`);
    return g.body.state === 'done' && g.body;
  }, 40000, 'the experiment');
  assert.equal(done.t_start, 1);
  near(done.segments[0].t_command, 1, 1e-9, 'first command'); // integrator time, as above
  assert.equal(done.segments[1].t_end, 5);
  assert.ok(done.segments[0].steady_velocity < 0);
  assert.ok(done.segments[1].steady_velocity > 0);
  const nf = await req(d.base, 'POST', '/api/v1/experiments', { session: 'ffffffffffffffff', schedule: [{ beta: 90, until: 1 }] });
  assert.equal(nf.status, 404);
  assert.equal(nf.body.field, 'session');
  const bad = await req(d.base, 'POST', '/api/v1/experiments', { schedule: [{ beta: 90, until: 2 }, { beta: 30, until: 1 }] });
  assert.equal(bad.status, 422);
  assert.equal(bad.body.field, 'schedule[1].until');
  await req(d.base, 'DELETE', `/api/v1/sessions/${id}`);
});

test('sweep v(beta) for cw and ccw, JSON and CSV', { timeout: 60000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sweeps',
    { scene: { ...CHEAP.scene, transient: 1 }, beta: { from: 38, to: 128, step: 90 }, rotations: ['cw', 'ccw'], t_end: 2.5 });
  assert.equal(r.status, 202, r.text);
  assert.equal(r.body.total, 4);
  const done = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}`);
    return g.body.state === 'done' && g.body;
  }, 50000, 'the sweep');
  assert.equal(done.done, 4);
  const v = (beta, rot) => done.points.find((p) => p.beta === beta && p.rotation === rot).velocity;
  assert.ok(v(38, 'cw') > 0.05, `cw 38: ${v(38, 'cw')}`);
  assert.ok(v(128, 'cw') < -0.05, `cw 128: ${v(128, 'cw')}`);
  assert.equal(done.series.cw.length, 2);
  for (const p of done.points) {
    assert.ok(Number.isFinite(p.uncertainty) && p.uncertainty > 0, `uncertainty ${p.uncertainty}`);
    assert.equal(typeof p.steady, 'boolean');
  }
  const csv = await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}?format=csv`);
  assert.equal(csv.headers.get('content-type'), 'text/csv');
  const lines = csv.text.trim().split('\n');
  assert.equal(lines[0], 'beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
  assert.equal(lines.length, 5);
  const first = lines[1].split(',');
  const p0 = done.points[0];
  assert.deepEqual(first, [String(p0.beta), p0.rotation, String(p0.velocity), String(p0.uncertainty),
    String(p0.steady), 'done', String(p0.dt), String(p0.substeps), String(p0.step_error), String(p0.tol_met),
    // the preset's 2-layer bed is in the DEM map: its model error, checked
    String(p0.model_error), String(p0.model_error_uncertainty), 'true']);
  assert.equal(p0.model_checked, true);
  assert.ok(p0.model_error > 0);
  for (const p of done.points) {
    assert.ok(p.dt > 0 && p.dt <= 1.25e-3, `dt ${p.dt}`);
    assert.ok(Number.isInteger(p.substeps) && p.substeps >= 5, `substeps ${p.substeps}`);
    assert.ok(p.step_error > 0 && p.step_error <= p.uncertainty, `step_error ${p.step_error}`);
    assert.equal(typeof p.tol_met, 'boolean');
  }
  const bad = await req(d.base, 'POST', '/api/v1/sweeps', { rotations: ['up'] });
  assert.equal(bad.status, 422);
  const bad2 = await req(d.base, 'POST', '/api/v1/sweeps', { beta: [10, 'x'] });
  assert.equal(bad2.status, 400);
  assert.equal(bad2.body.field, 'beta[1]');
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sweeps/${r.body.id}`)).status, 204);
  assert.equal((await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}`)).status, 404);
});

test('the mirror reduction: a sweep over both senses of the symmetric machine runs (cw, beta) and takes (ccw, 180 - beta) as its mirror image; mirror=false and an asymmetric machine run every point', { timeout: 90000 * SLOW }, async () => {
  const grid = { beta: [40, 90, 140], rotations: ['cw', 'ccw'], t_end: 1.5 };
  const sweep = async (scene, params) => {
    const r = await req(d.base, 'POST', '/api/v1/sweeps', { scene: { ...CHEAP.scene, transient: 0.5, ...scene }, params, ...grid });
    assert.equal(r.status, 202, r.text);
    const done = await until(async () => {
      const g = await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}`);
      return g.body.state === 'done' && g.body;
    }, 60000, 'the sweep');
    await req(d.base, 'DELETE', `/api/v1/sweeps/${r.body.id}`);
    return done;
  };
  const before = metric(await metrics(d.base), 'convsim_sweep_points_total');
  const mirrored = await sweep({});
  assert.equal(metric(await metrics(d.base), 'convsim_sweep_points_total') - before, 3, 'three points ran');
  assert.deepEqual(mirrored.reductions, ['mirror']);
  assert.equal(mirrored.done, 6);
  const at = (s, beta, rot) => s.points.find((p) => p.beta === beta && p.rotation === rot);
  for (const p of mirrored.points) {
    assert.equal(p.state, 'done', p.error);
    assert.equal(p.mirrored, p.rotation === 'ccw', `${p.beta} ${p.rotation}`);
    if (p.rotation === 'cw')
      continue;
    const image = at(mirrored, 180 - p.beta, 'cw');
    assert.equal(p.velocity, -image.velocity);
    assert.equal(p.uncertainty, image.uncertainty);
    assert.equal(p.steady, image.steady);
  }
  const direct = await sweep({ mirror: false });
  assert.deepEqual(direct.reductions, []);
  for (const p of direct.points) {
    assert.equal(p.mirrored, false);
    // the symmetry holds to round-off that the feed amplifies (~2e-6 m/s here)
    near(p.velocity, at(mirrored, p.beta, p.rotation).velocity, 2e-5, `${p.beta} ${p.rotation}: direct against mirrored`);
  }
  const asymmetric = await sweep({}, { l2: 0.9 });
  assert.deepEqual(asymmetric.reductions, []);
  assert.ok(asymmetric.points.every((p) => !p.mirrored && p.state === 'done'));
});

test('sweep of the defaults at the clockwise peaks: t_end = transient + 4 s, v within 1 % and its error bar', { timeout: 60000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sweeps', { beta: [30, 135], rotations: ['cw'] });
  assert.equal(r.status, 202, r.text);
  assert.equal(r.body.t_end, 4); // the preset's transient is 0
  const done = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}`);
    return g.body.state === 'done' && g.body;
  }, 50000, 'the sweep');
  for (const [beta, vRef] of [[30, 0.152557], [135, -0.147252]]) {
    const p = done.points.find((q) => q.beta === beta);
    assert.equal(p.state, 'done', p.error);
    near(p.velocity, vRef, 0.01 * Math.abs(vRef), `sweep at ${beta} deg against 1 % of v_ref`);
    near(p.velocity, vRef, p.uncertainty, `sweep at ${beta} deg against its error bar`);
    assert.equal(p.steady, true);
  }
  // a transient moves the default window with it
  const later = await req(d.base, 'POST', '/api/v1/sweeps', { scene: { transient: 1.5 }, beta: [90], rotations: ['cw'] });
  assert.equal(later.status, 202, later.text);
  assert.equal(later.body.t_end, 5.5);
  await req(d.base, 'DELETE', `/api/v1/sweeps/${later.body.id}`);
  await req(d.base, 'DELETE', `/api/v1/sweeps/${r.body.id}`);
});

test('a sweep whose t_end does not pass the transient is refused whole', { timeout: 20000 * SLOW }, async () => {
  const before = (await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length;
  for (const [body, transient] of [[{ t_end: 0 }, 0], [{ scene: { transient: 2 }, t_end: 2 }, 2],
    [{ scene: { transient: 2 }, t_end: 1, beta: [30] }, 2]]) {
    const r = await req(d.base, 'POST', '/api/v1/sweeps', body);
    assert.equal(r.status, 422, r.text);
    assert.match(r.headers.get('content-type'), /^application\/problem\+json/);
    assert.deepEqual(r.body, {
      type: '/api/v1/problems/out-of-range',
      title: 'Value out of range',
      status: 422,
      detail: `t_end must exceed scene.transient = ${transient} s (the transport velocity is measured after it) and be at most 600 s`,
      instance: '/api/v1/sweeps',
      field: 't_end',
      min: transient,
      max: 600,
    });
  }
  const wrong = await req(d.base, 'POST', '/api/v1/sweeps', { t_end: '5' });
  assert.equal(wrong.status, 400);
  assert.equal(wrong.body.field, 't_end');
  assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length, before, 'nothing was started');
});

test('experiment at a clockwise peak: the segment\'s mean velocity, its error bar and steady flag', { timeout: 60000 * SLOW }, async () => {
  // the session starts at 30 deg and the segment commands 30 deg: no ramp,
  // the estimator restarts at the command
  const r = await req(d.base, 'POST', '/api/v1/experiments', {
    session: { params: { beta: 30 } },
    schedule: [{ beta: 30, until: 4 }],
    keep_session: true,
  });
  assert.equal(r.status, 201, r.text);
  // the answer is written once its session runs, which may have ended the
  // segment already (4 s of the defaults take milliseconds)
  if (r.body.segments[0].state !== 'done') {
    assert.equal(r.body.segments[0].uncertainty, null);
    assert.equal(r.body.segments[0].steady, null);
  }
  const done = await until(async () => {
    const g = await req(d.base, 'GET', `/api/v1/experiments/${r.body.id}`);
    return ['done', 'aborted'].includes(g.body.state) && g.body;
  }, 50000, 'the experiment');
  assert.equal(done.state, 'done', done.error);
  const [seg] = done.segments;
  const vRef = 0.152557;
  near(seg.mean_velocity, vRef, 0.01 * vRef, 'mean_velocity against 1 % of v_ref');
  near(seg.mean_velocity, vRef, seg.uncertainty, 'mean_velocity against its error bar');
  assert.equal(seg.steady, true);
  // keep_session: the session stays after the end
  await new Promise((res) => setTimeout(res, 1500));
  assert.equal((await req(d.base, 'GET', `/api/v1/sessions/${done.session}`)).status, 200);
  await req(d.base, 'DELETE', `/api/v1/sessions/${done.session}`);
});

test('a sweep can be cancelled while queued', { timeout: 60000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sweeps',
    { ...NO_FEED, beta: { from: 0, to: 180, step: 5 }, t_end: 0.2 });
  assert.equal(r.status, 202);
  assert.equal(r.body.total, 74);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sweeps/${r.body.id}`)).status, 204);
  await until(async () => {
    const h = await req(d.base, 'GET', '/api/v1/health');
    return h.body.pool_queued === 0;
  }, 20000, 'the pool to drain');
});

// A daemon on a fresh --data-dir for body(dd, dir, restart); restart()
// stops it (it must exit 0) and starts another on the same directory.
async function withDataDir(body) {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-'));
  let dd = await startDaemon(['--data-dir', dir]);
  const restart = async () => {
    assert.equal((await dd.stop()).code, 0, dd.stderr());
    dd = await startDaemon(['--data-dir', dir]);
    return dd;
  };
  try {
    await body(dd, dir, restart);
  } finally {
    assert.equal((await dd.stop()).code, 0, dd.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
}

test('--data-dir keeps finished sweeps and experiments', { timeout: 60000 * SLOW }, () => withDataDir(async (dd, dir) => {
  const sw = await req(dd.base, 'POST', '/api/v1/sweeps', { ...NO_FEED, beta: [20, 40], rotations: ['cw'], t_end: 0.1 });
  const ex = await req(dd.base, 'POST', '/api/v1/experiments', { session: { ...NO_FEED }, schedule: [{ beta: 50, until: 0.2 }] });
  await until(async () => (await req(dd.base, 'GET', `/api/v1/sweeps/${sw.body.id}`)).body.state === 'done', 20000, 'sweep');
  await until(async () => (await req(dd.base, 'GET', `/api/v1/experiments/${ex.body.id}`)).body.state === 'done', 20000, 'experiment');
  // results are written by the store's writer, just after the state says done
  await until(() => existsSync(join(dir, `sweep-${sw.body.id}.csv`)) &&
    existsSync(join(dir, `experiment-${ex.body.id}.json`)), 5000, 'the result files');
  const csv = readFileSync(join(dir, `sweep-${sw.body.id}.csv`), 'utf8').trim().split('\n');
  assert.equal(csv.length, 3);
  assert.equal(csv[1].split(',')[0], '20');
  const saved = JSON.parse(readFileSync(join(dir, `experiment-${ex.body.id}.json`), 'utf8'));
  assert.equal(saved.state, 'done');
  assert.equal(saved.segments[0].beta, 50);
}));

// An experiment short enough to end before its creation's answer is
// written still names its session in its saved result, on a fresh session
// and on an existing one (the session notes itself before its worker runs).
test('a short experiment\'s saved result names its session', { timeout: 60000 * SLOW }, () => withDataDir(async (dd, dir) => {
  const host = await req(dd.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 'max', until: 0.05 });
  assert.equal(host.status, 201, host.text);
  await until(async () => (await req(dd.base, 'GET', `/api/v1/sessions/${host.body.id}`)).body.state === 'finished', 20000, 'the session');
  const made = [];
  for (let i = 0; i < 12; i++) {
    const ex = await req(dd.base, 'POST', '/api/v1/experiments', { session: { ...NO_FEED }, schedule: [{ beta: 50, until: 0.05 }] });
    assert.equal(ex.status, 201, ex.text);
    made.push(ex.body);
  }
  const on = await req(dd.base, 'POST', '/api/v1/experiments', { session: host.body.id, schedule: [{ beta: 60, until: 0.05 }], keep_session: true });
  assert.equal(on.status, 201, on.text);
  made.push(on.body);
  for (const ex of made) {
    const file = join(dir, `experiment-${ex.id}.json`);
    await until(() => existsSync(file), 20000, `experiment-${ex.id}.json`);
    assert.equal(JSON.parse(readFileSync(file, 'utf8')).session, ex.session, file);
  }
}));

// A sweep deleted while its points run stays deleted: the points that were
// running when it went write no record of it again, so a restart does not
// bring it back.
test('a sweep deleted while its points run leaves no record behind', { timeout: 120000 * SLOW }, () => withDataDir(async (dd, dir, restart) => {
  // points of a few tenths of a second each (600 s of the defaults)
  const sw = await req(dd.base, 'POST', '/api/v1/sweeps', { beta: [10, 30, 50, 70, 90, 110], rotations: ['cw'], t_end: 600 });
  assert.equal(sw.status, 202, sw.text);
  const path = `/api/v1/sweeps/${sw.body.id}`;
  await until(async () => (await req(dd.base, 'GET', path)).body.state === 'running', 20000, 'a point to run');
  assert.equal((await req(dd.base, 'DELETE', path, undefined, { 'Content-Type': 'application/json' })).status, 204);
  // the points that were running end (the others are skipped)
  await until(async () => (await req(dd.base, 'GET', '/api/v1/health')).body.pool_queued === 0, 60000, 'the pool to drain');
  // and the ones running then: once the daemon idles (its CPU still over 0.3 s)
  await until(async () => {
    const cpu0 = processCpu(dd.proc.pid);
    await sleep(300);
    return processCpu(dd.proc.pid) - cpu0 < 0.02;
  }, 60000 * SLOW, 'the running points to end');
  const again = await restart();
  assert.ok(!existsSync(join(dir, 'sweeps', `${sw.body.id}.bin`)), 'the record is gone');
  assert.equal((await req(again.base, 'GET', path)).status, 404);
}));

// A v(beta) curve judges tol_met again with its own peak (docs/accuracy.md
// "A curve's own peak"): with g = 60 m/s^2 the feed barely throws, the
// run's peak estimate (half the trough's largest speed) is eight times the
// curve's, and the points near the curve's peak, whose bars exceed 1 % of
// |v|, said tol_met true by it. The daemon's curve and the CLI's agree to
// the byte; a point alone (no curve) keeps its run's judgement.
test('a v(beta) curve judges tol_met with its own peak, the daemon as the CLI', { timeout: 60000 * SLOW }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sweeps',
    { params: { g: 60 }, beta: { from: 0, to: 180, step: 30 }, rotations: ['cw'] });
  assert.equal(r.status, 202, r.text);
  await until(async () => (await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}`)).body.state === 'done', 50000, 'the sweep');
  const daemon = (await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}?format=csv`)).text.trim().split('\n');
  const cli = execFileSync(CLI, ['sweep', '--set', 'g=60', '--beta', '0:180:30', '--rotation', 'cw', '-q'])
    .toString().trim().split('\n');
  assert.deepEqual(daemon, cli);
  const col = cli[0].split(',');
  const rows = cli.slice(1).map((l) => Object.fromEntries(l.split(',').map((x, i) => [col[i], x])));
  const peak = Math.max(...rows.map((x) => Math.abs(+x.velocity)));
  for (const x of rows) {
    const v = Math.abs(+x.velocity), allowed = 0.01 * (v >= 0.3 * peak ? v : peak);
    assert.equal(x.tol_met, String(+x.uncertainty <= allowed), `beta ${x.beta}: ${x.uncertainty} against ${allowed}`);
  }
  assert.deepEqual(rows.map((x) => x.tol_met), ['false', 'false', 'true', 'true', 'true', 'false', 'false']);
  const one = execFileSync(CLI, ['sweep', '--set', 'g=60', '--beta', '150', '--rotation', 'cw', '-q']).toString().trim().split('\n');
  assert.equal(one[1].split(',')[col.indexOf('tol_met')], 'true');
});
