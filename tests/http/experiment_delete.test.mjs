// SPDX-License-Identifier: GPL-3.0-or-later
// DELETE of an experiment stops it as DELETE of a sweep or a fit stops
// theirs (docs/api-jobs.md "Experiments"): 204 with no body, then the 404
// of an unknown id, whether it ran or had ended. A fresh session it
// created goes with it (as at its end, unless keep_session); a session the
// client made stays, its controls the client's again: an until before the
// experiment's end, and another experiment, are taken. Its files go too.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdtempSync, readdirSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, CHEAP, NO_FEED, SLOW } from './lib.mjs';

const LONG = [{ beta: 38, until: 300 }, { beta: 120, until: 600 }];

// DELETE path: 204 and empty, then a GET and a second DELETE are the 404
// of an unknown experiment
async function deleted(d, id) {
  const path = `/api/v1/experiments/${id}`;
  const del = await req(d.base, 'DELETE', path);
  assert.equal(del.status, 204, del.text);
  assert.equal(del.text, '');
  const again = await req(d.base, 'DELETE', path);
  assert.equal(again.status, 404, again.text);
  assert.equal(again.headers.get('content-type'), 'application/problem+json');
  assert.deepEqual(again.body, {
    type: '/api/v1/problems/not-found', title: 'Not found', status: 404,
    detail: `no experiment with id "${id}"`, instance: path,
  });
  const get = await req(d.base, 'GET', path);
  assert.equal(get.status, 404, get.text);
  assert.deepEqual(get.body, again.body);
}

test('a running experiment on a fresh session: DELETE stops it and deletes its session; kept: the session stays', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon([]);
  try {
    const ex = await req(d.base, 'POST', '/api/v1/experiments', { session: { ...NO_FEED, pace: 1 }, schedule: LONG });
    assert.equal(ex.status, 201, ex.text);
    await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${ex.body.id}`)).body.state === 'running',
      10000, 'running');
    await deleted(d, ex.body.id);
    assert.equal((await req(d.base, 'GET', `/api/v1/sessions/${ex.body.session}`)).status, 404);
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/experiments')).body.experiments, []);

    const kept = await req(d.base, 'POST', '/api/v1/experiments',
      { session: { ...NO_FEED, pace: 1 }, schedule: LONG, keep_session: true });
    assert.equal(kept.status, 201, kept.text);
    await deleted(d, kept.body.id);
    const s = await req(d.base, 'GET', `/api/v1/sessions/${kept.body.session}`);
    assert.equal(s.status, 200, s.text);
    assert.equal(s.body.experiment, null);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${kept.body.session}`)).status, 204);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test("a running experiment on the client's session: DELETE stops it, the session stays with its controls", { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon([]);
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const spath = `/api/v1/sessions/${s.body.id}`;
    const ex = await req(d.base, 'POST', '/api/v1/experiments', { session: s.body.id, schedule: LONG });
    assert.equal(ex.status, 201, ex.text);
    // once its worker has taken it (the 201 may come before), the
    // experiment holds the session: an earlier until and a second one refused
    await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${ex.body.id}`)).body.state === 'running',
      20000 * SLOW, 'the experiment running');
    assert.equal((await req(d.base, 'PATCH', spath, { until: 100 })).status, 409);
    assert.equal((await req(d.base, 'POST', '/api/v1/experiments', { session: s.body.id, schedule: LONG })).status, 409);
    await deleted(d, ex.body.id);
    const back = await req(d.base, 'GET', spath);
    assert.equal(back.status, 200, back.text);
    assert.equal(back.body.experiment, null);
    assert.equal(back.body.state, 'running');
    const p = await req(d.base, 'PATCH', spath, { until: 100 });
    assert.equal(p.status, 200, p.text);
    const next = await req(d.base, 'POST', '/api/v1/experiments', { session: s.body.id, schedule: LONG });
    assert.equal(next.status, 201, next.text);
    assert.equal((await req(d.base, 'DELETE', spath)).status, 204);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('an ended experiment: DELETE forgets it and its files, also after a restart', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsim-exp-delete-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  try {
    const ex = await req(d.base, 'POST', '/api/v1/experiments', { session: { ...CHEAP }, schedule: [{ beta: 38, until: 0.2 }] });
    assert.equal(ex.status, 201, ex.text);
    const id = ex.body.id;
    await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${id}`)).body.state === 'done', 20000, 'done');
    await until(() => existsSync(join(dir, `experiment-${id}.json`)), 5000, 'its result written');
    await deleted(d, id);
    await until(() => !existsSync(join(dir, `experiment-${id}.json`)) &&
      !readdirSync(join(dir, 'experiments')).includes(`${id}.bin`), 5000, 'its files removed');
    assert.equal((await d.stop()).code, 0, d.stderr());
    d = await startDaemon(args);
    assert.equal((await req(d.base, 'GET', `/api/v1/experiments/${id}`)).status, 404);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
