// SPDX-License-Identifier: GPL-3.0-or-later
// The OpenAPI document against the live daemon, with ajv's JSON Schema
// 2020-12 validator: every operation it lists is exercised and its answer
// validated against the schema the document gives for that status; every
// stream record kind seen (SSE and NDJSON) against StreamRecord; the
// request bodies sent against their (closed) request schemas, and a body
// with an unknown member is refused by both the schema and the daemon.
// Besides, the document itself is validated as OpenAPI 3.1 by an external
// validator, @apidevtools/swagger-parser, and every well-formed request of
// the tour goes through a validating proxy, Prism (`prism proxy --errors`),
// in front of the daemon: a request or an answer that breaks the document
// is a violation there, and the test fails on any.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import Ajv2020 from 'ajv/dist/2020.js';
import SwaggerParser from '@apidevtools/swagger-parser';
import { startDaemon, req, until, openStream, SLOW, CHEAP } from './lib.mjs';
import { startPrism } from './prism.mjs';

const ID = 'https://convsim.invalid/openapi.json';
let d, doc, ajv;
const seen = new Set();

let prism, proxy;

before(async () => {
  d = await startDaemon(['--heartbeat', '0.2']);
  const r = await req(d.base, 'GET', '/api/v1/openapi.json');
  doc = r.body;
  ajv = new Ajv2020({ strict: false, allErrors: true });
  ajv.addSchema({ ...doc, $id: ID });
  prism = await startPrism(r.text, d.base);
  proxy = prism.url;
});
after(async () => { prism?.stop(); await d?.stop(); });

test('the served document is valid OpenAPI 3.1 (swagger-parser)', async () => {
  assert.equal(doc.openapi, '3.1.0');
  await SwaggerParser.validate(structuredClone(doc));
  // a stream is a sequence of records: the body is text, each record is a StreamRecord
  const ok = doc.paths['/api/v1/sessions/{id}/stream'].get.responses['200'].content;
  for (const type of ['text/event-stream', 'application/x-ndjson']) {
    assert.deepEqual(ok[type].schema, { type: 'string' }, type);
    assert.equal(ok[type]['x-itemSchema'].$ref, '#/components/schemas/StreamRecord', type);
  }
  // and the validator does reject what is not OpenAPI 3.1
  const bad = structuredClone(doc);
  bad.paths['/api/v1/sessions/{id}/stream'].get.responses['200'].content['application/x-ndjson'].itemSchema = { type: 'object' };
  await assert.rejects(SwaggerParser.validate(bad), /unevaluated properties|itemSchema/);
});

const schema = (name) => {
  const v = ajv.getSchema(`${ID}#/components/schemas/${name}`);
  assert.ok(v, `schema ${name}`);
  return v;
};
function valid(name, value, what) {
  const v = schema(name);
  assert.ok(v(value), `${what} against ${name}: ${ajv.errorsText(v.errors)}\n${JSON.stringify(value).slice(0, 400)}`);
}
const deref = (o) => (o && o.$ref ? o.$ref.split('/').slice(1).reduce((a, k) => a[k], doc) : o);

// call an operation as the document describes it and validate the answer;
// a request that is well-formed by the document (checkBody) goes through
// the validating proxy, which must find nothing wrong with it or its answer
async function call(method, template, path, body, headers, checkBody = true) {
  const op = doc.paths[template]?.[method.toLowerCase()];
  assert.ok(op, `${method} ${template} is in the document`);
  if (body !== undefined && op.requestBody && checkBody) {
    const ref = op.requestBody.content['application/json'].schema.$ref.split('/').pop();
    valid(ref, body, `${method} ${template} request`);
  }
  const r = await req(checkBody ? proxy : d.base, method, path, body, headers);
  if (checkBody) {
    assert.equal(r.headers.get('sl-violations'), null, `${method} ${path}: Prism found violations: ${r.headers.get('sl-violations')}`);
    assert.notEqual(r.body?.type, 'https://stoplight.io/prism/errors#VIOLATIONS',
      `${method} ${path}: Prism found violations: ${JSON.stringify(r.body?.validation)?.slice(0, 1000)}`);
  }
  const resp = deref(op.responses[String(r.status)]);
  assert.ok(resp, `${method} ${path}: status ${r.status} is documented (${r.text.slice(0, 200)})`);
  const ct = (r.headers.get('content-type') || '').split(';')[0];
  if (resp.content) {
    assert.ok(resp.content[ct], `${method} ${path}: ${ct} is documented for ${r.status}`);
    const s = resp.content[ct].schema;
    if (s && ct.includes('json')) {
      const name = (s.$ref || '').split('/').pop();
      if (name) valid(name, r.body, `${method} ${path} -> ${r.status}`);
    }
  } else {
    assert.equal(r.text, '', `${method} ${path}: no body documented`);
  }
  seen.add(`${method.toLowerCase()} ${template}`);
  return r;
}

test('every operation answers what the document says', { timeout: 120000 * SLOW }, async () => {
  const create = { ...CHEAP, params: { beta: 38, rotation: 'cw' }, pace: 'max', until: 0.5, sample_rate: 250 };
  const s = (await call('POST', '/api/v1/sessions', '/api/v1/sessions', create)).body;
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${s.id}`)).body.state === 'finished', 30000 * SLOW, 'finished');
  await call('GET', '/api/v1/sessions', '/api/v1/sessions');
  await call('GET', '/api/v1/sessions', '/api/v1/sessions?format=csv');
  await call('GET', '/api/v1/sessions/{id}', `/api/v1/sessions/${s.id}`);
  await call('PATCH', '/api/v1/sessions/{id}', `/api/v1/sessions/${s.id}`,
    { beta: 128, beta_rate: 90, rotation: 'ccw', omega_ss: 150, running: true, motor_on: true, pace: 'max', until: 0.8 });
  await call('GET', '/api/v1/sessions/{id}/trajectory', `/api/v1/sessions/${s.id}/trajectory?from=0&to=0.4`);
  await call('GET', '/api/v1/sessions/{id}/trajectory', `/api/v1/sessions/${s.id}/trajectory?format=csv`);
  const e = (await call('POST', '/api/v1/experiments', '/api/v1/experiments',
    { session: { ...CHEAP, pace: 'max' }, schedule: [{ beta: 38, until: 0.3 }, { beta: 128, until: 0.6 }], beta_rate: 90 })).body;
  await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${e.id}`)).body.state === 'done', 30000 * SLOW, 'experiment');
  await call('GET', '/api/v1/experiments/{id}', `/api/v1/experiments/${e.id}`);
  // the kinds: an identification and a closed loop with a disturbance (docs/control.md)
  for (const body of [{ identify: { beta: 60, step: 4, hold: 0.5 } },
    { control: { setpoint: [{ v: 0.05, until: 0.5 }], controller: { kp: 1, ki: 100 } },
      disturbances: [{ at: 0.25, set: { omega_ss: 155 } }] }]) {
    const k = (await call('POST', '/api/v1/experiments', '/api/v1/experiments', body)).body;
    await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${k.id}`)).body.state === 'done', 30000 * SLOW, k.kind);
    await call('GET', '/api/v1/experiments/{id}', `/api/v1/experiments/${k.id}`);
  }
  await call('GET', '/api/v1/experiments', '/api/v1/experiments');
  const w = (await call('POST', '/api/v1/sweeps', '/api/v1/sweeps',
    { ...CHEAP, beta: { from: 30, to: 60, step: 30 }, rotations: ['cw', 'ccw'], t_end: 0.3 })).body;
  await until(async () => (await req(d.base, 'GET', `/api/v1/sweeps/${w.id}`)).body.state === 'done', 30000 * SLOW, 'sweep');
  await call('GET', '/api/v1/sweeps/{id}', `/api/v1/sweeps/${w.id}`);
  await call('GET', '/api/v1/sweeps', '/api/v1/sweeps');
  const f = (await call('POST', '/api/v1/fits', '/api/v1/fits',
    { ...CHEAP, free: [{ name: 'e', min: 0.01, max: 0.03 }], t_end: 0.5, curve_step: 90, max_iter: 2,
      points: [{ beta: 30, rotation: 'cw', v: 0.1, sigma: 0.01 }, { beta: 130, rotation: 'cw', v: -0.1, sigma: 0.01 }] })).body;
  await until(async () => (await req(d.base, 'GET', `/api/v1/fits/${f.id}`)).body.state === 'done', 60000 * SLOW, 'fit');
  await call('GET', '/api/v1/fits/{id}', `/api/v1/fits/${f.id}`);
  await call('GET', '/api/v1/fits/{id}', `/api/v1/fits/${f.id}?format=csv`);
  await call('GET', '/api/v1/fits', '/api/v1/fits');
  // a study over two settings and a sweep with the fit's band, through the proxy too
  for (const body of [{ ...CHEAP, vary: { mu: [0.3, 0.9], beta: { from: 30, to: 150, step: 120 } }, rotations: ['cw'], t_end: 0.3 },
    { ...CHEAP, beta: [30, 130], rotations: ['cw'], t_end: 0.5, band_from_fit: f.id }]) {
    const st = (await call('POST', '/api/v1/sweeps', '/api/v1/sweeps', body)).body;
    await until(async () => (await req(d.base, 'GET', `/api/v1/sweeps/${st.id}`)).body.state === 'done', 60000 * SLOW, 'study');
    await call('GET', '/api/v1/sweeps/{id}', `/api/v1/sweeps/${st.id}`);
    await call('GET', '/api/v1/sweeps/{id}', `/api/v1/sweeps/${st.id}?format=csv`);
  }
  await call('DELETE', '/api/v1/fits/{id}', `/api/v1/fits/${f.id}`, undefined, { 'Content-Type': 'application/json' });
  await call('GET', '/api/v1/presets', '/api/v1/presets');
  await call('GET', '/api/v1/health', '/api/v1/health');
  await call('GET', '/api/v1/openapi.json', '/api/v1/openapi.json');
  await call('GET', '/api/v1/problems/{id}', '/api/v1/problems/out-of-range');
  await call('GET', '/metrics', '/metrics');
  // problems, each validated as the documented Problem
  // (sent past the proxy: Prism itself answers a request that breaks the document)
  await call('GET', '/api/v1/sessions/{id}', '/api/v1/sessions/none');
  await call('GET', '/api/v1/sessions/{id}/trajectory', `/api/v1/sessions/${s.id}/trajectory?fromm=1`, undefined, {}, false);
  await call('GET', '/api/v1/sweeps/{id}', `/api/v1/sweeps/${w.id}`, undefined, { Accept: 'image/png' }, false);
  await call('POST', '/api/v1/sessions', '/api/v1/sessions', { params: { k_s1: -1 } }, {}, false);
  await call('PATCH', '/api/v1/sessions/{id}', `/api/v1/sessions/${s.id}`, { beta: 500 }, {}, false);
  assert.equal(schema('Control')({ beta: 500 }), false, 'the document bounds a control as the daemon does');
  // a DELETE without the JSON type: 415, as the document says
  assert.equal((await call('DELETE', '/api/v1/sweeps/{id}', `/api/v1/sweeps/${w.id}`, undefined, { 'Content-Type': null })).status, 415);
  await call('DELETE', '/api/v1/sweeps/{id}', `/api/v1/sweeps/${w.id}`);
  await call('DELETE', '/api/v1/experiments/{id}', `/api/v1/experiments/${e.id}`);
  await call('DELETE', '/api/v1/sessions/{id}', `/api/v1/sessions/${s.id}`);
  // the stream: SSE and NDJSON records of every kind it produced
  const s2 = (await call('POST', '/api/v1/sessions', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 0.2 })).body;
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${s2.id}`)).body.state === 'finished', 30000 * SLOW, 'finished');
  await req(d.base, 'PATCH', `/api/v1/sessions/${s2.id}`, { until: 0.3 });
  await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${s2.id}`)).body.status.t >= 0.3, 30000 * SLOW, 'resumed');
  const slow = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 0.001 })).body;
  const kinds = new Set();
  for (const [path, ndjson] of [[`/api/v1/sessions/${s2.id}/stream?since=0&fields=all&limit=200`, false],
    [`/api/v1/sessions/${s2.id}/stream?format=ndjson&since=0&fields=all&limit=200`, true],
    [`/api/v1/sessions/${slow.id}/stream?format=ndjson&fields=feed`, true]]) {
    let n = 0;
    for await (const r of openStream(d.base, path)) {
      if (r.comment) continue;
      if (!ndjson && !r.data) continue; /* the retry: line */
      const rec = ndjson ? r : { type: r.event, ...(r.id !== undefined ? { id: r.id } : {}), ...r.data };
      valid('StreamRecord', rec, `${path} record ${n}`);
      kinds.add(rec.type);
      n++;
      if (rec.type === 'end' || (rec.type === 'heartbeat' && !path.includes('since'))) break;
    }
  }
  seen.add('get /api/v1/sessions/{id}/stream');
  for (const k of ['hello', 'sample', 'control', 'finished', 'end', 'heartbeat']) assert.ok(kinds.has(k), `a ${k} record was seen and validated`);
  const ops = Object.entries(doc.paths).flatMap(([p, o]) => Object.keys(o).map((m) => `${m} ${p}`));
  assert.deepEqual(ops.filter((o) => !seen.has(o)), [], 'every documented operation was exercised');
});

test('request schemas are closed like the parsers: an unknown member fails both', async () => {
  for (const [name, path, body] of [
    ['SessionCreate', '/api/v1/sessions', { pace: 1, bogus: 1 }],
    ['ExperimentCreate', '/api/v1/experiments', { schedule: [{ beta: 38, until: 1 }], bogus: 1 }],
    ['SweepCreate', '/api/v1/sweeps', { beta: [30], bogus: 1 }],
    ['FitCreate', '/api/v1/fits', { free: ['e'], bogus: 1 }],
  ]) {
    assert.equal(schema(name)(body), false, `${name} refuses an unknown member`);
    const r = await req(d.base, 'POST', path, body);
    assert.equal(r.status, 422, path);
    assert.equal(r.body.type, '/api/v1/problems/unknown-field');
  }
  for (const name of ['Status', 'Session', 'Experiment', 'Sweep', 'SweepPoint', 'Segment', 'Trajectory', 'Problem', 'Fit', 'FitResult']) {
    const s = doc.components.schemas[name];
    assert.ok(s.additionalProperties === false || s.unevaluatedProperties === false, `${name} is closed`);
    assert.ok(Array.isArray(s.required) || s.allOf, `${name} says what is required`);
  }
  // query parameters: what the document lists, the daemon takes
  for (const [p, o] of Object.entries(doc.paths)) {
    const ps = (o.get?.parameters || []).filter((x) => x.in === 'query');
    if (!p.includes('trajectory')) continue;
    assert.deepEqual(ps.map((x) => x.name).sort(), ['format', 'from', 'stride', 'to']);
  }
});
