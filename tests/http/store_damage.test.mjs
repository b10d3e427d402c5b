// SPDX-License-Identifier: GPL-3.0-or-later
// Files of the data directory with a right checksum and wrong contents
// (what a fuzz harness, tests/fuzz/fuzz_store.c, feeds the restore): a
// checkpoint whose experiment length wraps the length check, a spec whose
// preset name is not terminated, and specs holding what no request can set
// (a method named rk2, an atol out of its range on a method that does not
// read it, pace "max" without until: the fuzz harness's regression inputs,
// as real files), and a spec.json created at 1e999 s (body_specfile's
// regression input). The restart lists every such session as damaged with the
// reason (the one whose both checkpoints are refused is re-created from
// its spec, the reasons logged), reads nothing past a buffer (make check runs
// this under ASan) and stops cleanly. The offsets are this build's record
// layouts (server/session/session_load.c, host order, x86-64).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, untilReplayed, reframe, STORE_FRAME, CHEAP, SLOW } from './lib.mjs';

const FRAME = STORE_FRAME;
const CKPT_RECORD = 320;   // srv_ckpt_record; exp_len at 304, sim_len at 312
const SPEC_PRESET = 24;    // spec_record: id[24], then api_spec's preset[32]
const SPEC_METHOD = 472;   // api_spec's method.name[24] (api_spec at 24)
const SPEC_ATOL = 512;     // method.atol
const SPEC_PACE = 536;     // pace (0: "max"), then until at 544

test('a checksummed checkpoint with wrapping lengths and specs no request could make are listed damaged', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-damage-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  try {
    const ids = [];
    for (let i = 0; i < 6; i++)
      ids.push((await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 0.2 })).body.id);
    for (const id of ids)
      await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.state === 'finished', 20000 * SLOW, id);
    assert.equal((await d.stop()).code, 0);
    for (const name of ['checkpoint.bin', 'checkpoint.bin.prev']) {
      const path = join(dir, 'sessions', ids[0], name);
      const b = readFileSync(path);
      const payload = BigInt(b.length - FRAME);
      const expLen = payload - BigInt(CKPT_RECORD) + 100n;
      b.writeBigUInt64LE(expLen, FRAME + 304);
      b.writeBigUInt64LE((payload - BigInt(CKPT_RECORD) - expLen) & 0xffffffffffffffffn, FRAME + 312);
      writeFileSync(path, reframe(b));
    }
    // the binary specs an earlier build wrote: this build's spec.json gone
    for (const id of ids.slice(1, 5)) rmSync(join(dir, 'sessions', id, 'spec.json'));
    // a spec.json created at 1e999 s (infinite: written again it would be
    // null, and the session lost at the restart after)
    const json = join(dir, 'sessions', ids[5], 'spec.json');
    const text = readFileSync(json, 'utf8');
    assert.match(text, /"created":[0-9.e+]+,/, 'the layout this test assumes');
    writeFileSync(json, text.replace(/"created":[0-9.e+]+,/, '"created":1e999,'));
    const spec = readFileSync(join(dir, 'sessions', ids[1], 'spec.bin'));
    assert.equal(spec.toString('latin1', FRAME + SPEC_PRESET, FRAME + SPEC_PRESET + 10), 'czubak2016', 'the layout this test assumes');
    spec.fill('x', FRAME + SPEC_PRESET, FRAME + SPEC_PRESET + 32);
    writeFileSync(join(dir, 'sessions', ids[1], 'spec.bin'), reframe(spec));
    const edit = (id, f) => {
      const path = join(dir, 'sessions', id, 'spec.bin');
      const b = readFileSync(path);
      assert.equal(b.toString('latin1', FRAME + SPEC_METHOD, FRAME + SPEC_METHOD + 4), 'dem\0', 'the layout this test assumes');
      assert.equal(b.readDoubleLE(FRAME + SPEC_PACE + 8), 0.2, 'the layout this test assumes');
      f(b);
      writeFileSync(path, reframe(b));
    };
    edit(ids[2], (b) => b.write('rk2\0', FRAME + SPEC_METHOD, 'latin1'));
    edit(ids[3], (b) => b.writeDoubleLE(3e-48, FRAME + SPEC_ATOL));
    edit(ids[4], (b) => { b.writeDoubleLE(0, FRAME + SPEC_PACE); b.writeDoubleLE(0, FRAME + SPEC_PACE + 8); });
    d = await startDaemon(args);
    // both checkpoints refused: re-created from its spec (replay.test.mjs),
    // the reasons logged
    await untilReplayed(d.base, ids[0]);
    // the replay reaches where it was; then it runs on to its until
    const a = await until(async () => {
      const v = (await req(d.base, 'GET', `/api/v1/sessions/${ids[0]}`)).body;
      return v.state !== 'running' && v;
    }, 20000 * SLOW, 'the replayed session to reach its until');
    assert.equal(a.state, 'finished');
    assert.equal(a.restored, 'replayed');
    assert.match(d.stderr(), /checkpoint\.bin: inconsistent lengths or state.*checkpoint\.bin\.prev: inconsistent lengths.*re-created from its spec/);
    const b = (await req(d.base, 'GET', `/api/v1/sessions/${ids[1]}`)).body;
    assert.equal(b.state, 'damaged');
    assert.match(b.error, /spec\.bin: the preset or method name is not a string/);
    const why = [];
    for (const id of ids.slice(2, 6)) {
      const v = (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body;
      assert.equal(v.state, 'damaged', JSON.stringify(v));
      why.push(v.error);
    }
    assert.match(why[0], /spec\.bin: method must be one of rk4\|dopri5\|euler\|dem$/);
    assert.match(why[1], /spec\.bin: atol must be a finite number in \[1e-15, 1\]$/);
    assert.match(why[2], /spec\.bin: pace "max" without until/);
    assert.match(why[3], /spec\.json: created is no finite time \(unix s\)$/);
    assert.equal((await req(d.base, 'GET', '/api/v1/health')).status, 200);
    assert.equal((await d.stop()).code, 0, `clean stop; stderr: ${d.stderr()}`);
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
});

// A session whose two checkpoints are damaged is re-created from its spec
// with its controls replayed ("restored": "replayed"), and one that has
// none yet starts again from its spec without a replay, whatever its id
// reads: the restore asks whether the files could be read, not whether
// their reason's text says "missing" (a replica named "missing" has ids
// that do).
test('checkpoints damaged or absent, on a replica named "missing"', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-damage-'));
  const args = ['--data-dir', dir, '--node-id', 'missing'];
  let d = await startDaemon(args);
  try {
    const ids = [];
    for (let i = 0; i < 2; i++)
      ids.push((await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 'max', until: 0.2 })).body.id);
    for (const id of ids)
      await until(async () => (await req(d.base, 'GET', `/api/v1/sessions/${id}`)).body.state === 'finished', 20000 * SLOW, id);
    assert.equal((await d.stop()).code, 0);
    assert.match(ids[0], /^missing-/);
    for (const name of ['checkpoint.bin', 'checkpoint.bin.prev']) {
      const path = join(dir, 'sessions', ids[0], name);
      if (existsSync(path)) {
        const v = readFileSync(path);
        v[FRAME] ^= 0xff; // the payload: its checksum no longer matches
        writeFileSync(path, v);
      }
      rmSync(join(dir, 'sessions', ids[1], name), { force: true });
    }
    assert.ok(existsSync(join(dir, 'sessions', ids[0], 'checkpoint.bin')));
    d = await startDaemon(args);
    const damaged = (await req(d.base, 'GET', `/api/v1/sessions/${ids[0]}`)).body;
    assert.notEqual(damaged.state, 'damaged', JSON.stringify(damaged));
    assert.equal(damaged.restored, 'replayed', JSON.stringify(damaged));
    const fresh = (await req(d.base, 'GET', `/api/v1/sessions/${ids[1]}`)).body;
    assert.notEqual(fresh.state, 'damaged', JSON.stringify(fresh)); // started again from its spec
    assert.notEqual(fresh.restored, 'replayed', JSON.stringify(fresh));
    assert.equal((await d.stop()).code, 0);
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
});
