// SPDX-License-Identifier: GPL-3.0-or-later
// A 200 on a control means its line is in the control log on disk
// (docs/durability.md): the daemon is killed with SIGKILL at once (0 ms)
// and about 1 ms after a PATCH is answered, round after round, and after
// each restart every acknowledged control is in controls.ndjson and in
// force (beta_target), on running and on paused sessions alike.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { mkdtempSync, readFileSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, sleep, CHEAP, SLOW } from './lib.mjs';

const ROUNDS = 8;

const logged = (dir, id) => {
  let text = '';
  try { text = readFileSync(join(dir, 'sessions', id, 'controls.ndjson'), 'utf8'); } catch { /* none yet */ }
  return text.split('\n').filter((l) => l).map((l) => JSON.parse(l).beta).filter((b) => b !== undefined);
};

for (const delay of [0, 1]) {
  test(`every acknowledged control survives kill -9 ${delay} ms after its 200 (${ROUNDS} rounds)`, { timeout: 120000 * SLOW }, async () => {
    const dir = mkdtempSync(join(tmpdir(), 'convsimd-durable-'));
    // no checkpoint falls due: what survives is the control log's doing
    const args = ['--data-dir', dir, '--checkpoint-interval', '3600'];
    const acked = {}; // id -> betas answered 200, in order
    let ids = [];
    try {
      for (let round = 0; round < ROUNDS; round++) {
        const d = await startDaemon(args);
        try {
          if (round === 0) {
            for (let i = 0; i < 4; i++) {
              const c = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: i === 3 ? 'max' : 1 });
              assert.equal(c.status, 201, c.text);
              ids.push(c.body.id);
              acked[c.body.id] = [];
            }
            // one of them paused: its targets change while it stands still
            assert.equal((await req(d.base, 'PATCH', `/api/v1/sessions/${ids[0]}`, { running: false })).status, 200);
          } else {
            // what came back: every acknowledged control, in the log and in force
            for (const id of ids) {
              const g = await until(async () => {
                const r = await req(d.base, 'GET', `/api/v1/sessions/${id}`);
                return r.status === 200 && r.body;
              }, 20000, `session ${id} answering`);
              // a control whose answer the kill cut off may be in the log
              // too: every acknowledged one must be, in order
              const want = acked[id], log = logged(dir, id);
              let at = 0;
              for (const b of log) if (at < want.length && b === want[at]) at++;
              assert.equal(at, want.length,
                `round ${round}: session ${id}'s log ${JSON.stringify(log)} holds every acknowledged beta ${JSON.stringify(want)}`);
              if (log.length) {
                assert.equal(g.status.beta_target, log[log.length - 1],
                  `round ${round}: session ${id}'s last logged beta in force (log ${JSON.stringify(log)}): t ${g.status.t}`);
              }
            }
          }
          // four PATCHes at once; the daemon dies right after the first 200
          const beta = 20 + round * 5 + delay;
          let killed = false;
          const kill = () => {
            if (killed) return;
            killed = true;
            if (delay === 0) d.proc.kill('SIGKILL');
            else { const t = process.hrtime.bigint(); while (process.hrtime.bigint() - t < 1000000n); d.proc.kill('SIGKILL'); }
          };
          await Promise.all(ids.map(async (id, i) => {
            try {
              const res = await fetch(`${d.base}/api/v1/sessions/${id}`, {
                method: 'PATCH', headers: { 'Content-Type': 'application/json' },
                body: JSON.stringify({ beta: beta + i * 0.25 }),
              });
              if (res.status === 200 && !killed) {
                acked[id].push(beta + i * 0.25);
                kill();
              } else if (res.status === 200) {
                acked[id].push(beta + i * 0.25); // answered before the kill took
              }
              await res.text().catch(() => {});
            } catch { /* cut by the kill: not acknowledged */ }
          }));
        } finally {
          await d.stop('SIGKILL');
        }
      }
      assert.ok(Object.values(acked).flat().length >= ROUNDS, 'controls were acknowledged');
    } finally {
      rmSync(dir, { recursive: true, force: true });
    }
  });
}

test('24 concurrent controls of one session: each in the log once when answered, no more syncs than controls', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-group-'));
  const d = await startDaemon(['--data-dir', dir]);
  try {
    const id = (await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 })).body.id;
    const betas = Array.from({ length: 24 }, (_, i) => 30 + i);
    const res = await Promise.all(betas.map((b) => req(d.base, 'PATCH', `/api/v1/sessions/${id}`, { beta: b })));
    for (const r of res) assert.equal(r.status, 200, r.text);
    const log = logged(dir, id);
    assert.deepEqual([...log].sort((a, b) => a - b), betas, 'every control in the log once');
    const m = (await req(d.base, 'GET', '/metrics')).text;
    const syncs = Number(m.match(/^convsim_control_log_syncs_total (\d+)/m)[1]);
    assert.ok(syncs >= 1 && syncs <= betas.length, `syncs ${syncs} for ${betas.length} controls`);
    await sleep(10);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});
