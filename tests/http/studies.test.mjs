// SPDX-License-Identifier: GPL-3.0-or-later
// Studies over any setting through POST /api/v1/sweeps ("vary", "lhs",
// "seed") on the real daemon: the table equals the CLI's table of the same
// study bit for bit (the same core plans and measures both); the columns
// are the varied settings by name; an unknown setting or a value out of
// its range is a 422 problem naming the field with the range, and nothing
// is started; a study survives a restart of the daemon mid-way.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import Ajv2020 from 'ajv/dist/2020.js';
import { startDaemon, req, until, CHEAP, CLI } from './lib.mjs';

// the CLI's options for CHEAP and t_end
const CHEAP_CLI = ['--set', 'drive=ideal', '--set', 'columns=1', '--set', 'layers=2', '-q'];
const cli = (...args) => execFileSync(CLI, ['sweep', ...CHEAP_CLI, ...args], { encoding: 'utf8' });

let d, ajv;
const ID = 'https://convsim.invalid/openapi.json';
before(async () => {
  d = await startDaemon();
  ajv = new Ajv2020({ strict: false, allErrors: true });
  ajv.addSchema({ ...(await req(d.base, 'GET', '/api/v1/openapi.json')).body, $id: ID });
});
// value is what the served OpenAPI document's schema `name` says
function valid(name, value) {
  const v = ajv.getSchema(`${ID}#/components/schemas/${name}`);
  assert.ok(v(value), `${name}: ${ajv.errorsText(v.errors)}`);
}
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const done = (dd, id) => until(async () => {
  const r = await req(dd.base, 'GET', `/api/v1/sweeps/${id}`);
  return r.body.state === 'done' && r.body;
}, 60000, `sweep ${id}`);

test('a 2-D study (mu x beta): the daemon\'s table is the CLI\'s, bit for bit, the varied settings first', { timeout: 120000 }, async () => {
  const body = { ...CHEAP, vary: { mu: [0.3, 0.9], beta: { from: 30, to: 150, step: 60 } }, rotations: ['cw', 'ccw'], t_end: 0.4 };
  const r = await req(d.base, 'POST', '/api/v1/sweeps', body);
  assert.equal(r.status, 202, r.text);
  assert.deepEqual(r.body.vary, [{ name: 'mu', unit: '1' }, { name: 'beta', unit: 'deg' }]);
  const s = await done(d, r.body.id);
  valid('SweepCreate', body);
  valid('Sweep', s);
  valid('SweepList', (await req(d.base, 'GET', '/api/v1/sweeps')).body);
  assert.equal(s.total, 12);
  assert.deepEqual(s.points.slice(0, 6).map((p) => [p.mu, p.beta, p.rotation]),
    [[0.3, 30, 'cw'], [0.3, 90, 'cw'], [0.3, 150, 'cw'], [0.9, 30, 'cw'], [0.9, 90, 'cw'], [0.9, 150, 'cw']]);
  // the mirror reduction: (ccw, 180 - beta) at the same mu
  assert.deepEqual(s.reductions, ['mirror']);
  const ccw = s.points.find((p) => p.mu === 0.9 && p.beta === 30 && p.rotation === 'ccw');
  const cw = s.points.find((p) => p.mu === 0.9 && p.beta === 150 && p.rotation === 'cw');
  assert.equal(ccw.mirrored, true);
  assert.equal(ccw.velocity, -cw.velocity);
  assert.notEqual(s.points[0].velocity, s.points[3].velocity, 'mu changes v');
  const csv = (await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}?format=csv`)).text;
  assert.equal(csv.split('\n')[0], 'mu,beta,rotation,velocity,uncertainty,steady,state,dt,substeps,step_error,tol_met,model_error,model_error_uncertainty,model_checked');
  assert.equal(csv, cli('--vary', 'mu=0.3,0.9', '--vary', 'beta=30:150:60', '--duration', '0.4'));
  // a point alone, on the CLI, is the same point
  const alone = cli('--vary', 'mu=0.9', '--beta', '90', '--rotation', 'cw', '--duration', '0.4').split('\n')[1];
  assert.equal(alone, csv.split('\n')[5]);
});

test('"lhs" and "seed": the CLI\'s Latin hypercube; without vary, beta kept the model\'s', { timeout: 120000 }, async () => {
  const r = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, vary: { e: { from: 0.01, to: 0.03, step: 0.01 }, mu: { from: 0.2, to: 1, step: 0.1 } }, lhs: 4, seed: 5, rotations: ['cw'], t_end: 0.3, params: { beta: 50 } });
  assert.equal(r.status, 202, r.text);
  assert.equal(r.body.lhs, 4);
  assert.equal(r.body.seed, 5);
  await done(d, r.body.id);
  const csv = (await req(d.base, 'GET', `/api/v1/sweeps/${r.body.id}?format=csv`)).text;
  assert.equal(csv, cli('--vary', 'e=0.01:0.03:0.01', '--vary', 'mu=0.2:1:0.1', '--lhs', '4', '--seed', '5',
    '--rotation', 'cw', '--duration', '0.3', '--set', 'beta=50'));
  assert.equal(csv.trim().split('\n').length, 5);
});

test('an unknown setting or a value out of range: 422 naming the field and the range, nothing started', async () => {
  const before = (await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length;
  for (const [body, status, field, re, range] of [
    [{ vary: { muu: [0.2] } }, 422, 'vary.muu', /unknown setting "muu" \(did you mean "mu"\?\)/],
    [{ vary: { mu: { from: 0, to: 3, step: 1 } } }, 422, 'vary.mu', /mu must be a finite number in \[0, 2\]/, [0, 2]],
    [{ vary: { e: [0.01, 0.7] } }, 422, 'vary.e', /e must be a finite number in \[0, 0\.5\] m/, [0, 0.5]],
    [{ vary: { columns: [1, 2.5] } }, 422, 'vary.columns', /columns must be an integer/, [1, 64]],
    [{ vary: { drive: [0, 1] } }, 422, 'vary.drive', /drive is a choice, not a number/],
    [{ vary: { rotation: [0, 1] } }, 422, 'vary.rotation', /rotation is not varied as a setting/],
    // the setting is judged before its values: the senses as strings, a
    // choice by its names, an unknown name with an empty list
    [{ vary: { rotation: ['cw', 'ccw'] } }, 422, 'vary.rotation', /rotation is not varied as a setting/],
    [{ vary: { drive: ['ideal', 'motor'] } }, 422, 'vary.drive', /drive is a choice, not a number/],
    [{ vary: { drive: { from: 'a', to: 'b', step: 1 } } }, 422, 'vary.drive', /drive is a choice, not a number/],
    [{ vary: { muu: [] } }, 422, 'vary.muu', /unknown setting "muu" \(did you mean "mu"\?\)/],
    // every point's transient lies before t_end (given or default)
    [{ vary: { transient: [0, 10] }, t_end: 4 }, 422, 't_end', /^t_end \(4 s\) must exceed scene\.transient = 10 s \(the largest of vary\.transient/, [10, 600]],
    [{ vary: { transient: { from: 0, to: 6, step: 3 } } }, 422, 't_end', /^t_end \(4 s\) must exceed scene\.transient = 6 s/, [6, 600]],
    [{ vary: { mu: { from: 1, to: 0, step: 0.1 } } }, 422, 'vary.mu', /a range needs FROM <= TO/],
    [{ vary: { mu: { from: 0, to: 1 } } }, 400, 'vary.mu', /vary\.mu\.step must be a number/],
    [{ vary: { mu: { from: 0, to: 1, step: 0.5, by: 1 } } }, 422, 'vary.mu.by', /by/],
    [{ vary: { mu: [0.1, 'x'] } }, 400, 'vary.mu', /vary\.mu\[1\] must be a number/],
    [{ vary: [] }, 400, 'vary', /vary must be an object/],
    [{ beta: [10], vary: { beta: [20] } }, 422, 'vary.beta', /beta is varied twice/],
    [{ lhs: 3 }, 422, 'lhs', /lhs samples the ranges of vary/],
    [{ vary: { mu: [0.1, 0.2] }, lhs: 3 }, 422, 'lhs', /a Latin-hypercube sample needs a range/],
    [{ vary: { mu: { from: 0, to: 1, step: 0.5 } }, lhs: 2.5 }, 422, 'lhs', /whole number/],
    [{ vary: { mu: { from: 0, to: 2, step: 0.01 }, e: { from: 0.01, to: 0.05, step: 0.01 } } }, 422, 'vary', /the study has 2010 points/],
  ]) {
    const r = await req(d.base, 'POST', '/api/v1/sweeps', body);
    const what = JSON.stringify(body);
    assert.equal(r.status, status, `${what}: ${r.text}`);
    assert.match(r.headers.get('content-type'), /^application\/problem\+json/);
    assert.equal(r.body.field, field, what);
    assert.match(r.body.detail, re, what);
    if (range) assert.deepEqual([r.body.min, r.body.max], range, what);
  }
  assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length, before, 'nothing started');
});

test('a study survives a restart: its settings and points as they were, the rest run after', { timeout: 180000 }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-study-'));
  let dd = await startDaemon(['--data-dir', dir, '--pool-threads', '1']);
  try {
    // points of a few tenths of a second each (300 s simulated): the stop
    // falls mid-study
    const body = { vary: { k_c: [1e5, 2e5, 4e5], beta: [40, 80] }, rotations: ['cw'], t_end: 300 };
    const r = await req(dd.base, 'POST', '/api/v1/sweeps', body);
    assert.equal(r.status, 202, r.text);
    await until(async () => (await req(dd.base, 'GET', `/api/v1/sweeps/${r.body.id}`)).body.done >= 1, 60000, 'a point');
    assert.equal((await dd.stop()).code, 0, dd.stderr());
    dd = await startDaemon(['--data-dir', dir, '--pool-threads', '1']);
    const back = await req(dd.base, 'GET', `/api/v1/sweeps/${r.body.id}`);
    assert.equal(back.status, 200, back.text);
    assert.ok(back.body.done < 6, `the stop fell mid-study (${back.body.done} of 6 done)`);
    assert.deepEqual(back.body.vary.map((a) => a.name), ['k_c', 'beta']);
    assert.deepEqual(back.body.points.map((p) => [p.k_c, p.beta]), [[1e5, 40], [1e5, 80], [2e5, 40], [2e5, 80], [4e5, 40], [4e5, 80]]);
    const s = await done(dd, r.body.id);
    const csv = (await req(dd.base, 'GET', `/api/v1/sweeps/${r.body.id}?format=csv`)).text;
    assert.equal(csv, execFileSync(CLI, ['sweep', '--vary', 'k_c=1e5,2e5,4e5', '--vary', 'beta=40,80', '--rotation', 'cw',
      '--duration', '300', '-q'], { encoding: 'utf8' }));
    assert.equal(s.state, 'done');
  } finally {
    assert.equal((await dd.stop()).code, 0, dd.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
