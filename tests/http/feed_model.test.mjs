// SPDX-License-Identifier: GPL-3.0-or-later
// scene.feed_model in the daemon: the settings list it (column|liggghts),
// the column model is the default and runs; liggghts, whose bed runs in a
// bed process (build/convsim-bed, tests/dem/session.test.mjs), is refused
// with a problem naming the field and the choices it takes where the
// daemon finds no bed program (column, auto), and always in sweeps (which
// run many scenes at once: column); nothing is created then.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, openStream, SLOW } from './lib.mjs';

// The stream's first record (hello), NDJSON.
async function hello(base, id) {
  const ac = new AbortController();
  let first;
  for await (const rec of openStream(base, `/api/v1/sessions/${id}/stream?format=ndjson`, {}, ac.signal)) {
    first = rec;
    break;
  }
  ac.abort();
  return first;
}

let d;
// a daemon that finds no bed program (as one built without LIGGGHTS)
before(async () => { d = await startDaemon(['--dem-bed', '/nonexistent/convsim-bed']); });
after(async () => { await d.stop(); });

test('feed_model: listed, column by default, liggghts refused with 422 and nothing created', { timeout: 20000 * SLOW }, async () => {
  const settings = (await req(d.base, 'GET', '/api/v1/presets')).body.settings;
  const fm = settings.find((s) => s.name === 'feed_model');
  assert.ok(fm, 'feed_model in the settings');
  assert.equal(fm.group, 'scene');
  const n0 = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length;
  const r = await req(d.base, 'POST', '/api/v1/sessions', { scene: { feed_model: 'liggghts' } });
  assert.equal(r.status, 422);
  assert.equal(r.headers.get('content-type'), 'application/problem+json');
  assert.equal(r.body.field, 'scene.feed_model');
  assert.deepEqual(r.body.choices, ['column', 'auto']);
  assert.ok(!('min' in r.body) && !('max' in r.body), r.text);
  assert.match(r.body.detail, /needs the bed program \/nonexistent\/convsim-bed, which this daemon does not find/);
  assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, n0);
  const sw = await req(d.base, 'POST', '/api/v1/sweeps', { beta: [30], scene: { feed_model: 'liggghts' } });
  assert.equal(sw.status, 422);
  assert.equal(sw.body.field, 'scene.feed_model');
  assert.match(sw.body.detail, /must be column in sweeps, fits and experiments/);
  assert.deepEqual(sw.body.choices, ['column']);
  const ok = await req(d.base, 'POST', '/api/v1/sessions', { scene: { feed_model: 'column' }, pace: 1 });
  assert.equal(ok.status, 201);
});

test('status.feed_warning: the model check\'s short sentence where the scene is not checked against DEM, null where it is', { timeout: 20000 * SLOW }, async () => {
  // a depth the map has not (3 grains): not checked
  const a = await req(d.base, 'POST', '/api/v1/sessions', { scene: { layers: 3 }, pace: 1 });
  assert.equal(a.status, 201);
  const sa = (await req(d.base, 'GET', `/api/v1/sessions/${a.body.id}`)).body.status;
  assert.equal(sa.feed_warning, 'not checked against DEM for 3-layer beds: nearest checked bed is 2 layers, czubak2016 against glass');
  const b = await req(d.base, 'POST', '/api/v1/sessions', { preset: 'liggghts-bed4', pace: 1 });
  const sb = (await req(d.base, 'GET', `/api/v1/sessions/${b.body.id}`)).body.status;
  assert.equal(sb.feed_warning, null);
  assert.equal(sb.model_checked, true);
  // the stream's first record says the same
  const ha = await hello(d.base, a.body.id), hb = await hello(d.base, b.body.id);
  assert.equal(ha.type, 'hello');
  assert.equal(ha.feed_warning, sa.feed_warning);
  assert.equal(ha.model_checked, false);
  assert.equal(hb.type, 'hello');
  assert.equal(hb.feed_warning, null);
  assert.equal(hb.model_error, sb.model_error);
});
