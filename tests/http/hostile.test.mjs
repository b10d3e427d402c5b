// SPDX-License-Identifier: GPL-3.0-or-later
// Hostile bytes and files: the web root serves regular files only (a FIFO,
// a directory or a link out of the root is "not found", at once, and the
// daemon still stops cleanly); every problem is valid UTF-8 JSON whatever
// bytes the request held; a malformed Content-Length is refused with 400
// before any of the daemon's code runs (libmicrohttpd answers it; docs/operations.md
// "Security" says what it sends).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { execFileSync } from 'node:child_process';
import { copyFileSync, mkdirSync, mkdtempSync, symlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, rawRequest, metric, WEB_ROOT, SLOW } from './lib.mjs';

test('the web root serves regular files only; a FIFO neither hangs a request nor the shutdown', { timeout: 60000 * SLOW }, async () => {
  const root = mkdtempSync(join(tmpdir(), 'convsim-web-'));
  copyFileSync(join(WEB_ROOT, 'index.html'), join(root, 'index.html'));
  writeFileSync(join(root, 'secret.txt'), 'outside the root\n');
  const web = join(root, 'web');
  mkdirSync(join(web, 'dir'), { recursive: true });
  copyFileSync(join(WEB_ROOT, 'index.html'), join(web, 'index.html'));
  execFileSync('mkfifo', [join(web, 'fifo.js')]);
  symlinkSync('/etc/passwd', join(web, 'passwd.txt'));
  symlinkSync('../secret.txt', join(web, 'secret.txt'));
  symlinkSync('..', join(web, 'up'));
  symlinkSync('/dev/zero', join(web, 'zero.js'));
  symlinkSync('index.html', join(web, 'home.html')); // a link inside the root is fine
  const d = await startDaemon(['--web-root', web]);
  try {
    for (const path of ['/fifo.js', '/passwd.txt', '/secret.txt', '/up/secret.txt', '/zero.js', '/dir',
      '/dir/', '/up/index.html', '/../secret.txt', '/%2e%2e/secret.txt']) {
      const t0 = Date.now();
      const r = await req(d.base, 'GET', path);
      assert.equal(r.status, 404, `${path}: ${r.text}`);
      assert.equal(r.body.type, '/api/v1/problems/not-found');
      assert.ok(!r.text.includes('outside the root') && !r.text.includes('root:'), path);
      assert.ok(Date.now() - t0 < 5000 * SLOW, `${path} answered at once`);
    }
    for (const path of ['/', '/index.html', '/home.html']) {
      const r = await req(d.base, 'GET', path);
      assert.equal(r.status, 200, path);
      assert.match(r.text, /<html/);
    }
  } finally {
    const t0 = Date.now();
    assert.equal((await d.stop()).code, 0, d.stderr());
    assert.ok(Date.now() - t0 < 10000 * SLOW, 'the shutdown is not hung');
  }
});

// The answer decodes as strict UTF-8 and parses as JSON; returns it.
function strict(r) {
  const text = new TextDecoder('utf-8', { fatal: true }).decode(r.body);
  return JSON.parse(text);
}

test('problems are valid UTF-8 JSON whatever bytes the request held', { timeout: 30000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const host = `Host: 127.0.0.1:${d.port}`;
    const bytes = (...parts) => Buffer.concat(parts.map((p) => (typeof p === 'string' ? Buffer.from(p, 'latin1') : Buffer.from(p))));
    const post = (path, body, more = '') => rawRequest(d.port, bytes(`POST ${path} HTTP/1.1\r\n${host}\r\n` +
      `Content-Type: application/json\r\nContent-Length: ${body.length}${more}`), body);
    const cases = [
      // path bytes, raw and percent-encoded
      [await rawRequest(d.port, bytes('GET /api/v1/sessions/', [0xff, 0xfe, 0xc3], ` HTTP/1.1\r\n${host}`)), 404, 'instance'],
      [await rawRequest(d.port, bytes(`GET /api/v1/sessions/%e0%80%af HTTP/1.1\r\n${host}`)), 404, 'instance'],
      [await rawRequest(d.port, bytes(`GET /api/v1/sessions/%ff%c0%80%ed%a0%80 HTTP/1.1\r\n${host}`)), 404, 'instance'],
      [await rawRequest(d.port, bytes('GET /', [0xf8, 0x80], `.js HTTP/1.1\r\n${host}`)), 404, 'detail'],
      // a member's name and a value: invalid UTF-8 is malformed JSON (strict.test.mjs)
      [await post('/api/v1/sessions', bytes('{"', [0xff, 0xc0, 0xaf], 'x":1}')), 400, null],
      [await post('/api/v1/sessions', bytes('{"preset":"', [0xe2, 0x82], '"}')), 400, null],
      [await post('/api/v1/sessions', bytes('{"params":{"', [0xf4, 0x90, 0x80, 0x80], '":1}}')), 400, null],
      // a name of 2-byte characters cut at the field's 64 bytes and in the detail
      [await post('/api/v1/sessions', Buffer.from(`{"params":{"a${'é'.repeat(200)}":1}}`)), 422, null],
      // header values echoed in details
      [await post('/api/v1/sessions', Buffer.from('{}'), '\r\nOrigin: http://\xff.example'), 403, 'detail'],
      [await rawRequest(d.port, bytes(`POST /api/v1/sessions HTTP/1.1\r\n${host}\r\nContent-Type: text/`, [0xff])), 415, 'detail'],
      [await rawRequest(d.port, bytes('GET /api/v1/sessions HTTP/1.1\r\nHost: \xff\xfe')), 421, 'detail'],
    ];
    for (const [r, status, member] of cases) {
      assert.equal(r.status, status, r.raw.toString('latin1'));
      assert.match(r.headers['content-type'], /^application\/problem\+json/);
      const p = strict(r);
      assert.equal(p.status, status);
      if (member) assert.ok(p[member].includes('\uFFFD'), `${member} marks the bad bytes: ${p[member]}`);
    }
    // valid multi-byte text passes unchanged
    const ok = await post('/api/v1/sessions', Buffer.from('{"params":{"βeta_ü":1}}'));
    assert.equal(strict(ok).field, 'params.βeta_ü');
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('a malformed Content-Length: 400 from libmicrohttpd, the handler never runs, nothing changes', { timeout: 30000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const count400 = async () => metric((await req(d.base, 'GET', '/metrics')).text, 'convsim_http_requests_total{status="400"}');
    const before = await count400();
    for (const cl of ['abc', '5x', '-1', '1 2', '0x10']) {
      const r = await rawRequest(d.port, `POST /api/v1/sessions HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
        `Content-Type: application/json\r\nContent-Length: ${cl}`, '{}');
      assert.equal(r.status, 400, cl);
      assert.match(r.raw.toString('latin1'), /^HTTP\/1\.1 400 Bad Request\r\n/);
      assert.match(r.raw.toString('latin1'), /wrong value for <b>Content-Length<\/b>/);
    }
    assert.equal(await count400(), before, 'answered before the access handler (not counted by it)');
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
