// SPDX-License-Identifier: GPL-3.0-or-later
// The daemon's own accept loop (server/admit/acceptor.c): it empties the
// kernel's accept queue at once and hands the connections to the HTTP
// library those of an address with fewer open or waiting first, so a
// newcomer passes a flood's backlog instead of waiting behind all of it.
// The backlog is made without timing: the daemon is stopped (SIGSTOP)
// while 300 connections from 10 loopback addresses and then the
// newcomer's complete their handshake in the kernel and send their
// requests; then it continues (SIGCONT). libmicrohttpd's own accept took
// them one at a time in the kernel's order, the newcomer last.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import net from 'node:net';
import { readFileSync, readdirSync } from 'node:fs';
import { startDaemon, req, metric, until, SLOW } from './lib.mjs';

const BACKLOG = 300;

// Every thread of process pid stopped (state T in /proc): SIGSTOP is
// delivered asynchronously, and a thread still running could accept.
function isStopped(pid) {
  return readdirSync(`/proc/${pid}/task`).every((t) => {
    try {
      const stat = readFileSync(`/proc/${pid}/task/${t}/stat`, 'utf8');
      return stat.slice(stat.lastIndexOf(')') + 2)[0] === 'T';
    } catch { return true; } /* a thread that ended */
  });
}
const ADDRESSES = 10;

// GET /api/v1/health on a raw socket from localAddress, once connected;
// resolves with the socket. onAnswer(status, body) at the answer's end.
function ask(port, localAddress, onAnswer) {
  return new Promise((resolve, reject) => {
    const s = net.connect({ port, host: '127.0.0.1', localAddress });
    let raw = '';
    s.setEncoding('utf8');
    s.on('data', (c) => { raw += c; });
    s.on('end', () => {
      const at = raw.indexOf('\r\n\r\n');
      let body = null;
      try { body = JSON.parse(raw.slice(at + 4)); } catch { /* not JSON */ }
      onAnswer(Number(raw.split(' ')[1]), body);
    });
    s.on('error', reject);
    s.on('connect', () => {
      s.write(`GET /api/v1/health HTTP/1.1\r\nHost: 127.0.0.1:${port}\r\nConnection: close\r\n\r\n`);
      resolve(s);
    });
  });
}

test('a backlog of 300 connections from 10 addresses: a newcomer is answered before most of them, with its exact body', { timeout: 60000 * SLOW }, async (t) => {
  const d = await startDaemon([]);
  const socks = [];
  let stopped = false;
  try {
    const answers = []; // 'flood' or 'newcomer', in the order the answers end
    const bodies = [];
    d.proc.kill('SIGSTOP');
    stopped = true;
    await until(() => isStopped(d.proc.pid), 5000 * SLOW, 'the daemon stopped');
    for (let i = 0; i < BACKLOG; i++) {
      socks.push(await ask(d.port, `127.3.0.${1 + (i % ADDRESSES)}`, (status) => {
        assert.equal(status, 200, 'a flood connection answered 200');
        answers.push('flood');
      }));
    }
    let newcomer = null;
    socks.push(await ask(d.port, '127.0.0.4', (status, body) => {
      newcomer = { status, body, rank: answers.length };
      answers.push('newcomer');
      bodies.push(body);
    }));
    d.proc.kill('SIGCONT');
    stopped = false;
    await until(() => answers.length === BACKLOG + 1, 30000 * SLOW, 'every connection answered');
    assert.equal(newcomer.status, 200);
    assert.deepEqual({ ...newcomer.body, uptime: 0 },
      { status: 'ok', uptime: 0, sessions: 0, max_sessions: 64, stream_clients: 0, max_streams: 256,
        pool_threads: 2, pool_queued: 0, api: 'v1' });
    // its address had none open or waiting: only the first connection of
    // each of the 10 flooding addresses came before it (a few more may end
    // first while it is being answered); in the kernel's order it was last
    assert.ok(newcomer.rank < BACKLOG / 2,
      `the newcomer answered after ${newcomer.rank} of the ${BACKLOG} that were waiting before it`);
    t.diagnostic(`the newcomer's answer ended after ${newcomer.rank} of the backlog's`);
    const m = (await req(d.base, 'GET', '/metrics')).text;
    // the backlog, the newcomer and this request
    assert.equal(metric(m, 'convsim_connections_accepted_total'), BACKLOG + 2);
    assert.equal(metric(m, 'convsim_connections_waiting_max'), BACKLOG + 1, 'all taken from the kernel at once');
    assert.equal(metric(m, 'convsim_connections_dropped_total'), 0);
  } finally {
    if (stopped) d.proc.kill('SIGCONT');
    for (const s of socks) s.destroy();
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
