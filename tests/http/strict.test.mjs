// SPDX-License-Identifier: GPL-3.0-or-later
// Strict reading of requests: a body JSON forbids (RFC 8259, I-JSON RFC
// 7493) is refused with 400 and the byte where it goes wrong, whichever
// route reads it; a duplicated Host or Content-Length header is refused
// with 400 (RFC 9112); a very long query still gets an answer (431).
// Nothing refused changes anything.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { readFileSync } from 'node:fs';
import { startDaemon, req, rawRequest, CHEAP, NO_FEED, SLOW } from './lib.mjs';

const bytes = (...parts) => Buffer.concat(parts.map((p) => (typeof p === 'string' ? Buffer.from(p, 'latin1') : Buffer.from(p))));

// [body, position of the fault, field (a duplicated name) or null]
const BAD = [
  ['{"pace":01}', 8, null],
  ['{"pace":1.}', 8, null],
  ['{"pace":-}', 9, null],
  ['{"pace":1e}', 8, null],
  ['{"preset":"czubak2016\u0000x"}', 21, null],
  ['{"preset":"czubak\u00012016"}', 17, null],
  ['{"preset":"czu\tbak"}', 14, null],
  [bytes('{"preset":"czubak', [0xff], '2016"}'), 17, null],
  [bytes('{"preset":"', [0xc0, 0xaf], '"}'), 11, null],
  [bytes('{"preset":"', [0xed, 0xa0, 0x80], '"}'), 11, null],
  [bytes('{"preset":"abc', [0xe2, 0x82], '"}'), 14, null],
  ['{"preset":"\\ud800"}', 11, null],
  ['{"preset":"\\udc00\\ud800"}', 11, null],
  ['{"preset":"\\x41"}', 11, null],
  ['{"pace":1,"pace":"max"}', 10, 'pace'],
  ['{"pace":1,"p\\u0061ce":2}', 10, 'p\\u0061ce'],
  ['{"scene":{"columns":1,"layers":2,"columns":3}}', 33, 'columns'],
  ['{"pace":1,}', 10, null],
  ['{"pace":1} x', 11, null],
  ['{"pace":true1}', 12, null],
  ['{\'pace\':1}', 1, null],
];

test('a body JSON forbids is refused with 400 and its position on every route; nothing is created', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const post = (path, body, method = 'POST') => rawRequest(d.port, bytes(`${method} ${path} HTTP/1.1\r\n` +
      `Host: 127.0.0.1:${d.port}\r\nContent-Type: application/json\r\nContent-Length: ${Buffer.from(body).length}`), body);
    for (const [body, position, field] of BAD) {
      const r = await post('/api/v1/sessions', body);
      const shown = Buffer.from(body).toString('latin1');
      assert.equal(r.status, 400, `${shown}: ${r.raw.toString('latin1')}`);
      assert.match(r.headers['content-type'], /^application\/problem\+json/);
      const p = JSON.parse(r.body.toString('utf8'));
      assert.equal(p.type, '/api/v1/problems/malformed-json', shown);
      assert.equal(p.position, position, `${shown}: ${p.detail}`);
      assert.match(p.detail, new RegExp(`at byte ${position}$`), shown);
      assert.equal(p.field, field ?? undefined, shown);
    }
    // the other readers of a body go through the same check
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    for (const [method, path] of [['PATCH', `/api/v1/sessions/${s.body.id}`], ['POST', '/api/v1/sweeps'],
      ['POST', '/api/v1/experiments'], ['POST', '/api/v1/fits']]) {
      const r = await post(path, '{"beta":30,"beta":40}', method);
      assert.equal(r.status, 400, `${method} ${path}: ${r.raw.toString('latin1')}`);
      assert.equal(JSON.parse(r.body.toString('utf8')).position, 11, path);
    }
    // what JSON allows still passes: escapes, a paired surrogate, exponents, -0
    const ok = await post('/api/v1/sessions', bytes('{"preset":"czubak2016","pace":1e0,"sample_rate":2.5E2,' +
      '"scene":{"drive":"ide\\u0061l","columns":1,"layers":2}}'));
    assert.equal(ok.status, 201, ok.raw.toString('latin1'));
    const names = await post('/api/v1/sessions', '{"params":{"\\ud83d\\ude00":1,"\\u00e9":1}}');
    assert.equal(names.status, 422, 'two distinct names decode apart and reach the member check');
    const list = await req(d.base, 'GET', '/api/v1/sessions');
    assert.equal(list.body.sessions.length, 2, 'only the two valid sessions exist');
    const g = await req(d.base, 'GET', `/api/v1/sessions/${s.body.id}`);
    assert.notEqual(g.body.status.beta_target, 40, 'the refused PATCH changed nothing');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

// A string whose decoded value holds U+0000 (written \u0000, which JSON
// allows) on every route that reads a body: cJSON's C strings used to cut
// it there, so "czubak2016\u0000x" was read as czubak2016. [method, path
// (SID: the session's), body]; the fault is at the backslash.
const NUL = [
  ['POST', '/api/v1/sessions', '{"preset":"czubak2016\\u0000x"}'],
  ['POST', '/api/v1/sessions', '{"params":{"rotation":"ccw\\u0000garbage"}}'],
  ['POST', '/api/v1/sessions', '{"pace\\u0000x":1}'],
  ['PATCH', '/api/v1/sessions/SID', '{"rotation":"ccw\\u0000garbage"}'],
  ['POST', '/api/v1/sweeps', '{"rotations":["cw\\u0000x"],"t_end":0.5}'],
  ['POST', '/api/v1/fits', '{"free":["e\\u0000x"],"peaks":[{"rotation":"cw","beta":38}]}'],
  ['POST', '/api/v1/experiments', '{"session":{"pace":"max\\u0000"},"schedule":[{"beta":38,"until":1}]}'],
  ['POST', '/api/v1/sessions', '{"preset":"czubak2016","scene":{"drive":"ideal\\u0000"}}'],
];

test('a string holding U+0000 (\\u0000) is 400 with its position on every route; nothing changes', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1, params: { rotation: 'cw' } });
    assert.equal(s.status, 201, s.text);
    for (const [method, template, body] of NUL) {
      const path = template.replace('SID', s.body.id);
      const r = await req(d.base, method, path, body);
      const position = Buffer.from(body).indexOf('\\u0000');
      assert.equal(r.status, 400, `${method} ${path} ${body}: ${r.text}`);
      assert.match(r.headers.get('content-type'), /^application\/problem\+json/);
      assert.deepEqual(r.body, {
        type: '/api/v1/problems/malformed-json', title: 'Malformed JSON', status: 400,
        detail: 'the request body is refused: a string may not hold U+0000 (\\u0000) (no member ' +
          `takes it; it would cut the string short) at byte ${position}`,
        instance: path, position,
      }, `${method} ${path} ${body}`);
    }
    assert.equal(NUL[0][2].indexOf('\\u0000'), 21, 'the first fault is at byte 21');
    // nothing was created or changed
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 1);
    for (const kind of ['sweeps', 'fits', 'experiments']) {
      assert.equal((await req(d.base, 'GET', `/api/v1/${kind}`)).body[kind].length, 0, kind);
    }
    const g = await req(d.base, 'GET', `/api/v1/sessions/${s.body.id}`);
    assert.equal(g.body.status.rotation, 'cw', 'the refused PATCH changed nothing');
    // other escapes, \u0001 among them, still decode and reach the API
    const one = await req(d.base, 'POST', '/api/v1/sessions', '{"preset":"czubak2016\\u0001x"}');
    assert.equal(one.status, 422, one.text);
    assert.equal(one.body.field, 'preset');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

// The same name twice in one object, at every depth and after many other
// names, is refused as it was before the check became linear: the first
// fault in the text wins, whether a duplicate or another.
const DUP = [
  // [body, position, field]
  ['{"pace":1,"pace":2}', 10, 'pace'],
  ['{"scene":{"drive":"ideal","layers":2,"drive":"ideal"}}', 37, 'drive'],
  ['{"a":{"b":{"c":{"d":{"e":1,"f":2,"e":3}}}}}', 33, 'e'],
  ['{"a":{"x":1,"x":2},"a":3}', 12, 'x'], // the inner one comes first
  ['{"a":1,"b":{"x":1,"x":2},"a":3}', 18, 'x'],
  ['{"a":1,"a":{"x":1,"x":2}}', 7, 'a'], // the outer one comes first
  ['{"b":1,"a":1,"b":1,"a":1}', 13, 'b'], // two names twice: the earlier
  ['{"a":1,"b":1,"a":1,"b":1}', 13, 'a'],
  ['{"a":1,"a":01}', 7, 'a'], // before a bad number
  ['{"a":1,"b":01,"a":1}', 11, null], // after one
  ['{"a":1,"b":{"c":[1,{"d":1,"d":2}]},"a":2}', 26, 'd'],
  ['{"\\u00e9":1,"\\u00E9":2}', 12, '\\u00E9'],
  ['{"\\ud83d\\ude00":1,"\\ud83d\\ude00":2}', 18, '\\ud83d\\ude00'],
];

test('a name given twice is refused at its second place at any depth, also among 20,000 names', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const many = Array.from({ length: 20000 }, (_, i) => `"n${i}":0`);
    const manyBody = `{"scene":{"inner":{${many.join(',')},"n12345":1}}}`;
    // ZjEppR and yjepeD have one 32-bit FNV-1a hash of their code points
    // (tests/bench/body_parse.mjs found the pair), so only their text tells
    // them apart; among 100 names the check sorts by hash first
    const filler = Array.from({ length: 100 }, (_, i) => `"f${i}":0`).join(',');
    const collide = `{${filler},"ZjEppR":1,"yjepeD":2,"ZjEppR":3}`;
    const cases = [...DUP, [manyBody, manyBody.lastIndexOf('"n12345"'), 'n12345'],
      [collide, collide.lastIndexOf('"ZjEppR"'), 'ZjEppR']];
    for (const [body, position, field] of cases) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', body);
      const shown = body.length > 80 ? `${body.slice(0, 80)}...` : body;
      assert.equal(r.status, 400, `${shown}: ${r.text}`);
      const why = field === null ? 'a number may not have a leading zero'
        : `a member's name is given twice in one object ("${field}")`;
      const want = {
        type: '/api/v1/problems/malformed-json', title: 'Malformed JSON', status: 400,
        detail: `the request body is not valid JSON (RFC 8259, I-JSON): ${why} at byte ${position}`,
        instance: '/api/v1/sessions', position,
      };
      if (field !== null) want.field = field;
      assert.deepEqual(r.body, want, shown);
    }
    // 20,000 distinct names pass the check (and meet the member check)
    const distinct = await req(d.base, 'POST', '/api/v1/sessions', `{${many.join(',')}}`);
    assert.equal(distinct.status, 422, distinct.text);
    assert.equal(distinct.body.field, 'n0');
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('a Host or Content-Length header given twice is 400 and changes nothing; 500 query parameters get 431', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const host = `Host: 127.0.0.1:${d.port}`;
    const body = JSON.stringify(CHEAP);
    const cases = [
      [`GET /api/v1/health HTTP/1.1\r\n${host}\r\nHost: evil.example`, '', 'Host'],
      [`GET /api/v1/health HTTP/1.1\r\n${host}\r\n${host}`, '', 'Host'],
      [`POST /api/v1/sessions HTTP/1.1\r\n${host}\r\nContent-Type: application/json\r\n` +
        `Content-Length: ${body.length}\r\nContent-Length: ${body.length}`, body, 'Content-Length'],
      [`POST /api/v1/sessions HTTP/1.1\r\n${host}\r\nContent-Type: application/json\r\n` +
        `Content-Length: ${body.length}\r\ncontent-length: 5`, body, 'Content-Length'],
    ];
    for (const [head, b, field] of cases) {
      const r = await rawRequest(d.port, head, b);
      assert.equal(r.status, 400, r.raw.toString('latin1'));
      const p = JSON.parse(r.body.toString('utf8'));
      assert.equal(p.type, '/api/v1/problems/bad-request');
      assert.equal(p.field, field);
    }
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 0, 'nothing created');
    // one Host and one Content-Length still pass
    const ok = await rawRequest(d.port, `POST /api/v1/sessions HTTP/1.1\r\n${host}\r\n` +
      `Content-Type: application/json\r\nContent-Length: ${body.length}`, body);
    assert.equal(ok.status, 201, ok.raw.toString('latin1'));
    // ~500 query parameters (a 4 kB URL): an answer, not a closed socket
    for (const n of [500, 3000]) {
      const query = Array.from({ length: n }, (_, i) => `a${i}=${i}`).join('&');
      const r = await rawRequest(d.port, `GET /api/v1/sessions?${query} HTTP/1.1\r\n${host}`);
      assert.equal(r.status, 431, `${n} parameters: ${r.raw.toString('latin1').slice(0, 300)}`);
      const p = JSON.parse(r.body.toString('utf8'));
      assert.equal(p.type, '/api/v1/problems/header-fields-too-large');
      assert.match(p.detail, new RegExp(`has ${n} parameters`));
    }
    // a few unknown ones are still named one by one
    const few = await req(d.base, 'GET', '/api/v1/sessions?a=1&b=2');
    assert.equal(few.status, 400);
    assert.equal(few.body.field, 'a');
    assert.equal((await req(d.base, 'GET', '/api/v1/health')).status, 200, 'the daemon still answers');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('an empty or blank body is 400 on every route that reads one; nothing is created', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const routes = [['POST', '/api/v1/sessions'], ['POST', '/api/v1/sweeps'], ['POST', '/api/v1/fits'],
      ['POST', '/api/v1/experiments'], ['PATCH', `/api/v1/sessions/${s.body.id}`]];
    for (const [method, path] of routes) {
      for (const body of ['', ' ', '\r\n\t ']) {
        const r = await req(d.base, method, path, body);
        assert.equal(r.status, 400, `${method} ${path} ${JSON.stringify(body)}: ${r.text}`);
        assert.deepEqual(r.body, {
          type: '/api/v1/problems/malformed-json', title: 'Malformed JSON', status: 400,
          detail: `the request body is ${body ? 'only whitespace' : 'empty'}; a JSON object is expected ({} for no members)`,
          instance: path,
        }, `${method} ${path} ${JSON.stringify(body)}`);
      }
    }
    assert.equal((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions.length, 1, 'no session created');
    assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length, 0, 'no sweep started');
    // {} still takes every default
    assert.equal((await req(d.base, 'POST', '/api/v1/sessions', '{}')).status, 201);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('%00 in the path or the query is 400, never a shorter path; a Last-Event-ID, since or limit past its range is 400 with the range', { timeout: 60000 * SLOW }, async () => {
  const d = await startDaemon();
  try {
    const host = `Host: 127.0.0.1:${d.port}`;
    const get = (target, more = '') => rawRequest(d.port, `GET ${target} HTTP/1.1\r\n${host}${more}`);
    // [target, type, field, instance (the path as libmicrohttpd decoded it), position]
    const cases = [
      ['/api/v1/health%00x', 'bad-request', 'path', '/api/v1/health', 14],
      ['/index.html%00.txt', 'bad-request', 'path', '/index.html', 11],
      ['/%00', 'bad-request', 'path', '/', 1],
      ['/api/v1/sessions?limit=1%00x', 'bad-query', 'query', '/api/v1/sessions', 24],
    ];
    for (const [target, type, field, instance, position] of cases) {
      const r = await get(target);
      assert.equal(r.status, 400, `${target}: ${r.raw.toString('latin1')}`);
      assert.deepEqual(JSON.parse(r.body.toString('utf8')), {
        type: `/api/v1/problems/${type}`, title: type === 'bad-query' ? 'Bad query parameter' : 'Bad request',
        status: 400,
        detail: `the request target has %00 (a NUL byte) at byte ${position}; no path or query value holds one`,
        instance, field,
      }, target);
    }
    assert.equal((await get('/api/v1/health')).status, 200);
    assert.equal((await get('/index.html')).status, 200);
    assert.equal((await get('/api/v1/health%41')).status, 404, 'other escapes still decode');

    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...NO_FEED, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const stream = `/api/v1/sessions/${s.body.id}/stream`;
    // a record id states its range, 0 to 2^53, as limit does: 2^63 - 1,
    // its end before, is no number JSON states exactly
    const idProblem = (field) => ({
      type: '/api/v1/problems/bad-query', title: 'Bad query parameter', status: 400,
      detail: 'Last-Event-ID (or since) must be a record id, an integer from 0 to 9007199254740992 (2^53)',
      instance: stream, field, min: 0, max: 9007199254740992,
    });
    // (fetch: a stream taken would not end, and is cancelled)
    const refusal = async (path, headers) => {
      const r = await fetch(d.base + path, { headers });
      if (r.status !== 400) await r.body.cancel();
      return { status: r.status, body: r.status === 400 ? await r.json() : null };
    };
    const ids = ['9007199254740993', '9223372036854775807', '9223372036854775808', '18446744073709551616',
      '99999999999999999999999', '+5', '5x', '-1', '0x1'];
    for (const id of ids) {
      const r = await refusal(stream, { 'Last-Event-ID': id });
      assert.equal(r.status, 400, `Last-Event-ID ${id}`);
      assert.deepEqual(r.body, idProblem('Last-Event-ID'), id);
      const since = await refusal(`${stream}?since=${encodeURIComponent(id)}`);
      assert.equal(since.status, 400, `since=${id}`);
      assert.deepEqual(since.body, idProblem('since'), id);
    }
    // a limit states its range, up to 2^53: the largest integer a JSON
    // number (a double) holds exactly, so that max is the very number
    for (const limit of ['9007199254740993', '18446744073709551615', '18446744073709551616', '0', '+5', '0x1']) {
      const r = await get(`${stream}?limit=${limit}`);
      assert.equal(r.status, 400, limit);
      assert.deepEqual(JSON.parse(r.body.toString('utf8')), {
        type: '/api/v1/problems/bad-query', title: 'Bad query parameter', status: 400,
        detail: 'limit must be a whole number of records from 1 to 9007199254740992 (2^53)', instance: stream,
        field: 'limit', min: 1, max: 9007199254740992,
      }, limit);
    }
    // the largest id and limit still open a stream
    const ok = await fetch(`${d.base}${stream}?limit=9007199254740992`,
      { headers: { 'Last-Event-ID': '9007199254740992' } });
    assert.equal(ok.status, 200);
    await ok.body.cancel();
    const since = await fetch(`${d.base}${stream}?since=9007199254740992`);
    assert.equal(since.status, 200);
    await since.body.cancel();
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});

test('docs/hardening.md: its example bodies get the answers it shows', { timeout: 30000 * SLOW }, async () => {
  const doc = readFileSync(new URL('../../docs/hardening.md', import.meta.url), 'utf8');
  const blocks = [...doc.matchAll(/<!-- test:strict-example -->\s*```json\n([\s\S]*?)\n```/g)];
  assert.equal(blocks.length, 2, 'docs/hardening.md has two json blocks after <!-- test:strict-example -->');
  const d = await startDaemon();
  try {
    for (const m of blocks) {
      const example = JSON.parse(m[1]);
      const r = await req(d.base, 'POST', '/api/v1/sessions', example.request);
      assert.equal(r.status, example.answer.status, example.request);
      assert.deepEqual(r.body, example.answer);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
