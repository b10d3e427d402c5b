// SPDX-License-Identifier: GPL-3.0-or-later
// null is no value of a request member (docs/api-errors.md): every member
// of every request body the OpenAPI document describes, nested ones too,
// sent as null onto a body the daemon accepts, is the 400 wrong-type a
// value of a wrong type gets there, naming the member (or the array item
// it is in), and creates or changes nothing.
// The one exception is `until` of a session and of PATCH, where null is
// "no end"; the document declares it nullable and no other member.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, CHEAP, NO_FEED, SLOW } from './lib.mjs';

let d, spec, session, fitId;
before(async () => {
  d = await startDaemon(['--max-cpu-seconds', '300']);
  spec = (await req(d.base, 'GET', '/api/v1/openapi.json')).body;
  const s = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1 });
  assert.equal(s.status, 201, s.text);
  session = s.body.id;
  // a finished fit for band_from_fit (openapi.test.mjs's)
  const f = await req(d.base, 'POST', '/api/v1/fits', {
    ...CHEAP, free: [{ name: 'e', min: 0.01, max: 0.03 }], t_end: 0.5, curve_step: 90, max_iter: 2,
    points: [{ beta: 30, rotation: 'cw', v: 0.1, sigma: 0.01 }, { beta: 130, rotation: 'cw', v: -0.1, sigma: 0.01 }],
  });
  assert.equal(f.status, 202, f.text);
  fitId = f.body.id;
  await until(async () => (await req(d.base, 'GET', `/api/v1/fits/${fitId}`)).body.state === 'done', 60000 * SLOW, 'fit');
});
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const NULLABLE = ['Control.until', 'SessionCreate.until'];
const sweep = { ...NO_FEED, beta: [20], rotations: ['cw'], t_end: 0.1 };
const fit = { ...CHEAP, free: ['mu'], points: [{ beta: 60, rotation: 'cw', v: 0.1, sigma: 0.01 }], t_end: 1, max_iter: 1 };
const experiment = { session: { ...NO_FEED }, schedule: [{ beta: 50, until: 0.2 }], beta_rate: 180, keep_session: false };
const loop = (controller) => ({
  session: { ...CHEAP },
  control: { setpoint: [{ v: 0.1, until: 1 }], controller, ...(controller === 'auto' ? { tau_c: 1 } : {}) },
  disturbances: [{ at: 0.5, set: { omega_ss: 150 } }],
});

// [request schema, method, path, a body the daemon accepts, where the
// schema's object is in it, the members tried (default: all)]
const CASES = [
  ['SessionCreate', 'POST', '/api/v1/sessions', { ...NO_FEED, preset: 'czubak2016', params: {}, integrator: {}, pace: 1, sample_rate: 100 }, []],
  ['Control', 'PATCH', () => `/api/v1/sessions/${session}`, { beta: 50 }, []],
  ['SweepCreate', 'POST', '/api/v1/sweeps', { ...sweep, preset: 'czubak2016', params: {}, integrator: {} }, [],
    (m) => !['lhs', 'seed', 'band_from_fit', 'vary'].includes(m)],
  ['SweepCreate', 'POST', '/api/v1/sweeps', { ...NO_FEED, vary: { beta: { from: 20, to: 40, step: 10 } }, lhs: 2, seed: 1, rotations: ['cw'], t_end: 0.1 }, [],
    (m) => ['lhs', 'seed', 'vary'].includes(m)],
  ['SweepCreate', 'POST', '/api/v1/sweeps', () => ({ ...CHEAP, beta: [30, 130], rotations: ['cw'], t_end: 0.5, band_from_fit: fitId }), [],
    (m) => m === 'band_from_fit'],
  ['BetaRange', 'POST', '/api/v1/sweeps', { ...sweep, beta: { from: 20, to: 40, step: 10 } }, ['beta']],
  ['FitCreate', 'POST', '/api/v1/fits', { ...fit, preset: 'czubak2016', params: {}, integrator: {}, curve_step: 5, starts: 1, fd_step: 0.05 }, [],
    (m) => m !== 'csv' && m !== 'peaks'],
  ['FitCreate', 'POST', '/api/v1/fits', { ...CHEAP, free: ['mu'], csv: 'beta,rotation,v\n60,cw,0.1\n', t_end: 1, max_iter: 1 }, [],
    (m) => m === 'csv'],
  ['FitCreate', 'POST', '/api/v1/fits', { ...CHEAP, free: ['mu'], peaks: [{ beta: 60, rotation: 'cw', sigma: 2 }], t_end: 1, max_iter: 1 }, [],
    (m) => m === 'peaks'],
  ['FitFree', 'POST', '/api/v1/fits', { ...fit, free: [{ name: 'mu', min: 0.1, max: 1, start: 0.5, prior: { mean: 0.5, sd: 0.1 } }] }, ['free', 0]],
  ['FitPrior', 'POST', '/api/v1/fits', { ...fit, free: [{ name: 'mu', prior: { mean: 0.5, sd: 0.1 } }] }, ['free', 0, 'prior'],
    (m) => m !== 'factor'],
  ['FitPrior', 'POST', '/api/v1/fits', { ...fit, free: [{ name: 'mu', min: 0.1, max: 1, prior: { mean: 0.5, factor: 2 } }] }, ['free', 0, 'prior'],
    (m) => m === 'factor'],
  ['FitPoint', 'POST', '/api/v1/fits', fit, ['points', 0]],
  ['FitPeak', 'POST', '/api/v1/fits', { ...CHEAP, free: ['mu'], peaks: [{ beta: 60, rotation: 'cw', sigma: 2 }], t_end: 1, max_iter: 1 }, ['peaks', 0]],
  ['ExperimentCreate', 'POST', '/api/v1/experiments', experiment, [], (m) => m !== 'disturbances'],
  ['ExperimentCreate', 'POST', '/api/v1/experiments', loop({ kp: 2, ki: 800 }), [], (m) => m === 'disturbances'],
  ['ExperimentSession', 'POST', '/api/v1/experiments',
    { ...experiment, session: { ...NO_FEED, preset: 'czubak2016', params: {}, integrator: {}, pace: 'max', sample_rate: 100 } }, ['session']],
  ['ScheduleSegment', 'POST', '/api/v1/experiments', experiment, ['schedule', 0]],
  ['Identify', 'POST', '/api/v1/experiments', { session: { ...CHEAP }, identify: { beta: 60, step: 4, hold: 0.5 } }, ['identify']],
  ['ExperimentControl', 'POST', '/api/v1/experiments', loop({ kp: 2, ki: 800 }), ['control'], (m) => m !== 'tau_c'],
  ['ExperimentControl', 'POST', '/api/v1/experiments', loop('auto'), ['control'], (m) => m === 'tau_c'],
  ['Setpoint', 'POST', '/api/v1/experiments', loop({ kp: 2, ki: 800 }), ['control', 'setpoint', 0]],
  ['Controller', 'POST', '/api/v1/experiments', loop({ kp: 2, ki: 800 }), ['control', 'controller']],
  ['Disturbance', 'POST', '/api/v1/experiments', loop({ kp: 2, ki: 800 }), ['disturbances', 0]],
];

const ids = async () => {
  const out = {};
  for (const kind of ['sessions', 'sweeps', 'fits', 'experiments']) {
    out[kind] = (await req(d.base, 'GET', `/api/v1/${kind}?scope=local`)).body[kind].map((e) => e.id).sort();
  }
  return out;
};

const nullable = (schema) => [].concat(schema.type || []).includes('null');

test('the document declares null for no request member but until', () => {
  const found = [];
  for (const [name, schema] of Object.entries(spec.components.schemas)) {
    if (!name.match(/Create$|^Control$/) || !schema.properties) continue;
    for (const [m, p] of Object.entries(schema.properties)) if (nullable(p)) found.push(`${name}.${m}`);
  }
  assert.deepEqual(found.sort(), NULLABLE);
});

test('until: null is no end, on creation and in PATCH', async () => {
  const c = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, until: null });
  assert.equal(c.status, 201, c.text);
  assert.equal(c.body.until, null);
  const p = await req(d.base, 'PATCH', `/api/v1/sessions/${c.body.id}`, { until: null });
  assert.equal(p.status, 200, p.text);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${c.body.id}`)).status, 204);
});

test('every other member sent as null is 400 wrong-type naming it, and changes nothing', { timeout: 120000 * SLOW }, async () => {
  const tried = new Set();
  for (const [name, method, pathOf, baseOf, at, pick = () => true] of CASES) {
    const path = typeof pathOf === 'function' ? pathOf() : pathOf;
    const base = typeof baseOf === 'function' ? baseOf() : baseOf;
    const schema = spec.components.schemas[name];
    assert.ok(schema && schema.properties, name);
    // the body as it is is accepted (so a refusal below is the null's)
    const ok = await req(d.base, method, path, base);
    assert.ok(ok.status < 300, `${name}: the base body: ${ok.text}`);
    if (method === 'POST' && !path.endsWith('/experiments')) {
      assert.equal((await req(d.base, 'DELETE', `${path}/${ok.body.id}`)).status, 204);
    }
    const before = await ids();
    const sessionBefore = (await req(d.base, 'GET', `/api/v1/sessions/${session}`)).body;
    for (const m of Object.keys(schema.properties).filter(pick)) {
      if (NULLABLE.includes(`${name}.${m}`)) continue;
      const body = structuredClone(base);
      let obj = body;
      for (const k of at) obj = obj[k];
      assert.ok(obj && typeof obj === 'object', `${name}: ${at.join('.')}`);
      // a value of a wrong type for the member (true, or 5 where true is right)
      const wrongBody = structuredClone(body);
      let wobj = wrongBody;
      for (const k of at) wobj = wobj[k];
      wobj[m] = [].concat(schema.properties[m].type || []).includes('boolean') ? 5 : true;
      obj[m] = null;
      const r = await req(d.base, method, path, body);
      const what = `${name}.${m}: ${r.text}`;
      assert.equal(r.status, 400, what);
      assert.equal(r.body.type, '/api/v1/problems/wrong-type', what);
      assert.equal(r.headers.get('content-type'), 'application/problem+json', what);
      assert.ok(r.body.field.includes(m) || /\[\d+\]$/.test(r.body.field), what);
      // the same problem as the wrong type's
      const w = await req(d.base, method, path, wrongBody);
      assert.deepEqual(r.body, w.body, `${what}\n${w.text}`);
      tried.add(`${name}.${m}`);
    }
    // no new id (the base bodies' fresh sessions go as their experiments end)
    const after = await ids();
    for (const kind of Object.keys(after)) {
      assert.deepEqual(after[kind].filter((id) => !before[kind].includes(id)), [], `${name}: no ${kind} created`);
    }
    const sessionAfter = (await req(d.base, 'GET', `/api/v1/sessions/${session}`)).body;
    assert.equal(sessionAfter.status.beta_target, sessionBefore.status.beta_target, `${name}: no control applied`);
  }
  // every member of every request schema was tried
  for (const [name] of CASES) {
    for (const m of Object.keys(spec.components.schemas[name].properties)) {
      if (!NULLABLE.includes(`${name}.${m}`)) assert.ok(tried.has(`${name}.${m}`), `${name}.${m} not tried`);
    }
  }
});

test('the model members named in the issue: the same problem as a wrong type', async () => {
  for (const member of ['params', 'scene', 'integrator', 'preset']) {
    const wrong = await req(d.base, 'POST', '/api/v1/sessions', { [member]: 5 });
    const none = await req(d.base, 'POST', '/api/v1/sessions', { [member]: null });
    assert.equal(none.status, wrong.status, none.text);
    assert.deepEqual(none.body, wrong.body);
    assert.equal(none.body.field, member);
    assert.match(none.body.detail, member === 'preset' ? /^preset must be a string/ : new RegExp(`^${member} must be an object of NAME: VALUE`));
  }
});

test('an experiment\'s fresh session names its members by their path in the body (session.scene, not scene)', async () => {
  const schedule = [{ beta: 30, until: 1 }];
  const cases = [
    [{ scene: 5 }, 400, 'wrong-type', 'session.scene'],
    [{ scene: null }, 400, 'wrong-type', 'session.scene'],
    [{ params: { beta: 500 } }, 422, 'out-of-range', 'session.params.beta'],
    [{ scene: { layers: 0 } }, 422, 'out-of-range', 'session.scene.layers'],
    [{ pace: -1 }, 422, 'out-of-range', 'session.pace'],
    [{ foo: 1 }, 422, 'unknown-field', 'session.foo'],
  ];
  for (const [session, status, slug, field] of cases) {
    const r = await req(d.base, 'POST', '/api/v1/experiments', { session, schedule });
    assert.equal(r.status, status, r.text);
    assert.equal(r.body.type, `/api/v1/problems/${slug}`, r.text);
    assert.equal(r.body.field, field, r.text);
  }
});
