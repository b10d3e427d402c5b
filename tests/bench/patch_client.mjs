// SPDX-License-Identifier: GPL-3.0-or-later
// A lean HTTP/1.1 client for the control benchmarks (controls.mjs,
// kill_probe.mjs): one keep-alive socket, one request at a time, the
// answer's status and body read by Content-Length. fetch() cost this
// machine's node about 1.5 ms of CPU a PATCH, three times what the daemon
// spent answering it, so with both on 2 shared cores the benchmark
// measured its own client; this one costs a small fraction of that.
// CLIENT=fetch in the benchmarks uses fetch() instead, for comparison.
import net from 'node:net';

export class LeanClient {
  constructor(port) {
    this.port = port;
    this.sock = null;
    this.buf = Buffer.alloc(0);
    this.wait = null; // {resolve, reject} of the request in flight
  }

  connect() {
    const sock = net.connect({ port: this.port, host: '127.0.0.1', noDelay: true });
    sock.on('data', (b) => { this.buf = this.buf.length ? Buffer.concat([this.buf, b]) : b; this.parse(); });
    const gone = (e) => {
      if (this.sock === sock) this.sock = null;
      const w = this.wait;
      this.wait = null;
      if (w) w.reject(e || new Error('closed before the answer'));
    };
    sock.on('error', gone);
    sock.on('close', () => gone(null));
    this.sock = sock;
    this.buf = Buffer.alloc(0);
  }

  // The answer in this.buf once whole: resolves the request in flight.
  parse() {
    const head = this.buf.indexOf('\r\n\r\n');
    if (head < 0 || !this.wait) return;
    const text = this.buf.subarray(0, head).toString('latin1');
    const m = /\r\ncontent-length:\s*(\d+)/i.exec(text);
    const len = m ? Number(m[1]) : 0;
    if (this.buf.length < head + 4 + len) return;
    const status = Number(text.slice(9, 12));
    const body = this.buf.subarray(head + 4, head + 4 + len).toString('utf8');
    this.buf = this.buf.subarray(head + 4 + len);
    const close = /\r\nconnection:\s*close/i.test(text);
    const w = this.wait;
    this.wait = null;
    if (close) { const s = this.sock; this.sock = null; s.destroy(); }
    w.resolve({ status, body });
  }

  // method path (JSON body or undefined): {status, body (text)}; rejects
  // when the connection ends first (a killed daemon: no answer).
  request(method, path, json) {
    if (!this.sock) this.connect();
    const body = json === undefined ? '' : JSON.stringify(json);
    return new Promise((resolve, reject) => {
      this.wait = { resolve, reject };
      this.sock.write(`${method} ${path} HTTP/1.1\r\nHost: 127.0.0.1:${this.port}\r\n` +
        (json === undefined ? '' : 'Content-Type: application/json\r\n') +
        `Content-Length: ${Buffer.byteLength(body)}\r\n\r\n${body}`);
    });
  }

  close() {
    if (this.sock) this.sock.destroy();
    this.sock = null;
  }
}

// A client of the kind CLIENT names (lean, the default, or fetch) for the
// daemon at port: request(method, path, json) -> {status, body}.
export function client(port, kind = process.env.CLIENT || 'lean') {
  if (kind === 'lean') return new LeanClient(port);
  const base = `http://127.0.0.1:${port}`;
  return {
    async request(method, path, json) {
      const init = { method };
      if (json !== undefined) {
        init.headers = { 'Content-Type': 'application/json' };
        init.body = JSON.stringify(json);
      }
      const r = await fetch(base + path, init);
      return { status: r.status, body: await r.text() };
    },
    close() {},
  };
}
