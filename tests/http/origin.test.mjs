// SPDX-License-Identifier: GPL-3.0-or-later
// Cross-origin safety: Host must name the daemon (421: DNS rebinding),
// Origin must be its own or an --allow-origin (403), CORS preflights are
// answered exactly, and POST, PATCH, PUT and DELETE need Content-Type:
// application/json even without a body (415). Each refused request changes
// nothing. Requests with a chosen Host go out byte for byte (rawRequest).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, rawRequest, NO_FEED, SLOW } from './lib.mjs';

const LAB = 'http://lab.example:3000';
let d;
let id;
before(async () => {
  d = await startDaemon(['--allow-origin', LAB, '--server-name', 'conveyor.lab',
    '--server-name', 'proxy.lab:8443']);
  const r = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, params: { beta: 40 } });
  assert.equal(r.status, 201, r.text);
  id = r.body.id;
});
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

const get = (host, path = '/api/v1/sessions', more = '') =>
  rawRequest(d.port, `GET ${path} HTTP/1.1\r\nHost: ${host}${more}`);
const json = (r) => JSON.parse(r.body.toString('utf8'));

async function unchanged() {
  const list = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
  assert.deepEqual(list.map((s) => s.id), [id], 'the session list is unchanged');
  const s = await req(d.base, 'GET', `/api/v1/sessions/${id}`);
  assert.equal(s.body.status.beta_target, 40, 'beta is unchanged');
}

test('Host names the listening address and port, localhost or a --server-name', { timeout: 30000 * SLOW }, async () => {
  const p = d.port;
  for (const host of [`127.0.0.1:${p}`, `localhost:${p}`, `LOCALHOST:${p}`, 'conveyor.lab',
    `conveyor.lab:${p}`, 'proxy.lab:8443'])
    assert.equal((await get(host)).status, 200, host);
  for (const host of [`evil.example:${p}`, 'evil.example', `127.0.0.1:${p + 1}`, '127.0.0.1',
    `127.0.0.2:${p}`, `[::1]:${p}`, `localhost.evil.example:${p}`, 'proxy.lab', `proxy.lab:${p}`,
    `conveyor.lab:${p + 1}`, `127.0.0.1:${p}x`, `[::1`,
    // the port as clients write it: no leading zero, sign or space
    `127.0.0.1:0${p}`, `127.0.0.1:00${p}`, `127.0.0.1:+${p}`, `127.0.0.1: ${p}`, `localhost:0${p}`,
    `conveyor.lab:0${p}`, 'proxy.lab:08443', `127.0.0.1:`]) {
    const r = await get(host);
    assert.equal(r.status, 421, host);
    assert.deepEqual(json(r), {
      type: '/api/v1/problems/misdirected-request', title: 'Misdirected request', status: 421,
      detail: `Host "${host}" names neither the address this daemon listens on nor a --server-name`,
      instance: '/api/v1/sessions', field: 'Host',
    });
  }
  // a rebound name reaches neither the dashboard nor a mutating route
  assert.equal((await get(`evil.example:${p}`, '/')).status, 421);
  const post = await rawRequest(p, `POST /api/v1/sessions HTTP/1.1\r\nHost: evil.example:${p}\r\n` +
    'Content-Type: application/json\r\nContent-Length: 2', '{}');
  assert.equal(post.status, 421);
  // HTTP/1.0 without Host: 400
  const none = await rawRequest(p, 'GET /api/v1/sessions HTTP/1.0');
  assert.equal(none.status, 400);
  assert.deepEqual(json(none), {
    type: '/api/v1/problems/bad-request', title: 'Bad request', status: 400,
    detail: 'the request has no Host header', instance: '/api/v1/sessions', field: 'Host',
  });
  await unchanged();
});

test('Origin: our own and --allow-origin get CORS headers, others 403', { timeout: 30000 * SLOW }, async () => {
  const p = d.port;
  for (const origin of [`http://127.0.0.1:${p}`, `http://localhost:${p}`, LAB]) {
    const host = origin === LAB ? `127.0.0.1:${p}` : origin.slice(7);
    const r = await get(host, '/api/v1/sessions', `\r\nOrigin: ${origin}`);
    assert.equal(r.status, 200, origin);
    assert.equal(r.headers['access-control-allow-origin'], origin);
    assert.equal(r.headers.vary, 'Accept, Origin'); // a result route varies on Accept too
    assert.equal(r.headers['access-control-expose-headers'], 'Location, Retry-After, WWW-Authenticate');
  }
  const plain = await get(`127.0.0.1:${p}`);
  assert.equal(plain.headers['access-control-allow-origin'], undefined, 'no CORS without Origin');
  for (const origin of ['http://evil.example', `http://127.0.0.1:${p + 1}`, `http://localhost:${p}.evil.example`,
    'null', `${LAB}/`, 'http://lab.example']) {
    const r = await get(`127.0.0.1:${p}`, '/api/v1/sessions', `\r\nOrigin: ${origin}`);
    assert.equal(r.status, 403, origin);
    assert.equal(r.headers['access-control-allow-origin'], undefined);
    assert.deepEqual(json(r), {
      type: '/api/v1/problems/forbidden-origin', title: 'Origin not allowed', status: 403,
      detail: `origin "${origin}" may not call this daemon: only its own origin and those given with --allow-origin may`,
      instance: '/api/v1/sessions', field: 'Origin',
    });
  }
  // a hostile page's POST, PATCH and DELETE with the right content type
  const hostile = { Origin: 'http://evil.example' };
  assert.equal((await req(d.base, 'POST', '/api/v1/sessions', NO_FEED, hostile)).status, 403);
  assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 100 }, hostile)).status, 403);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${id}`, undefined, hostile)).status, 403);
  assert.equal((await req(d.base, 'POST', '/api/v1/sweeps', { beta: [30] }, hostile)).status, 403);
  await unchanged();
});

test('preflight: exact headers for an allowed origin, 403 for another', { timeout: 20000 * SLOW }, async () => {
  const pre = (origin) => rawRequest(d.port, `OPTIONS /api/v1/sessions/${id} HTTP/1.1\r\n` +
    `Host: 127.0.0.1:${d.port}\r\nOrigin: ${origin}\r\nAccess-Control-Request-Method: PATCH\r\n` +
    'Access-Control-Request-Headers: authorization, content-type');
  const ok = await pre(LAB);
  assert.equal(ok.status, 204);
  assert.equal(ok.body.length, 0);
  assert.equal(ok.headers['access-control-allow-origin'], LAB);
  assert.equal(ok.headers['access-control-allow-methods'], 'GET, HEAD, POST, PATCH, PUT, DELETE');
  assert.equal(ok.headers['access-control-allow-headers'], 'Authorization, Content-Type, Accept, Last-Event-ID');
  assert.equal(ok.headers['access-control-max-age'], '600');
  assert.equal(ok.headers.vary, 'Origin');
  const no = await pre('http://evil.example');
  assert.equal(no.status, 403);
  assert.equal(no.headers['access-control-allow-origin'], undefined);
  assert.equal(no.headers['access-control-allow-methods'], undefined);
  assert.equal(json(no).type, '/api/v1/problems/forbidden-origin');
  // OPTIONS without Origin is no preflight: 405 with Allow
  const plain = await rawRequest(d.port, `OPTIONS /api/v1/sessions HTTP/1.1\r\nHost: 127.0.0.1:${d.port}`);
  assert.equal(plain.status, 405);
  assert.equal(plain.headers.allow, 'POST, GET, HEAD');
});

test('POST, PATCH, PUT and DELETE without Content-Type: application/json: 415', { timeout: 20000 * SLOW }, async () => {
  const cases = [['POST', '/api/v1/sessions', undefined, null], ['POST', '/api/v1/sessions', '{}', 'text/plain'],
    ['POST', '/api/v1/sessions', 'a=1', 'application/x-www-form-urlencoded'],
    ['PATCH', `/api/v1/sessions/${id}`, '{"beta":100}', 'text/plain'],
    ['DELETE', `/api/v1/sessions/${id}`, undefined, null], ['POST', '/api/v1/sweeps', undefined, null],
    ['POST', '/api/v1/experiments', '{}', 'multipart/form-data; boundary=x'],
    ['PUT', '/api/v1/sessions', undefined, null], ['DELETE', '/index.html', undefined, null]];
  for (const [method, path, body, type] of cases) {
    const r = await req(d.base, method, path, body, { 'Content-Type': type });
    assert.equal(r.status, 415, `${method} ${path} ${type}`);
    assert.deepEqual(r.body, {
      type: '/api/v1/problems/unsupported-media-type', title: 'Unsupported media type', status: 415,
      detail: `${method} needs Content-Type: application/json, even with an empty body (got "${type ?? 'none'}")`,
      instance: path, field: 'Content-Type',
    });
  }
  // the type with a parameter passes; a route that takes no body takes an
  // empty one (a route that reads one wants a JSON object: strict.test.mjs)
  const s = await req(d.base, 'POST', '/api/v1/sessions', '{}', { 'Content-Type': 'application/json; charset=utf-8' });
  assert.equal(s.status, 201, s.text);
  assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${s.body.id}`, undefined)).status, 204);
  await unchanged();
});
