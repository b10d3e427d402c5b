// SPDX-License-Identifier: GPL-3.0-or-later
// The memory a session reserves (docs/budgets.md "Memory"): the formula the
// page prints, read from the page and evaluated, equals the bytes the daemon
// reserves (convsim_memory_reserved_bytes) for sessions of several feeds,
// --ring and --history; and the page's MiB figures for the default scene
// and for 64 x 64 are that formula's at the default flags. So a change of
// what a session reserves fails here until the page says it.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { startDaemon, req, metric, SLOW } from './lib.mjs';

const PAGE = readFileSync(new URL('../../docs/budgets.md', import.meta.url), 'utf8');
const RING = 4096;      // the daemon's defaults (--ring, --history)
const HISTORY = 20000;

// The page's formula as a function of K, L, R, H: units (kB, B) become
// factors, "x" and juxtaposition multiplication; nothing else is allowed.
function pageFormula() {
  const m = PAGE.match(/^ {4}need = (.+)$/m);
  assert.ok(m, 'docs/budgets.md prints "    need = ..."');
  const expr = m[1]
    .replace(/\bkB\b/g, '* 1024').replace(/\bB\b/g, '').replace(/\bx\b/g, '*')
    .replace(/([\w)])\s+(?=[\w(])/g, '$1 * ');
  assert.match(expr, /^[\d\sKLRH+*()]+$/, `the formula reads as arithmetic: ${expr}`);
  return new Function('K', 'L', 'R', 'H', `return ${expr};`);
}

const mib = (bytes) => bytes / (1 << 20);

async function reserved(base) {
  const m = await (await fetch(base + '/metrics')).text();
  return metric(m, 'convsim_memory_reserved_bytes');
}

// Creates a session, returns the bytes it reserved, deletes it.
async function need(base, body) {
  const before = await reserved(base);
  const r = await req(base, 'POST', '/api/v1/sessions', { pace: 0.001, ...body });
  assert.equal(r.status, 201, r.text);
  const bytes = (await reserved(base)) - before;
  assert.equal((await req(base, 'DELETE', `/api/v1/sessions/${r.body.id}`)).status, 204);
  assert.equal(await reserved(base), before, 'given back');
  return bytes;
}

test('the page\'s formula is the reservation, for small flags', { timeout: 30000 * SLOW }, async () => {
  const f = pageFormula();
  const R = 40, H = 70;
  const d = await startDaemon(['--ring', String(R), '--history', String(H)]);
  try {
    const scenes = [[0, 0], [1, 2], [5, 8], [7, 3]];
    for (const [K, L] of scenes) {
      const scene = K ? { drive: 'ideal', columns: K, layers: L } : { drive: 'ideal', feed: false };
      assert.equal(await need(d.base, { scene }), f(K, L, R, H), `${K} x ${L}, --ring ${R} --history ${H}`);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('the page\'s MiB figures are the formula\'s at the default flags', { timeout: 30000 * SLOW }, async () => {
  const f = pageFormula();
  const m = PAGE.match(/([\d.]+) MiB for the default 5 x 8\s+session, ([\d.]+) MiB for 64 x 64/);
  assert.ok(m, 'the page gives the default session\'s and 64 x 64\'s need in MiB');
  assert.equal(m[1], mib(f(5, 8, RING, HISTORY)).toFixed(1), 'the default session');
  assert.equal(m[2], mib(f(64, 64, RING, HISTORY)).toFixed(0), '64 x 64');
  const d = await startDaemon([]);
  try {
    assert.equal(await need(d.base, {}), f(5, 8, RING, HISTORY), 'the default session, default flags');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
