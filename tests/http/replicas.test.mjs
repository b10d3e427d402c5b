// SPDX-License-Identifier: GPL-3.0-or-later
// A daemon as one replica of several: --node-id in every id it makes (and
// its data directory kept to that node id), --peers gathering lists.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import Ajv2020 from 'ajv/dist/2020.js';
import { BIN, CHEAP, startDaemon, req } from './lib.mjs';

// Run the daemon to its exit (bad flags end it at once).
const refused = (args) => spawnSync(BIN, ['--port', '0', ...args], { encoding: 'utf8', timeout: 10000 });

test('--node-id is checked: 1 to 10 of a-z, 0-9, "-"', () => {
  for (const bad of ['Lab', 'a_b', '-a', 'abcdefghijk', '']) {
    const r = refused(['--node-id', bad]);
    assert.equal(r.status, 2, `--node-id "${bad}": ${r.stderr}`);
    assert.match(r.stderr, /--node-id must be 1 to 10 characters of a-z, 0-9 and '-'/);
  }
  for (const bad of ['ftp://h:1', 'http://127.0.0.1', 'http://127.0.0.1:1/x', 'http://no.such.host.invalid:1']) {
    const r = refused(['--peers', bad]);
    assert.equal(r.status, 2, `--peers ${bad}: ${r.stderr}`);
    assert.match(r.stderr, /--peers takes up to 32 http:\/\/HOST:PORT/);
  }
});

test('every id a replica makes carries its node id; without one ids stay 16 hex digits', async () => {
  const d = await startDaemon(['--node-id', 'lab-0a']);
  const e = await startDaemon([]);
  try {
    const ID = /^lab-0a-[0-9a-f]{12}$/;
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 0.1 });
    assert.equal(s.status, 201, s.text);
    assert.match(s.body.id, ID);
    assert.equal(s.headers.get('location'), `/api/v1/sessions/${s.body.id}`);
    const x = await req(d.base, 'POST', '/api/v1/experiments',
      { session: CHEAP, schedule: [{ beta: 38, until: 0.2 }] });
    assert.equal(x.status, 201, x.text);
    assert.match(x.body.id, ID);
    assert.match(x.body.session, ID);
    const w = await req(d.base, 'POST', '/api/v1/sweeps', { ...CHEAP, beta: [38], rotations: ['cw'], t_end: 0.5 });
    assert.equal(w.status, 202, w.text);
    assert.match(w.body.id, ID);
    assert.equal((await req(d.base, 'GET', `/api/v1/sweeps/${w.body.id}`)).status, 200);
    const plain = await req(e.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 0.1 });
    assert.match(plain.body.id, /^[0-9a-f]{16}$/);
  } finally {
    await d.stop();
    await e.stop();
  }
});

test('a data directory keeps its node id: another (or none) is refused', async () => {
  const dir = fs.mkdtempSync(path.join(os.tmpdir(), 'convsim-node-'));
  try {
    const d = await startDaemon(['--node-id', 'a1', '--data-dir', dir]);
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 0.1 });
    assert.equal((await d.stop()).code, 0);
    assert.equal(fs.readFileSync(path.join(dir, 'node-id'), 'utf8'), 'a1\n');
    for (const args of [['--node-id', 'b1'], []]) {
      const r = refused([...args, '--data-dir', dir]);
      assert.equal(r.status, 1, r.stderr);
      assert.match(r.stderr, /belongs to --node-id a1/);
    }
    const again = await startDaemon(['--node-id', 'a1', '--data-dir', dir]);
    assert.equal((await req(again.base, 'GET', `/api/v1/sessions/${s.body.id}`)).status, 200);
    await again.stop();
  } finally {
    fs.rmSync(dir, { recursive: true, force: true });
  }
});

test('--peers: lists gather every peer, ?scope=local does not, a dead or wrong peer is named', async () => {
  // a "peer" that answers something else than a list
  const odd = http.createServer((q, res) => { res.writeHead(200, { 'Content-Type': 'application/json' }); res.end('{"x":1}'); });
  await new Promise((r) => odd.listen(0, '127.0.0.1', r));
  const oddUrl = `http://127.0.0.1:${odd.address().port}`;
  const b = await startDaemon(['--node-id', 'b']);
  const a = await startDaemon(['--node-id', 'a', '--peers', `${b.base},${oddUrl}`]);
  try {
    const ids = [];
    for (const d of [a, b, b]) ids.push((await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 0.1 })).body.id);
    await req(b.base, 'POST', '/api/v1/sweeps', { ...CHEAP, beta: [38], rotations: ['cw'], t_end: 0.5 });
    const list = await req(a.base, 'GET', '/api/v1/sessions');
    assert.equal(list.status, 200);
    assert.deepEqual(list.body.sessions.map((s) => s.id).sort(), [...ids].sort());
    assert.deepEqual(list.body.unreachable, [{ peer: oddUrl, reason: 'its answer is not a sessions list' }]);
    // the merged, partial list is what the OpenAPI document says
    const doc = (await req(a.base, 'GET', '/api/v1/openapi.json')).body;
    const ajv = new Ajv2020({ strict: false, allErrors: true });
    ajv.addSchema({ ...doc, $id: 'https://convsim.invalid/openapi.json' });
    const SessionList = ajv.getSchema('https://convsim.invalid/openapi.json#/components/schemas/SessionList');
    assert.ok(SessionList(list.body), ajv.errorsText(SessionList.errors));
    assert.ok(doc.paths['/api/v1/sessions'].get.parameters.some((q) => q.name === 'scope'));
    assert.equal(list.headers.get('convsim-unreachable'), oddUrl);
    const local = await req(a.base, 'GET', '/api/v1/sessions?scope=local');
    assert.deepEqual(local.body.sessions.map((s) => s.id), [ids[0]]);
    assert.equal(local.headers.get('convsim-unreachable'), null);
    const csv = await req(a.base, 'GET', '/api/v1/sessions?format=csv');
    const rows = csv.text.trim().split('\n');
    assert.equal(rows.length, 4, csv.text);
    assert.match(rows[0], /^id,state,/);
    assert.deepEqual(rows.slice(1).map((l) => l.split(',')[0]).sort(), [...ids].sort());
    const sweeps = await req(a.base, 'GET', '/api/v1/sweeps');
    assert.equal(sweeps.body.sweeps.length, 1);
    assert.match(sweeps.body.sweeps[0].id, /^b-/);
    assert.deepEqual((await req(a.base, 'GET', '/api/v1/experiments')).body.experiments, []);
    const bad = await req(a.base, 'GET', '/api/v1/sessions?scope=every');
    assert.equal(bad.status, 400);
    assert.equal(bad.body.type, '/api/v1/problems/bad-query');
    assert.equal(bad.body.field, 'scope');
    await b.stop();
    const partial = await req(a.base, 'GET', '/api/v1/sessions');
    assert.equal(partial.status, 200);
    assert.deepEqual(partial.body.sessions.map((s) => s.id), [ids[0]]);
    assert.equal(partial.body.unreachable.length, 2);
    assert.equal(partial.body.unreachable[0].peer, b.base);
    assert.match(partial.body.unreachable[0].reason, /refused/i);
    assert.equal(partial.headers.get('convsim-unreachable'), `${b.base}, ${oddUrl}`);
  } finally {
    await a.stop();
    await b.stop();
    await new Promise((r) => odd.close(r));
  }
});

// What one peer sends cannot put into a listing what no replica's own holds:
// entries without their id, rows of other fields, text after a NUL. A peer
// answer of that shape is refused whole and the peer named; a well-formed
// CSV whose last row lacks its newline is taken, that row on a line of its own.
test('--peers: a peer\'s entries without ids or rows of other fields are refused whole, the peer named', async () => {
  const b = await startDaemon(['--node-id', 'b']);
  const header = (await req(b.base, 'GET', '/api/v1/sessions?scope=local&format=csv')).text;
  const fields = header.trim().split(',').length;
  const row = (id) => [id, 'running', ...Array(fields - 2).fill('')].join(',');
  let answer = {};
  const odd = http.createServer((q, res) => {
    const csv = q.url.includes('format=csv');
    res.writeHead(200, { 'Content-Type': csv ? 'text/csv' : 'application/json' });
    res.end(csv ? answer.csv : answer.json);
  });
  await new Promise((r) => odd.listen(0, '127.0.0.1', r));
  const oddUrl = `http://127.0.0.1:${odd.address().port}`;
  const a = await startDaemon(['--node-id', 'a', '--peers', oddUrl]);
  try {
    const id = (await req(a.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 0.1 })).body.id;
    // the session runs: its row's figures move, its id and the lines do not
    const lines = (text) => text.split('\n');
    for (const [json, csv] of [
      ['{"sessions":[{"id":"x-1","state":"running"},7]}', `${header}${row('x-1')}\nx-2,running\n`],
      ['{"sessions":[{"state":"running"}]}', `${header}${row('x-1')}\n\n${row('x-2')}\n`],
      ['{"sessions":[{"id":""}]}', `${header}${row('x-1')}\0${row('x-2')}\n`],
    ]) {
      answer = { json, csv };
      const list = await req(a.base, 'GET', '/api/v1/sessions');
      assert.equal(list.status, 200);
      assert.deepEqual(list.body.sessions.map((s) => s.id), [id], json);
      assert.deepEqual(list.body.unreachable, [{ peer: oddUrl, reason: 'its answer is not a sessions list' }]);
      const merged = await req(a.base, 'GET', '/api/v1/sessions?format=csv');
      assert.equal(merged.status, 200);
      assert.deepEqual(lines(merged.text).map((l) => l.split(',')[0]), ['id', id, ''], JSON.stringify(csv));
      assert.equal(merged.headers.get('convsim-unreachable'), oddUrl);
    }
    answer = { json: '{"sessions":[]}', csv: `${header}${row('x-1')}` };
    const merged = await req(a.base, 'GET', '/api/v1/sessions?format=csv');
    assert.deepEqual(lines(merged.text).slice(2), [row('x-1'), '']);
    assert.deepEqual(lines(merged.text).map((l) => l.split(',')[0]), ['id', id, 'x-1', '']);
    assert.equal(merged.headers.get('convsim-unreachable'), null);
  } finally {
    await a.stop();
    await b.stop();
    await new Promise((r) => odd.close(r));
  }
});
