// SPDX-License-Identifier: GPL-3.0-or-later
// Read-only resources: presets, health, metrics format, the OpenAPI
// document, and the dashboard's static files (with no way out of web/).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { startDaemon, req, SLOW } from './lib.mjs';

let d;
before(async () => { d = await startDaemon(); });
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

test('presets carry the czubak2016 values and the settings table', { timeout: 10000 * SLOW }, async () => {
  const r = await req(d.base, 'GET', '/api/v1/presets');
  assert.equal(r.status, 200);
  const p = r.body.presets.find((x) => x.name === 'czubak2016');
  assert.equal(p.params.k_s1, 444132);
  assert.equal(p.params.e, 0.0215);
  assert.equal(p.params.omega_ss, 157.08);
  assert.equal(p.params.rotation, 'cw');
  assert.equal(p.scene.columns, 5);
  assert.equal(p.scene.layers, 8);
  const beta = r.body.settings.find((s) => s.name === 'beta');
  assert.equal(beta.group, 'params');
  assert.equal(beta.unit, 'deg');
  assert.ok(r.body.methods.length >= 1);
});

test('health and metrics', { timeout: 10000 * SLOW }, async () => {
  const h = await req(d.base, 'GET', '/api/v1/health');
  assert.equal(h.status, 200);
  assert.equal(h.body.status, 'ok');
  assert.equal(h.body.pool_threads, 2);
  const m = await req(d.base, 'GET', '/metrics');
  assert.match(m.headers.get('content-type'), /^text\/plain; version=0\.0\.4/);
  assert.match(m.text, /^# TYPE convsim_sessions gauge$/m);
  assert.match(m.text, /^convsim_http_requests_total\{status="200"\} \d+$/m);
});

test('OpenAPI 3.1 document', { timeout: 10000 * SLOW }, async () => {
  const r = await req(d.base, 'GET', '/api/v1/openapi.json');
  assert.equal(r.status, 200);
  assert.equal(r.body.openapi, '3.1.0');
  for (const p of ['/api/v1/sessions', '/api/v1/sessions/{id}', '/api/v1/sessions/{id}/stream',
    '/api/v1/sessions/{id}/trajectory', '/api/v1/experiments', '/api/v1/sweeps', '/metrics']) {
    assert.ok(r.body.paths[p], p);
  }
  assert.ok(r.body.paths['/api/v1/sessions/{id}'].patch);
  const params = r.body.components.schemas.Params.properties;
  assert.equal(params.k_s1.type, 'number');
  assert.deepEqual(params.rotation.enum, ['cw', 'ccw']);
  // every $ref names a schema, response or parameter the document has
  const refs = [];
  const walk = (v) => {
    if (!v || typeof v !== 'object') return;
    if (typeof v.$ref === 'string') refs.push(v.$ref);
    for (const x of Object.values(v)) walk(x);
  };
  walk(r.body);
  assert.ok(refs.length > 10);
  for (const ref of refs) {
    const m = ref.match(/^#\/components\/(schemas|responses|parameters)\/(\w+)$/);
    assert.ok(m && r.body.components[m[1]][m[2]], `unresolved ${ref}`);
  }
  const { schemas } = r.body.components;
  assert.deepEqual(schemas.Scene.properties.start.enum, ['rest', 'steady']);
  assert.equal(schemas.Scene.properties.start.default, 'steady');
  assert.equal(schemas.Scene.properties.transient.default, 0);
  const status = schemas.Status.properties;
  for (const k of ['transport_velocity', 'transport_velocity_uncertainty', 'rotor_speed_mean',
    'motor_torque_mean', 'power_mean']) assert.deepEqual(status[k].type, ['number', 'null'], k);
  assert.equal(status.steady.type, 'boolean');
  const item = (o) => (o.$ref ? schemas[o.$ref.split('/').pop()] : o);
  const point = item(schemas.Sweep.properties.points.items).properties;
  assert.ok(point.uncertainty && point.steady);
  const segment = item(schemas.Experiment.properties.segments.items).properties;
  assert.ok(segment.uncertainty && segment.steady && segment.mean_velocity);
});

test('static files: index at /, types by extension, no traversal', { timeout: 10000 * SLOW }, async () => {
  const r = await fetch(`${d.base}/`);
  assert.equal(r.status, 200);
  assert.match(r.headers.get('content-type'), /^text\/html/);
  assert.match(await r.text(), /<html/i);
  const curl = (path) => new Promise((resolve) => {
    const p = spawn('curl', ['-s', '--path-as-is', '-o', '/dev/null', '-w', '%{http_code}', d.base + path]);
    let o = '';
    p.stdout.on('data', (x) => { o += x; });
    p.on('exit', () => resolve(o));
  });
  for (const p of ['/../Makefile', '/js/../../Makefile', '/%2e%2e/Makefile', '/.git/config', '//etc/passwd', '/nope.html']) {
    assert.equal(await curl(p), '404', p);
  }
  assert.equal((await req(d.base, 'POST', '/index.html', {})).status, 405);
});
