// SPDX-License-Identifier: GPL-3.0-or-later
// At most --max-settling requests settle simulations in their own thread
// at once (docs/load.md "Creations that settle"): a session's
// creation settles its steady start and runs its probe before it is
// answered, an identification or a closed loop measures its scene at the
// request. Beyond, a request waits at most 250 ms for a slot (a burst of
// default creations queues through), then is answered 503 naming the
// limit, and changes nothing; the slot comes back on every path (an answer, a
// failed settling, a client that left). A 64 x 64 scene settles for about
// a CPU second here, so a burst of them overlaps whatever the machine's
// load: with no slot taken (the build before) all 8 of the first test are
// created; tests/bench/settle_flood.mjs measures what that did to a
// running paced session.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { mkdtempSync, readdirSync, readFileSync, rmSync } from 'node:fs';
import { cpus, tmpdir } from 'node:os';
import { join } from 'node:path';
import { BIN, startDaemon, req, metric, until, SLOW } from './lib.mjs';

const LARGE = { scene: { columns: 64, layers: 64 }, pace: 0.01, sample_rate: 1 };
const metrics = async (d) => (await req(d.base, 'GET', '/metrics')).text;
const busy = (limit, instance) => ({
  type: '/api/v1/problems/unavailable', title: 'Service unavailable', status: 503,
  detail: `as many requests as may settle simulations at once are settling (${limit}, --max-settling), ` +
    'and none ended within 250 ms: a session\'s creation (its steady start and its probe) and an ' +
    'experiment\'s measurements each take a core while they settle; nothing was created, retry in a second',
  instance, budget: 'settling', limit,
});
function assertBusy(r, limit, instance) {
  assert.equal(r.status, 503, r.text);
  assert.equal(r.headers.get('content-type'), 'application/problem+json');
  assert.equal(r.headers.get('retry-after'), '1');
  assert.deepEqual(r.body, busy(limit, instance));
}
const ids = async (d) => (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.map((s) => s.id).sort();

test('a burst of 8 large creations under --max-settling 2: 2 settle, 6 get 503 after waiting 250 ms and leave nothing', { timeout: 120000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-settling-'));
  const d = await startDaemon(['--max-settling', '2', '--ring', '64', '--data-dir', dir]);
  try {
    const running = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1 });
    assert.equal(running.status, 201, running.text);
    const before = await metrics(d);
    const t0 = performance.now();
    const answers = await Promise.all(Array.from({ length: 8 }, async () => {
      const r = await req(d.base, 'POST', '/api/v1/sessions', LARGE);
      return { ...r, ms: performance.now() - t0 };
    }));
    const created = answers.filter((a) => a.status === 201), refused = answers.filter((a) => a.status !== 201);
    assert.equal(created.length, 2, answers.map((a) => `${a.status} ${a.text.slice(0, 120)}`).join('\n'));
    for (const r of refused) assertBusy(r, 2, '/api/v1/sessions');
    // refused after the wait, not after the settling: every 503 was in
    // before either settling ended, none before 250 ms
    const firstCreated = Math.min(...created.map((a) => a.ms));
    for (const r of refused) assert.ok(r.ms < firstCreated && r.ms >= 250, `a 503 after ${r.ms} ms, the first 201 after ${firstCreated} ms`);
    const after = await metrics(d);
    assert.equal(metric(after, 'convsim_settling_max'), 2);
    assert.equal(metric(after, 'convsim_settling_refused_total'), 6);
    assert.equal(metric(after, 'convsim_settling'), 0);
    assert.equal(metric(after, 'convsim_sessions_created_total'), metric(before, 'convsim_sessions_created_total') + 2);
    // nothing of the refused ones: not listed, no directory, no memory held
    const expected = [running.body.id, ...created.map((a) => a.body.id)].sort();
    assert.deepEqual(await ids(d), expected);
    assert.deepEqual(readdirSync(join(dir, 'sessions')).sort(), expected);
    for (const a of created) assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${a.body.id}`)).status, 204);
    assert.equal(metric(await metrics(d), 'convsim_memory_reserved_bytes'), metric(before, 'convsim_memory_reserved_bytes'));
    // the slots are back: a default creation and a large one
    for (const body of [{ pace: 1 }, LARGE]) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', body);
      assert.equal(r.status, 201, r.text);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});

test('a burst of 12 default creations under --max-settling 1: all 201, queued through the wait', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon(['--max-settling', '1']);
  try {
    const answers = await Promise.all(Array.from({ length: 12 }, () => req(d.base, 'POST', '/api/v1/sessions', { pace: 1 })));
    const statuses = answers.map((a) => a.status), text = answers.map((a) => a.text.slice(0, 160)).join('\n');
    // a sanitizer build (SLOW > 1, make check-ci beside another file)
    // settles several times slower, so the queue may outlast the 250-ms
    // wait: there every answer is a creation or the settling budget's 503
    if (SLOW === 1) assert.deepEqual(statuses, Array(12).fill(201), text);
    const refused = answers.filter((a) => a.status !== 201);
    for (const a of refused) {
      assert.equal(a.status, 503, text);
      assert.equal(a.body.budget, 'settling', text);
    }
    assert.ok(refused.length < 12, text);
    const m = await metrics(d);
    assert.equal(metric(m, 'convsim_settling_max'), 1);
    assert.equal(metric(m, 'convsim_settling_refused_total'), refused.length);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('the slot comes back after a settling that fails and after a client that left; an experiment\'s measurements take it too', { timeout: 120000 * SLOW }, async () => {
  const d = await startDaemon(['--max-settling', '1', '--ring', '64']);
  const settling = async () => metric(await metrics(d), 'convsim_settling');
  try {
    // rk4 at a step too large for the feed's contact: it diverges while it settles
    const bad = await req(d.base, 'POST', '/api/v1/sessions', { integrator: { method: 'rk4', dt: 0.0018 } });
    assert.equal(bad.status, 422, bad.text);
    assert.match(bad.body.detail, /diverged at t = -/);
    assert.equal(await settling(), 0);
    const ok = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1 });
    assert.equal(ok.status, 201, ok.text);

    // a large creation whose client leaves while it settles: the settling
    // goes on to its end (the core's cannot be cut short) and holds the
    // slot until then, an experiment's measurements are refused meanwhile
    const leaving = new AbortController();
    const left = fetch(`${d.base}/api/v1/sessions`, {
      method: 'POST', headers: { 'Content-Type': 'application/json' }, body: JSON.stringify(LARGE),
      signal: leaving.signal,
    }).catch((e) => e);
    await until(async () => (await settling()) === 1, 10000, 'the large creation settling');
    leaving.abort();
    assert.equal((await left).name, 'AbortError');
    // a closed loop on the running session: its curve is measured in the
    // request, before it attaches
    const loop = { control: { setpoint: [{ v: 0.10, until: 2 }], controller: { kp: 2, ki: 800 } } };
    const exp = await req(d.base, 'POST', '/api/v1/experiments', { ...loop, session: ok.body.id });
    assertBusy(exp, 1, '/api/v1/experiments');
    assertBusy(await req(d.base, 'POST', '/api/v1/sessions', { pace: 1 }), 1, '/api/v1/sessions');
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/experiments')).body.experiments, []);
    await until(async () => (await settling()) === 0, 30000, 'the settling over');

    // a closed loop out of the machine's reach is refused after its curve
    // was measured (422), and gives the slot back; then one is created
    const far = await req(d.base, 'POST', '/api/v1/experiments',
      { control: { ...loop.control, setpoint: [{ v: 5, until: 2 }] } });
    assert.equal(far.status, 422, far.text);
    assert.equal(far.body.field, 'control.setpoint[0].v');
    assert.equal(await settling(), 0);
    const run = await req(d.base, 'POST', '/api/v1/experiments', loop);
    assert.equal(run.status, 201, run.text);
    const m = await metrics(d);
    assert.equal(metric(m, 'convsim_settling'), 0);
    assert.equal(metric(m, 'convsim_settling_max'), 1);
    assert.equal(metric(m, 'convsim_settling_refused_total'), 2);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('docs/load.md shows the 503 the daemon answers (with --max-settling 1)', () => {
  const doc = readFileSync(new URL('../../docs/load.md', import.meta.url), 'utf8');
  const section = doc.slice(doc.indexOf('## Creations that settle'));
  const block = section.match(/```json\n([\s\S]*?)```/);
  assert.ok(block, 'a json block in "Creations that settle"');
  assert.deepEqual(JSON.parse(block[1]), busy(1, '/api/v1/sessions'));
});

test('--max-settling: half the cores by default, 1 to 1024', () => {
  const h = spawnSync(BIN, ['--help'], { encoding: 'utf8' });
  assert.equal(h.status, 0);
  const m = h.stdout.match(/--max-settling N .*\n.*\n.*\(default (\d+): half the cores, rounded up\)/);
  assert.ok(m, h.stdout);
  assert.equal(Number(m[1]), Math.ceil(cpus().length / 2));
  for (const v of ['0', '1025', '1.5']) {
    const bad = spawnSync(BIN, ['--port', '0', '--max-settling', v], { encoding: 'utf8' });
    assert.equal(bad.status, 2, v);
    assert.match(bad.stderr, /--max-settling must be an integer in \[1, 1024\]/);
  }
});
