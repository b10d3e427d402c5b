// SPDX-License-Identifier: GPL-3.0-or-later
// The CPU probe a creation runs (docs/budgets.md, server/admit/cpu_probe.c)
// stops within one piece of simulated time (SRV_PROBE_PIECE_S, 0.01 s) of
// its bounds, --cpu-probe of CPU or SRV_PROBE_T_S = 0.2 simulated s,
// whatever the sample rate: at 1 sample per s it once advanced a whole
// second before it read its clock (1.7 s of CPU for a 64 x 64 feed). The
// daemon logs what each probe measured and over how long, at debug level.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { startDaemon, req, until, CHEAP } from './lib.mjs';

const probes = (d) => [...d.stderr().matchAll(
  /session ([0-9a-f]+): probe ([0-9.e+-]+) ms of CPU per simulated s over ([0-9.e+-]+) simulated s/g)]
  .map((m) => ({ id: m[1], ms: Number(m[2]), span: Number(m[3]) }));

test('the probe runs at most 0.2 simulated s, in pieces of 0.01 s, at any sample rate', async () => {
  // a CPU bound out of reach: the simulated bound ends every probe
  const d = await startDaemon(['--log-level', 'debug', '--cpu-probe', '1']);
  try {
    const made = [];
    for (const rate of [1, 3, 250, 10000]) {
      const r = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1, sample_rate: rate });
      assert.equal(r.status, 201, r.text);
      made.push({ id: r.body.id, rate });
    }
    await until(async () => probes(d).length >= made.length, 10000, 'a probe line per creation');
    for (const { id, rate } of made) {
      const p = probes(d).find((x) => x.id === id);
      assert.ok(p, `no probe line for ${id}`);
      // the last piece ends at 0.2 s or at the sample (10000/s: 0.2001)
      assert.ok(p.span >= 0.2 - 1e-9 && p.span <= 0.2 + Math.min(0.01, 1 / rate) + 1e-9,
        `rate ${rate}: probe over ${p.span} simulated s`);
      assert.ok(p.ms > 0, `rate ${rate}: ${p.ms} ms`);
    }
  } finally {
    await d.stop();
  }
});

test('a CPU bound of 1 ms ends the probe within one piece of it', async () => {
  const d = await startDaemon(['--log-level', 'debug', '--cpu-probe', '0.001']);
  try {
    const r = await req(d.base, 'POST', '/api/v1/sessions', { pace: 1, sample_rate: 1, scene: { columns: 16, layers: 16 } });
    assert.equal(r.status, 201, r.text);
    await until(async () => probes(d).some((x) => x.id === r.body.id), 10000, 'its probe line');
    const p = probes(d).find((x) => x.id === r.body.id);
    // one sample is 1 s; the probe stops at the first piece past 1 ms of CPU
    assert.ok(p.span > 0 && p.span < 0.2, `probe over ${p.span} simulated s`);
    assert.ok(Math.abs(p.span / 0.01 - Math.round(p.span / 0.01)) < 1e-6, `${p.span} is not whole pieces`);
  } finally {
    await d.stop();
  }
});
