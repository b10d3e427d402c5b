// SPDX-License-Identifier: GPL-3.0-or-later
// Slow request bodies from many loopback addresses must not starve the
// daemon: a request whose body would not be read is answered before any
// byte of it (GET, HEAD, DELETE with a body: 400; a route or method that
// does not exist: 404, 405; no token: 401), and a body slower than
// --min-body-rate is closed after --request-timeout. Meanwhile and after,
// /api/v1/health answers, also to the flooding address itself: beyond
// --max-client-connections its own least progressed connection is closed. Bounded: at most 300 sockets from 100 addresses
// 127.3.x.y against a cap of 32, on loopback only.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import { startDaemon, req, metric, tokenFile, until, SLOW } from './lib.mjs';
import { openFlood, closeFlood, health } from '../bench/flood.mjs';

const TOKEN = 'slow-body-token-0123456789';

// The request head (lines without the blank line) on a fresh socket; its
// body is never sent. Resolves {status, headers, body (parsed JSON)} once
// the daemon has answered and closed, or {status: 0} when nothing came
// within ms: the daemon waits for a body that will not come.
function headOnly(port, head, ms = 5000 * SLOW) {
  return new Promise((resolve) => {
    const sock = net.connect(port, '127.0.0.1');
    const parts = [];
    const timer = setTimeout(() => { sock.destroy(); resolve({ status: 0 }); }, ms);
    sock.on('data', (b) => parts.push(b));
    sock.on('close', () => {
      clearTimeout(timer);
      const raw = Buffer.concat(parts).toString('utf8');
      const at = raw.indexOf('\r\n\r\n');
      if (at < 0) { resolve({ status: 0, raw }); return; }
      const lines = raw.slice(0, at).split('\r\n');
      const headers = {};
      for (const l of lines.slice(1)) {
        const i = l.indexOf(':');
        headers[l.slice(0, i).toLowerCase()] = l.slice(i + 1).trim();
      }
      let body = null;
      try { body = JSON.parse(raw.slice(at + 4)); } catch { /* not JSON */ }
      resolve({ status: Number(lines[0].split(' ')[1]), headers, body });
    });
    sock.on('error', () => {});
    sock.write(head + '\r\n\r\n');
  });
}

// /api/v1/health from addr on a fresh connection: 200 with status "ok"
// and the daemon's counts (no session, no stream).
async function healthy(port, addr, what) {
  const r = await health(port, addr, 5000 * SLOW);
  assert.equal(r.status, 200, `${what}: /api/v1/health ${r.error || r.status}`);
  assert.ok(r.ok, `${what}: status "ok"`);
  const full = await req(`http://127.0.0.1:${port}`, 'GET', '/api/v1/health');
  assert.equal(full.status, 200, what);
  assert.deepEqual({ ...full.body, uptime: 0 },
    { status: 'ok', uptime: 0, sessions: 0, max_sessions: 64, stream_clients: 0, max_streams: 256,
      pool_threads: 2, pool_queued: 0, api: 'v1' }, what);
}

test('a request whose body would not be read is answered before any byte of the body', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--token-file', tokenFile(TOKEN)]);
  const host = `Host: 127.0.0.1:${d.port}`;
  const auth = `Authorization: Bearer ${TOKEN}`;
  const problem = (type, status, field, detail, instance) => ({
    type: `/api/v1/problems/${type}`, status, field, detail, instance });
  const pick = (b) => ({ type: b.type, status: b.status, field: b.field, detail: b.detail, instance: b.instance });
  try {
    // no token: the gate answers 401 at once
    let r = await headOnly(d.port, `GET /api/v1/sessions HTTP/1.1\r\n${host}\r\nContent-Length: 1000`);
    assert.equal(r.status, 401, 'GET with a body and no token');
    assert.equal(r.body.field, 'Authorization');
    // GET, DELETE and HEAD take no body: 400 naming the header that announces one
    const noBody = (m) => `${m} takes no body, and this request announces one (Content-Length); ` +
      'nothing of it was read: send the request without it';
    r = await headOnly(d.port, `GET /api/v1/health HTTP/1.1\r\n${host}\r\nContent-Length: 1000`);
    assert.equal(r.status, 400, 'GET /api/v1/health with a body, no token needed');
    assert.deepEqual(pick(r.body), problem('bad-request', 400, 'Content-Length', noBody('GET'), '/api/v1/health'));
    assert.equal(r.headers['content-type'], 'application/problem+json');
    r = await headOnly(d.port, `GET /api/v1/sessions HTTP/1.1\r\n${host}\r\n${auth}\r\nContent-Length: 1000`);
    assert.deepEqual(pick(r.body), problem('bad-request', 400, 'Content-Length', noBody('GET'), '/api/v1/sessions'));
    r = await headOnly(d.port, `DELETE /api/v1/sessions/abc HTTP/1.1\r\n${host}\r\n${auth}\r\n` +
      'Content-Type: application/json\r\nContent-Length: 1000');
    assert.deepEqual(pick(r.body), problem('bad-request', 400, 'Content-Length', noBody('DELETE'), '/api/v1/sessions/abc'));
    r = await headOnly(d.port, `GET /index.html HTTP/1.1\r\n${host}\r\nTransfer-Encoding: chunked`);
    assert.equal(r.status, 400, 'a static file with a chunked body');
    assert.equal(r.body.field, 'Transfer-Encoding');
    // a route or method that does not exist: 404 and 405 before the body
    r = await headOnly(d.port, `POST /api/v1/nothing HTTP/1.1\r\n${host}\r\n${auth}\r\n` +
      'Content-Type: application/json\r\nContent-Length: 1000');
    assert.equal(r.status, 404, 'POST to no route');
    r = await headOnly(d.port, `PATCH /api/v1/sessions HTTP/1.1\r\n${host}\r\n${auth}\r\n` +
      'Content-Type: application/json\r\nContent-Length: 1000');
    assert.equal(r.status, 405, 'PATCH on the session list');
    assert.equal(r.headers.allow, 'POST, GET, HEAD');
    // a body the route reads is still read and answered
    const ok = await req(d.base, 'POST', '/api/v1/sessions', { scene: { drive: 'ideal', feed: false } },
      { Authorization: `Bearer ${TOKEN}` });
    assert.equal(ok.status, 201, ok.text);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('a flood of GETs with slow bodies from many addresses: each answered at once, /health throughout', { timeout: 90000 * SLOW }, async () => {
  // the flags of the release before, so that its daemon can be compared
  const d = await startDaemon(['--max-connections', '32']);
  let st = null;
  try {
    st = await openFlood(d.port, 'slow-get', 300, 100, '127.3');
    // asked once the daemon has taken the flood up (as in the slow-POST
    // case below: this process writes a new socket's request only after
    // the flood's events)
    await until(() => st.closedByDaemon >= 300 - 32, 10000, 'the flood taken up');
    await healthy(d.port, '127.0.0.1', 'during the flood');
    // each one answered 400 at once and closed, or closed at the cap
    // before its thread read it; none waits for its body
    await until(() => st.closedByDaemon === st.connected, 10000, 'every flood socket closed by the daemon');
    assert.equal(st.connected, 300, 'the flood connected');
    assert.ok(st.answered >= 32, `flood requests answered at once: ${st.answered}`);
    closeFlood(st);
    await healthy(d.port, '127.0.0.1', 'after the flood');
  } finally {
    if (st) closeFlood(st);
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('a flood of slow POST bodies from many addresses: closed at the cap or at their deadline, /health throughout', { timeout: 90000 * SLOW }, async () => {
  const d = await startDaemon(['--max-connections', '32', '--request-timeout', '1']);
  let st = null;
  try {
    st = await openFlood(d.port, 'slow-post', 150, 50, '127.3');
    // held at the cap: beyond 32 the least progressed were closed. Only
    // then is /health asked: while the daemon takes the flood's
    // connections up, this process's event loop turns through their
    // events before it writes the request of a socket that connected
    // meanwhile, and a connection with nothing sent is the least
    // progressed of all (the connect phase is measured by `make flood`,
    // whose active client is a process of its own)
    await until(() => st.closedByDaemon >= 150 - 32, 10000, 'the flood held at the cap');
    await healthy(d.port, '127.0.0.1', 'during the flood');
    // one byte every 2 s is below --min-body-rate: each body is cut once
    // its second passed (the reaper runs once a second)
    await until(() => st.closedByDaemon === st.connected, 10000, 'every slow body closed by the daemon');
    assert.equal(st.connected, 150, 'the flood connected');
    await healthy(d.port, '127.0.0.1', 'after the flood');
    const m = (await req(d.base, 'GET', '/metrics')).text;
    const evicted = metric(m, 'convsim_connections_evicted_total');
    const timedOut = metric(m, 'convsim_connections_timed_out_total');
    // none was complete: only those cut at their deadline with a byte of
    // the body read were answered, each 408
    assert.equal(st.answered, metric(m, 'convsim_connections_answered_408_total'), 'answered: the 408s');
    assert.ok(st.answered <= timedOut, `${st.answered} answered 408, ${timedOut} timed out`);
    assert.equal(evicted + timedOut, 150, `every flood socket closed at the cap (${evicted}) or its deadline (${timedOut})`);
    assert.ok(evicted >= 150 - 32, `beyond the cap the least progressed were closed (${evicted})`);
    assert.ok(timedOut >= 32 - 6, `those under the cap were cut at their deadline (${timedOut})`);
    assert.equal(metric(m, 'convsim_connections_dropped_total'), 0, 'none closed at accept');
    // no session was created by a cut body
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0);
  } finally {
    if (st) closeFlood(st);
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('a flood of slow POST bodies from one address: beyond its --max-client-connections its own least progressed are closed, not refused; it is still answered', { timeout: 90000 * SLOW }, async () => {
  const cap = 8;
  const d = await startDaemon(['--max-client-connections', String(cap), '--request-timeout', '30']);
  let st = null;
  try {
    // 60 slow bodies from 127.3.0.1 alone
    st = await openFlood(d.port, 'slow-post', 60, 1, '127.3');
    assert.equal(st.connected, 60, 'the flood connected');
    // beyond the cap each new one closed that address's oldest
    await until(() => st.closedByDaemon >= 60 - cap, 10000, 'the address held at its cap');
    // the same address is answered during its own flood: its new
    // connection closes its least progressed one, no 429, no refusal
    await healthy(d.port, '127.3.0.1', 'the flooding address itself');
    await healthy(d.port, '127.0.0.1', 'another address');
    const m = (await req(d.base, 'GET', '/metrics')).text;
    const evicted = metric(m, 'convsim_connections_evicted_total');
    assert.ok(evicted >= 60 - cap + 1, `beyond the cap its least progressed were closed (${evicted})`);
    assert.equal(metric(m, 'convsim_client_connections_refused_total'), 0, 'no 429');
    assert.equal(metric(m, 'convsim_connections_dropped_total'), 0, 'none closed at accept');
    assert.equal(st.answered, 0, 'no slow body got an answer (none was complete)');
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0);
  } finally {
    if (st) closeFlood(st);
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('headers that trickle are closed at --request-timeout, a request line that trickles at --connection-timeout', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--request-timeout', '1', '--heartbeat', '0.5', '--connection-timeout', '2']);
  const socks = [];
  // one byte every 200 ms restarts libmicrohttpd's own timeout each time
  const trickle = (first, text) => {
    const s = net.connect(d.port, '127.0.0.1');
    const st = { closedAt: 0, t0: Date.now() };
    if (first) s.write(first);
    let i = 0;
    const timer = setInterval(() => { if (i < text.length && s.writable) s.write(text[i++]); }, 200);
    s.on('close', () => { clearInterval(timer); st.closedAt = Date.now(); });
    s.on('error', () => {});
    socks.push(s);
    return st;
  };
  try {
    // the request line at once, then the headers a byte at a time: closed
    // --request-timeout (1 s) after the line, within the reaper's second
    const headers = trickle(`GET /api/v1/health HTTP/1.1\r\n`, `Host: 127.0.0.1:${d.port}\r\nX-Slow: ${'a'.repeat(200)}`);
    // the request line itself a byte at a time: closed --connection-timeout
    // (2 s) after the connection opened
    const line = trickle('', `GET /api/v1/health${'a'.repeat(200)}`);
    await until(() => headers.closedAt && line.closedAt, 15000, 'both trickling sockets closed');
    assert.ok(headers.closedAt - headers.t0 < 4000 * SLOW, `headers closed after ${headers.closedAt - headers.t0} ms`);
    assert.ok(line.closedAt - line.t0 >= 1900, `request line closed after ${line.closedAt - line.t0} ms, not before 2 s`);
    assert.ok(line.closedAt - line.t0 < 5000 * SLOW, `request line closed after ${line.closedAt - line.t0} ms`);
    const m = (await req(d.base, 'GET', '/metrics')).text;
    assert.equal(metric(m, 'convsim_connections_timed_out_total'), 2, 'both counted as timed out');
    await healthy(d.port, '127.0.0.1', 'after');
  } finally {
    for (const s of socks) s.destroy();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

// A POST body that trickles (a byte every 300 ms, below --min-body-rate)
// until the connection closes; resolves with what the daemon sent.
function trickleBody(port, head) {
  return new Promise((resolve) => {
    const s = net.connect(port, '127.0.0.1');
    const parts = [];
    let timer = null;
    s.on('connect', () => {
      s.write(head);
      timer = setInterval(() => { if (s.writable) s.write('{'); }, 300);
    });
    s.on('data', (b) => parts.push(b));
    s.on('error', () => {});
    s.on('close', () => { clearInterval(timer); resolve(Buffer.concat(parts).toString('utf8')); });
  });
}

test('a body that falls behind --min-body-rate is answered 408 with a problem, then closed', { timeout: 30000 * SLOW }, async () => {
  const d = await startDaemon(['--request-timeout', '1']);
  try {
    const head = `POST /api/v1/sessions HTTP/1.1\r\nHost: 127.0.0.1:${d.port}\r\n` +
      'Content-Type: application/json\r\nContent-Length: 1000\r\n\r\n';
    const raw = await trickleBody(d.port, head);
    const at = raw.indexOf('\r\n\r\n');
    assert.ok(at > 0, `an answer came: ${JSON.stringify(raw)}`);
    const lines = raw.slice(0, at).split('\r\n');
    assert.equal(lines[0], 'HTTP/1.1 408 Request Timeout');
    assert.ok(lines.includes('Content-Type: application/problem+json'), lines.join(' | '));
    assert.ok(lines.includes('Connection: close'), lines.join(' | '));
    const body = raw.slice(at + 4);
    assert.ok(lines.includes(`Content-Length: ${Buffer.byteLength(body)}`), lines.join(' | '));
    assert.deepEqual(JSON.parse(body), {
      type: '/api/v1/problems/request-timeout', title: 'Request timeout', status: 408,
      detail: 'the body came slower than 1024 bytes/s (--min-body-rate) after its first 1 s ' +
        '(--request-timeout); nothing was done with the request and the connection is closed: ' +
        'send it again at a steady pace',
      field: 'body',
    });
    const m = (await req(d.base, 'GET', '/metrics')).text;
    assert.equal(metric(m, 'convsim_connections_timed_out_total'), 1);
    assert.equal(metric(m, 'convsim_connections_answered_408_total'), 1);
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
    const page = await req(d.base, 'GET', '/api/v1/problems/request-timeout');
    assert.equal(page.status, 200);
    assert.match(page.text, /slower than the daemon allows/);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
