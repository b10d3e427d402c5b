// SPDX-License-Identifier: GPL-3.0-or-later
// An adaptive method's steps are known only once it runs, so no estimate
// before a paced dopri5 session's settling could refuse it: a 64 x 64 one
// settled for about 48 CPU s, holding the only settling slot, before its
// probe refused it for needing 64 cores. Such a session now settles 0.2 CPU s
// first and is refused there where that settling alone needs twice the
// cores for paced sessions (server/admit/cpu_probe.c, srv_cpu_settle_peek;
// docs/load.md "What settling costs"); one that fits settles again from the
// start and is created.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, metric, postRefusedCpu, SLOW } from './lib.mjs';

const LARGE = { scene: { columns: 64, layers: 64 }, integrator: { method: 'dopri5' } };
const DETAIL = new RegExp('^this session needs ([0-9.e+]+) cores \\(([0-9.e+]+) ms of CPU per simulated s at ' +
  'pace 1\\), more than the 1 core for paced sessions \\(--max-paced-cores\\); nothing was created, lower ' +
  'the pace \\(measured over the first 0\\.2 CPU s of its settling: integrator\\.method dopri5 is adaptive\\)$');

test('a paced dopri5 session that needs far more than the paced cores is refused after 0.2 CPU s of its settling; one that fits is created', { timeout: 120000 * SLOW }, async () => {
  const d = await startDaemon(['--max-paced-cores', '1']);
  try {
    const { r, cpu } = await postRefusedCpu(d, '/api/v1/sessions', LARGE);
    const { detail, max, ...rest } = r.body;
    assert.deepEqual(rest, {
      type: '/api/v1/problems/out-of-range', title: 'Value out of range', status: 422,
      instance: '/api/v1/sessions', field: 'pace', budget: 'cpu', limit: 1, min: 0.001,
    });
    const m = detail.match(DETAIL);
    assert.ok(m, detail);
    const need = Number(m[1]);
    // refused at twice the budget or more; the largest pace is the budget over the need
    assert.ok(need >= 2, detail);
    // (the detail prints three significant digits)
    assert.ok(Math.abs(max * Number(m[2]) / 1e3 - 1) < 5e-3, `max ${max} against ${m[2]} ms`);
    // the settling stopped at the peek (its whole settling took about 48 CPU s)
    assert.ok(cpu < 3 * SLOW, `the daemon spent ${cpu} CPU s over the request`);
    // nothing was created or held: the settling slot and the cores are free
    assert.deepEqual((await req(d.base, 'GET', '/api/v1/sessions')).body.sessions, []);
    const text = (await req(d.base, 'GET', '/metrics')).text;
    assert.equal(metric(text, 'convsim_sessions_created_total'), 0);
    assert.equal(metric(text, 'convsim_paced_cpu_cores'), 0);
    // the default scene with dopri5 at pace 0.01 needs about 0.08 cores: its
    // settling (about 4 CPU s) goes past the peek, starts again and ends
    const ok = await req(d.base, 'POST', '/api/v1/sessions', { integrator: { method: 'dopri5' }, pace: 0.01 });
    assert.equal(ok.status, 201, ok.text);
    assert.equal(ok.body.status.t, 0);
    assert.equal(ok.body.columns, 5);
    assert.equal(ok.body.layers, 8);
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sessions/${ok.body.id}`)).status, 204);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
});
