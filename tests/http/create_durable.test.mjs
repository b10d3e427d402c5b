// SPDX-License-Identifier: GPL-3.0-or-later
// A 201 (202) on a creation means its record is on disk (docs/durability.md
// "A 201 on a creation means its record is on disk"): a session's
// spec.json, an experiment's, a sweep's and a fit's record. The daemon is
// killed with SIGKILL at once (0 ms) and about 1 ms after the answer, one
// kind a round, two creations at once; after each restart on the same
// data directory every acknowledged one is there, and nothing is listed
// damaged (a session whose creation the kill cut before its spec was
// written, never answered, leaves an empty directory: removed).
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, CHEAP, NO_FEED, SLOW } from './lib.mjs';

const KINDS = [
  { name: 'sessions', status: 201, body: { ...CHEAP, pace: 'max', until: 0.5 } },
  { name: 'experiments', status: 201, body: { session: { ...NO_FEED, pace: 'max' }, schedule: [{ beta: 50, until: 0.2 }] } },
  { name: 'sweeps', status: 202, body: { ...NO_FEED, beta: [20], rotations: ['cw'], t_end: 0.1 } },
  { name: 'fits', status: 202, body: { ...NO_FEED, t_end: 0.2, free: ['e'], curve_step: 90,
    points: [{ beta: 20, rotation: 'cw', v: 0.07 }, { beta: 60, rotation: 'cw', v: 0.06 }] } },
];
const ROUNDS = 2 * KINDS.length;

for (const delay of [0, 1]) {
  test(`every acknowledged creation survives kill -9 ${delay} ms after its answer (${ROUNDS} rounds)`, { timeout: 180000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsimd-create-'));
    const args = ['--data-dir', dir, '--checkpoint-interval', '3600'];
    const acked = []; // [kind name, id] answered 201/202
    try {
      for (let round = 0; round <= ROUNDS; round++) {
        const d = await startDaemon(args);
        try {
          // what came back: every acknowledged creation, whole
          for (const [kind, id] of acked) {
            const g = await until(async () => {
              const r = await req(d.base, 'GET', `/api/v1/${kind}/${id}`);
              return r.status !== 503 && r;
            }, 20000 * SLOW, `${kind} ${id} answering`);
            assert.equal(g.status, 200, `round ${round}: acknowledged ${kind} ${id} is back: ${g.text}`);
            assert.notEqual(g.body.state, 'damaged', `round ${round}: ${kind} ${id}: ${g.text}`);
          }
          // and a creation the kill cut short left nothing damaged
          for (const { name } of KINDS) {
            const list = (await req(d.base, 'GET', `/api/v1/${name}`)).body[name];
            const bad = list.filter((x) => x.state === 'damaged');
            assert.deepEqual(bad, [], `round ${round}: no ${name} damaged`);
          }
          if (round === ROUNDS) break;
          const kind = KINDS[round % KINDS.length];
          let killed = false;
          const kill = () => {
            if (killed) return;
            killed = true;
            if (delay > 0) { const t = process.hrtime.bigint(); while (process.hrtime.bigint() - t < 1000000n); }
            d.proc.kill('SIGKILL');
          };
          await Promise.all([0, 1].map(async () => {
            try {
              const res = await fetch(`${d.base}/api/v1/${kind.name}`, {
                method: 'POST', headers: { 'Content-Type': 'application/json' },
                body: JSON.stringify(kind.body),
              });
              const text = await res.text();
              if (res.status === kind.status) {
                acked.push([kind.name, JSON.parse(text).id]);
                kill();
              } else {
                assert.fail(`POST /api/v1/${kind.name}: ${res.status} ${text}`);
              }
            } catch (e) {
              if (e instanceof assert.AssertionError) throw e; // cut by the kill: not acknowledged
            }
          }));
        } finally {
          await d.stop('SIGKILL');
        }
      }
      for (const kind of KINDS) {
        assert.ok(acked.some(([k]) => k === kind.name), `${kind.name} were acknowledged`);
      }
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });
}
