// SPDX-License-Identifier: GPL-3.0-or-later
// The bearer token (--token-file): every route but the dashboard's files and
// /api/v1/health answers 401 with WWW-Authenticate without it or with another
// token, and the right one opens them; a refused request changes nothing.
// The daemon refuses to start with a token file others may read, an empty
// one, or a non-loopback --listen without a token (unless --insecure).
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { randomBytes } from 'node:crypto';
import { BIN, WEB_ROOT, startDaemon, req, rawRequest, tokenFile, NO_FEED, SLOW } from './lib.mjs';

const TOKEN = randomBytes(24).toString('hex');
const AUTH = { Authorization: `Bearer ${TOKEN}` };
let d;
let id; // a session created with the token
before(async () => {
  d = await startDaemon(['--token-file', tokenFile(TOKEN)]);
  const r = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, params: { beta: 40 } }, AUTH);
  assert.equal(r.status, 201, r.text);
  id = r.body.id;
});
after(async () => { assert.equal((await d.stop()).code, 0, d.stderr()); });

// One request of each route class: [method, path, body].
const routes = () => [
  ['GET', '/api/v1/sessions'], ['POST', '/api/v1/sessions', NO_FEED],
  ['GET', `/api/v1/sessions/${id}`], ['PATCH', `/api/v1/sessions/${id}`, { beta: 100 }],
  ['DELETE', `/api/v1/sessions/${id}`], ['GET', `/api/v1/sessions/${id}/stream`],
  ['GET', `/api/v1/sessions/${id}/trajectory`], ['POST', '/api/v1/experiments', {}],
  ['GET', '/api/v1/experiments'], ['POST', '/api/v1/sweeps', {}], ['GET', '/api/v1/sweeps'],
  ['DELETE', '/api/v1/sweeps/0123456789abcdef'], ['GET', '/api/v1/presets'],
  ['GET', '/api/v1/openapi.json'], ['GET', '/api/v1/problems/unauthorized'], ['GET', '/metrics'],
  ['GET', '/api/v1/no-such-route'], ['GET', '/api'],
];

async function refused(headers, detail, challenge) {
  for (const [method, path, body] of routes()) {
    const r = await req(d.base, method, path, body, headers);
    assert.equal(r.status, 401, `${method} ${path}: ${r.text}`);
    assert.equal(r.headers.get('www-authenticate'), challenge, path);
    assert.equal(r.headers.get('content-type'), 'application/problem+json');
    assert.deepEqual(r.body, {
      type: '/api/v1/problems/unauthorized', title: 'Unauthorized', status: 401,
      detail, instance: path, field: 'Authorization',
    });
  }
}

async function unchanged() {
  const list = (await req(d.base, 'GET', '/api/v1/sessions', undefined, AUTH)).body.sessions;
  assert.deepEqual(list.map((s) => s.id), [id], 'the session list is unchanged');
  const s = await req(d.base, 'GET', `/api/v1/sessions/${id}`, undefined, AUTH);
  assert.equal(s.body.status.beta_target, 40, 'beta is unchanged');
}

test('no token: 401 with the challenge on every route class, nothing changed', { timeout: 30000 * SLOW }, async () => {
  await refused({}, 'this route needs Authorization: Bearer TOKEN (the daemon runs with --token-file)',
    'Bearer realm="convsim"');
  await unchanged();
});

test('a wrong, truncated, extended or non-bearer token: 401 invalid_token', { timeout: 60000 * SLOW }, async () => {
  const other = 'the bearer token is not this daemon\'s';
  const challenge = 'Bearer realm="convsim", error="invalid_token"';
  const flipped = TOKEN.slice(0, -1) + (TOKEN.endsWith('0') ? '1' : '0');
  for (const auth of [`Bearer ${TOKEN.slice(0, -1)}`, `Bearer ${TOKEN}x`, `Bearer ${flipped}`,
    'Bearer', `Basic ${Buffer.from(`u:${TOKEN}`).toString('base64')}`, TOKEN])
    await refused({ Authorization: auth }, other, challenge);
  await unchanged();
});

test('the right token opens every route; the scheme is case-insensitive', { timeout: 30000 * SLOW }, async () => {
  for (const path of ['/api/v1/sessions', `/api/v1/sessions/${id}`, `/api/v1/sessions/${id}/trajectory`,
    '/api/v1/presets', '/api/v1/openapi.json', '/api/v1/problems/unauthorized', '/metrics',
    '/api/v1/experiments', '/api/v1/sweeps'])
    assert.equal((await req(d.base, 'GET', path, undefined, AUTH)).status, 200, path);
  const lower = await req(d.base, 'GET', '/api/v1/sessions', undefined, { Authorization: `bearer  ${TOKEN}` });
  assert.equal(lower.status, 200);
  const p = await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 41 }, AUTH);
  assert.equal(p.status, 200, p.text);
  assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: 40 }, AUTH)).status, 200);
  // a stream with the header
  const ac = new AbortController();
  const s = await fetch(`${d.base}/api/v1/sessions/${id}/stream?limit=1`, { headers: AUTH, signal: ac.signal });
  assert.equal(s.status, 200);
  ac.abort();
});

test('/api/v1/health and the dashboard\'s files need no token', { timeout: 20000 * SLOW }, async () => {
  const h = await req(d.base, 'GET', '/api/v1/health');
  assert.equal(h.status, 200);
  assert.equal(h.body.status, 'ok');
  for (const path of ['/', '/index.html', '/js/api.js', '/css/dashboard.css']) {
    const r = await req(d.base, 'GET', path);
    assert.equal(r.status, 200, path);
  }
});

test('the token is compared over the raw header too (no token leaks into the problem)', { timeout: 20000 * SLOW }, async () => {
  const r = await rawRequest(d.port, `GET /api/v1/sessions HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\nAuthorization: Bearer ${TOKEN}z`);
  assert.equal(r.status, 401);
  assert.ok(!r.raw.toString('latin1').includes(TOKEN), 'the answer does not echo the token');
});

// Start the daemon with args; resolves {code, stderr, stdout} once it exits
// or, when it prints its address, stops it and resolves with code 'listening'.
function launch(args) {
  return new Promise((resolve) => {
    const p = spawn(BIN, ['--port', '0', '--web-root', WEB_ROOT, '--log-level', 'warn', ...args]);
    let out = '', err = '';
    p.stdout.on('data', (x) => {
      out += x;
      if (/^listening on /m.test(out)) p.kill('SIGTERM');
    });
    p.stderr.on('data', (x) => { err += x; });
    p.on('exit', (code) => resolve({ code: /^listening on /m.test(out) ? 'listening' : code, stderr: err, stdout: out }));
  });
}

test('token files others may read, empty or missing ones are refused at start', { timeout: 30000 * SLOW }, async () => {
  let r = await launch(['--token-file', tokenFile(TOKEN, 0o644)]);
  assert.equal(r.code, 2);
  assert.match(r.stderr, /--token-file \S+ may be read or written by group or others; chmod 600 it \(mode 0644\)/);
  r = await launch(['--token-file', tokenFile(TOKEN, 0o640)]);
  assert.equal(r.code, 2);
  r = await launch(['--token-file', tokenFile('', 0o600)]);
  assert.equal(r.code, 2);
  assert.match(r.stderr, /--token-file \S+ is empty/);
  r = await launch(['--token-file', tokenFile('short', 0o600)]);
  assert.equal(r.code, 2);
  assert.match(r.stderr, /fewer than 16 characters/);
  r = await launch(['--token-file', '/nonexistent/token']);
  assert.equal(r.code, 2);
  assert.match(r.stderr, /--token-file \/nonexistent\/token: No such file or directory/);
  r = await launch(['--token-file', tokenFile(TOKEN, 0o400)]);
  assert.equal(r.code, 'listening', r.stderr);
});

test('beyond loopback: refused without a token, served with one or with --insecure', { timeout: 30000 * SLOW }, async () => {
  for (const addr of ['0.0.0.0', '::']) {
    const r = await launch(['--listen', addr]);
    assert.equal(r.code, 2);
    assert.equal(r.stderr, `convsimd: --listen ${addr} reaches beyond this machine: give --token-file FILE, ` +
      'or --insecure to serve without a token\n');
  }
  assert.equal((await launch(['--listen', '0.0.0.0', '--insecure'])).code, 'listening');
  assert.equal((await launch(['--listen', '0.0.0.0', '--token-file', tokenFile(TOKEN)])).code, 'listening');
  assert.equal((await launch(['--listen', '::1'])).code, 'listening');
  // served on every interface with --insecure: reachable, Host an IP literal
  const w = await startDaemon(['--listen', '0.0.0.0', '--insecure']);
  try {
    assert.equal((await req(w.base, 'GET', '/api/v1/sessions')).status, 200);
  } finally {
    assert.equal((await w.stop()).code, 0);
  }
});
