// SPDX-License-Identifier: GPL-3.0-or-later
// Stored sweeps and experiments with a right checksum and wrong contents
// (what the fuzz harness tests/fuzz/fuzz_jobs.c feeds the restore; docs/
// fuzzing.md): a sweep of 3 senses, a sweep point turned neither way, an
// experiment at its 1001st of 2 segments and one whose session has no
// layers. The restart lists each as damaged with its reason, serves them
// and the listings, keeps the rest of the data dir (the release fixture of
// c0da41f), reads nothing past a buffer (make check-ci runs this under
// ASan and UBSan) and stops cleanly. The offsets are this build's record
// layouts (server/store/records.h, host order, x86-64).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { cpSync, mkdtempSync, readdirSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, reframe, STORE_FRAME, SLOW } from './lib.mjs';

const FIXTURE = new URL('../fixtures/datadir/c0da41f/data', import.meta.url).pathname;
const F = STORE_FRAME;
const SWEEP_RECORD = 1888; // srv_sweep_record: then the betas, then the points
const SWEEP_NROT = 576;    // req.nrot (req at 24)
const SWEEP_NBETA = 560;   // req.nbeta
const BETA = 16;           // api_value
const POINT_ROTATION = 16; // api_sweep_point.rotation
const EXP_LAYERS = 440;    // req.spec.scene.layers
const EXP_STATE = 3712;    // state, then cur at 3716
const EXP_DONE = 2;

// A copy of file (in dir) under a new id, edited by f; the record's id at
// its start.
function copyAs(dir, name, id, f) {
  const b = readFileSync(join(dir, name));
  b.write(`${id}\0`, F, 'latin1');
  f(b);
  writeFileSync(join(dir, `${id}.bin`), reframe(b));
}

test('stored sweeps and experiments no request could make are listed damaged with why', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-jobdamage-'));
  cpSync(FIXTURE, dir, { recursive: true });
  const sweeps = join(dir, 'sweeps'), exps = join(dir, 'experiments');
  const [sweep] = readdirSync(sweeps), [exp] = readdirSync(exps);
  const sw = readFileSync(join(sweeps, sweep));
  assert.equal(sw.readInt32LE(F + SWEEP_NROT), 1, 'the layout this test assumes: one sense');
  assert.equal(sw.readInt32LE(F + SWEEP_NBETA), 2, 'the layout this test assumes: two betas');
  const point0 = F + SWEEP_RECORD + 2 * BETA;
  assert.equal(sw.readInt32LE(point0 + POINT_ROTATION), 1, 'the layout this test assumes: cw');
  const ex = readFileSync(join(exps, exp));
  assert.equal(ex.readInt32LE(F + EXP_LAYERS), 2, 'the layout this test assumes: 2 layers');
  assert.equal(ex.readInt32LE(F + EXP_STATE), EXP_DONE, 'the layout this test assumes: done');
  const cases = {
    '5e5e5e5e5e5e5e01': ['sweeps', sweep, (b) => b.writeInt32LE(3, F + SWEEP_NROT), 'inconsistent: senses'],
    '5e5e5e5e5e5e5e02': ['sweeps', sweep, (b) => b.writeInt32LE(7, point0 + POINT_ROTATION), 'inconsistent: a point'],
    'e0e0e0e0e0e0e001': ['experiments', exp, (b) => b.writeInt32LE(1000, F + EXP_STATE + 4), 'inconsistent: its segments'],
    'e0e0e0e0e0e0e002': ['experiments', exp, (b) => b.writeInt32LE(0, F + EXP_LAYERS), "its session's spec: layers must be an integer in [1, 64]"],
  };
  for (const [id, [kind, name, f]] of Object.entries(cases))
    copyAs(kind === 'sweeps' ? sweeps : exps, name, id, f);
  const d = await startDaemon(['--data-dir', dir]);
  try {
    for (const [id, [kind, , , why]] of Object.entries(cases)) {
      const r = await req(d.base, 'GET', `/api/v1/${kind}/${id}`);
      assert.equal(r.status, 200, `${kind} ${id}`);
      assert.equal(r.body.state, 'damaged', `${kind} ${id}`);
      assert.equal(r.body.error, `damaged: ${kind}/${id}.bin: ${why}`, `${kind} ${id}`);
    }
    // the fixture's own sweep and experiment come back done beside them
    const list = async (kind) => (await req(d.base, 'GET', `/api/v1/${kind}`)).body[kind];
    const swl = await list('sweeps'), exl = await list('experiments');
    assert.deepEqual(swl.map((s) => s.id).sort(), [sweep.slice(0, -4), '5e5e5e5e5e5e5e01', '5e5e5e5e5e5e5e02'].sort());
    assert.deepEqual(exl.map((e) => e.id).sort(), [exp.slice(0, -4), 'e0e0e0e0e0e0e001', 'e0e0e0e0e0e0e002'].sort());
    assert.equal(swl.find((s) => `${s.id}.bin` === sweep).state, 'done');
    assert.equal(exl.find((e) => `${e.id}.bin` === exp).state, 'done');
  } finally {
    assert.equal((await d.stop()).code, 0);
    rmSync(dir, { recursive: true, force: true });
  }
});
