// SPDX-License-Identifier: GPL-3.0-or-later
// The daemon's CPU time for reading a large request body (api/json_check.c,
// then cJSON): 1 MiB bodies of many member names, sent to POST
// /api/v1/sessions one after the other, with the daemon's user + system
// CPU time from /proc before and after. Prints a Markdown table and the
// command that made it.
//
//   CONVSIMD=$PWD/build/convsimd node tests/bench/body_parse.mjs
//
// REQUESTS (default 20) per body. The bodies: 131,000 distinct names of
// 1 to 3 characters; the same in an object nested 32 deep; 8,192 distinct
// names with one 32-bit FNV-1a hash of their code points (the hash
// json_check.c sorts by first), so that only their text tells them apart.
import { startDaemon, processCpu as cpuSeconds } from '../http/lib.mjs';

const REQUESTS = Number(process.env.REQUESTS || 20);
const MIB = 1 << 20;
const ALPHABET = 'abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789';

// Distinct names (shortest first) as an object's members "k":0, until
// the text would pass `room` bytes.
function manyNames(room) {
  const parts = [];
  let used = 2;
  for (let i = 0; ; i++) {
    let name = '';
    let k = i;
    do { name += ALPHABET[k % 62]; k = Math.floor(k / 62) - 1; } while (k >= 0);
    const member = `"${name}":0`;
    if (used + member.length + 1 > room) break;
    parts.push(member);
    used += member.length + 1;
  }
  return { text: `{${parts.join(',')}}`, names: parts.length };
}

// json_check.c's hash of a name: FNV-1a 32 over each code point's 4 bytes.
function fnvStep(h, text) {
  for (const ch of text) {
    const cp = ch.codePointAt(0);
    for (let k = 0; k < 4; k++) {
      h = (h ^ ((cp >>> (8 * k)) & 0xff)) >>> 0;
      h = Math.imul(h, 16777619) >>> 0;
    }
  }
  return h;
}

// 2^stages names with one hash: at each stage two 6-character blocks that
// take the running hash to the same value (a birthday search), so every
// choice of one block per stage gives the same hash.
function collidingNames(stages) {
  let h = 2166136261;
  let x = 2463534242; // xorshift32: the same names on every run
  const random = () => { x ^= x << 13; x ^= x >>> 17; x ^= x << 5; return (x >>> 0) % 62; };
  const pairs = [];
  for (let s = 0; s < stages; s++) {
    const seen = new Map();
    for (;;) {
      let block = '';
      for (let n = 0; n < 6; n++) block += ALPHABET[random()];
      const to = fnvStep(h, block);
      const other = seen.get(to);
      if (other !== undefined && other !== block) { pairs.push([other, block]); h = to; break; }
      seen.set(to, block);
    }
  }
  const members = [];
  for (let m = 0; m < 1 << stages; m++) {
    members.push(`"${pairs.map((p, s) => p[(m >> s) & 1]).join('')}":0`);
  }
  return { text: `{${members.join(',')}}`, names: members.length };
}

const flat = manyNames(MIB);
const depth = 32;
const inner = manyNames(MIB - depth * 6);
const nested = { text: '{"a":'.repeat(depth) + inner.text + '}'.repeat(depth), names: inner.names };
const colliding = collidingNames(13);
const bodies = [
  ['distinct names, one object', flat],
  [`distinct names, an object ${depth} deep`, nested],
  ['names of one hash, one object', colliding],
];

const d = await startDaemon(['--max-body', String(MIB)]);
const rows = [];
try {
  for (const [what, body] of bodies) {
    if (Buffer.byteLength(body.text) > MIB) throw new Error(`${what}: over 1 MiB`);
    const statuses = new Set();
    const before = cpuSeconds(d.proc.pid);
    const t0 = performance.now();
    for (let i = 0; i < REQUESTS; i++) {
      const r = await fetch(`${d.base}/api/v1/sessions`, {
        method: 'POST', headers: { 'Content-Type': 'application/json' }, body: body.text,
      });
      await r.text();
      statuses.add(r.status);
    }
    const wall = (performance.now() - t0) / REQUESTS;
    const cpu = (cpuSeconds(d.proc.pid) - before) / REQUESTS;
    rows.push(`| ${what} | ${Buffer.byteLength(body.text)} | ${body.names} | ${[...statuses].join(', ')} ` +
      `| ${(cpu * 1000).toFixed(1)} | ${wall.toFixed(1)} |`);
  }
} finally {
  await d.stop();
}
console.log(`body check: daemon CPU per request, ${REQUESTS} requests per body (POST /api/v1/sessions)\n`);
console.log('| body | bytes | names | status | daemon CPU ms / request | wall ms / request |');
console.log('|---|---|---|---|---|---|');
for (const r of rows) console.log(r);
console.log(`\ncommand: CONVSIMD=${process.env.CONVSIMD ? '$PWD/build/convsimd' : 'build/convsimd'} ` +
  `REQUESTS=${REQUESTS} node tests/bench/body_parse.mjs`);
