// SPDX-License-Identifier: GPL-3.0-or-later
// A LIGGGHTS session's admission (docs/dem.md "Admission and cost"), with a
// stand-in bed program that never answers (no LIGGGHTS needed): a create
// whose client leaves while the bed settles ends its bed process and
// frees the one DEM slot at once (not after --dem-timeout), and a bed whose
// DEM step makes it too dear is refused with 422 on params.k_c, with the
// estimate, before any bed process starts.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { chmodSync, existsSync, mkdtempSync, readFileSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, SLOW } from './lib.mjs';

const dir = mkdtempSync(join(tmpdir(), 'convsim-dem-admit-'));
const PIDS = join(dir, 'pids');
const BED = join(dir, 'bed');
// a bed program that notes its pid and never answers (a bed that settles for ever)
writeFileSync(BED, `#!/bin/sh\necho $$ >> '${PIDS}'\nexec sleep 600\n`);
chmodSync(BED, 0o755);

const pids = () => (existsSync(PIDS) ? readFileSync(PIDS, 'utf8').trim().split('\n').filter(Boolean).map(Number) : []);
const alive = (pid) => { try { process.kill(pid, 0); return true; } catch { return false; } };

let d;
before(async () => { d = await startDaemon(['--dem-bed', BED, '--max-dem-sessions', '1']); });
after(async () => {
  for (const pid of pids()) if (alive(pid)) process.kill(pid, 'SIGKILL');
  await d.stop();
});

const BODY = { scene: { feed_model: 'liggghts', layers: 1 }, pace: 'max', until: 1 };

// A create the client gives up on once its bed process has started.
async function abandonedCreate(nth) {
  const ac = new AbortController();
  const pending = fetch(`${d.base}/api/v1/sessions`, {
    method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(BODY), signal: ac.signal,
  }).then((r) => ({ status: r.status }), (e) => ({ aborted: e.name === 'AbortError' }));
  const answered = await Promise.race([pending, until(async () => pids().length >= nth, 10000 * SLOW, 'the bed process started')]);
  assert.equal(answered, true, `the create answered before its bed settled: ${JSON.stringify(answered)}`);
  ac.abort();
  assert.deepEqual(await pending, { aborted: true });
  return pids()[nth - 1];
}

test('an abandoned LIGGGHTS create ends its bed process and frees the DEM slot at once', { timeout: 30000 * SLOW }, async () => {
  const first = await abandonedCreate(1);
  // the daemon sees the client go, ends the bed and releases the slot:
  // well before --dem-timeout (300 s)
  await until(async () => !alive(first), 5000 * SLOW, `bed process ${first} ended`);
  assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing was created');
  // the one slot is free: the next create is admitted (its bed starts)
  // instead of 429
  const second = await abandonedCreate(2);
  await until(async () => !alive(second), 5000 * SLOW, `bed process ${second} ended`);
});

test('a bed whose DEM step makes it too dear is refused with 422 on params.k_c and the estimate', { timeout: 20000 * SLOW }, async () => {
  const n0 = pids().length;
  // k/m = k_c / m_n = 1e14 1/s^2: 92 grains at DEM steps of 5.3e-9 s
  const r = await req(d.base, 'POST', '/api/v1/sessions',
    { ...BODY, params: { k_c: 1e10, m_n: 1e-4 } });
  assert.equal(r.status, 422, r.text);
  assert.equal(r.headers.get('content-type'), 'application/problem+json');
  assert.equal(r.body.field, 'params.k_c');
  assert.match(r.body.detail, /^the LIGGGHTS bed of 92 grains at k_c\/m_n = 1e\+14 1\/s\^2 takes DEM steps of 5\.3e-09 s: about 5\.5\de\+03 CPU s a simulated second, more than --max-dem-cost 1000; k_c at most 3\.\d+e\+08 N\/m at this m_n/);
  assert.equal(r.body.min, 100);
  assert.ok(r.body.max > 3e8 && r.body.max < 3.5e8, `max ${r.body.max}`);
  assert.equal(pids().length, n0, 'no bed process started');
  assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0);
});
