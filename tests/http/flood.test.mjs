// SPDX-License-Identifier: GPL-3.0-or-later
// Idle sockets from many loopback addresses (any local user may pick
// 127.x.y.z, so the per-client budget does not hold them back) must not
// lock anyone out: at --max-connections the daemon closes the idlest
// connections with no request in flight, so /api/v1/health and an active
// client are answered within a second, and a stream (a request in flight)
// is never closed to make room. Bounded: 150 sockets from 50 addresses
// against a cap of 32, on loopback only.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import { startDaemon, req, openStream, metric, CHEAP, SLOW } from './lib.mjs';
import { call } from '../bench/streamlag.mjs';

const CAP = 32;

// n idle sockets spread over `addresses` source addresses 127.1.0.1...;
// resolves once each has connected, failed or waited 3 s.
function idleFlood(port, n, addresses) {
  const socks = [];
  const counts = { connected: 0, closedByDaemon: 0, failed: 0 };
  const done = Promise.all(Array.from({ length: n }, (_, i) => new Promise((resolve) => {
    const a = i % addresses;
    const s = net.connect({ port, host: '127.0.0.1', localAddress: `127.1.${Math.floor(a / 250)}.${1 + (a % 250)}` });
    socks.push(s);
    const timer = setTimeout(resolve, 3000);
    s.on('connect', () => { counts.connected++; clearTimeout(timer); resolve(); });
    s.on('close', () => { counts.closedByDaemon++; });
    s.on('error', () => { counts.failed++; clearTimeout(timer); resolve(); });
  })));
  return { socks, counts, done };
}

test('at the connection cap, idle sockets from many addresses make room for /health, an active client and keep streams', { timeout: 90000 * SLOW }, async () => {
  const d = await startDaemon(['--max-connections', String(CAP), '--connection-timeout', '60']);
  const flood = [];
  const ac = new AbortController();
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    // a stream: a request in flight for its whole life
    let records = 0;
    let streamError = null;
    const stream = (async () => {
      for await (const rec of openStream(d.base, `/api/v1/sessions/${s.body.id}/stream?fields=trough&rate=20`, {}, ac.signal)) {
        if (rec.event === 'sample') records++;
      }
    })().catch((e) => { streamError = e; });
    const t0 = Date.now();
    while (records === 0 && Date.now() - t0 < 5000 * SLOW) await new Promise((r) => setTimeout(r, 50));
    assert.ok(records > 0, `the stream delivers (${streamError})`);
    for (let round = 0; round < 3; round++) {
      const f = idleFlood(d.port, 50, 50);
      flood.push(f);
      await f.done;
      // each round: health and the active client answered at once, on fresh connections
      for (const [path, from] of [['/api/v1/health', '127.0.0.1'], [`/api/v1/sessions/${s.body.id}`, '127.0.0.4']]) {
        const r = await call(d.base, 'GET', path, undefined, { localAddress: from });
        assert.equal(r.status, 200, `round ${round}, ${path}: ${r.error || r.status}`);
        assert.ok(r.ms < 1000 * SLOW, `round ${round}, ${path}: answered in ${r.ms} ms`);
      }
    }
    const connected = flood.reduce((n, f) => n + f.counts.connected, 0);
    assert.ok(connected >= 140, `the idle sockets were accepted (${connected} of 150)`);
    const m = (await req(d.base, 'GET', '/metrics')).text;
    const evicted = metric(m, 'convsim_connections_evicted_total');
    assert.ok(evicted >= 150 - CAP, `idle connections were closed to make room (${evicted})`);
    const closed = flood.reduce((n, f) => n + f.counts.closedByDaemon, 0);
    assert.ok(closed >= 150 - CAP - 4, `the daemon closed the idlest sockets (${closed})`);
    // the idlest (the earlier rounds') went first; the cap's worth of the newest are still open
    assert.ok(flood[0].counts.closedByDaemon >= 48, `first round closed: ${flood[0].counts.closedByDaemon}`);
    assert.ok(flood[1].counts.closedByDaemon >= 48, `second round closed: ${flood[1].counts.closedByDaemon}`);
    const open = 50 - flood[2].counts.closedByDaemon;
    assert.ok(open >= CAP - 6 && open <= CAP, `last round still open: ${open}`);
    // the stream was never closed: it still delivers
    const before = records;
    const t1 = Date.now();
    while (records === before && Date.now() - t1 < 5000 * SLOW) await new Promise((r) => setTimeout(r, 100));
    assert.ok(records > before, `the stream still delivers (${records} records; ${streamError})`);
  } finally {
    ac.abort();
    for (const f of flood) for (const s of f.socks) s.destroy();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
