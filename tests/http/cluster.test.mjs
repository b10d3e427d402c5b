// SPDX-License-Identifier: GPL-3.0-or-later
// Three replicas behind the real HAProxy, started by server/cluster.sh run
// (as `make cluster N=3`) on free ports: creations spread over all three,
// every id is routed to its replica, streams and PATCH beta pass the proxy,
// heartbeats keep an idle stream open past the proxy's timeouts, lists
// gather every replica (--peers); kill -9 of one replica leaves the others
// answering, its ids answer HAProxy's 503 problem+json naming it, and after
// a restart its sessions come back from its data directory.
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import fs from 'node:fs';
import os from 'node:os';
import path from 'node:path';
import { SLOW, WEB_ROOT, CHEAP, CLUSTER_SCRIPT, req, openStream, until, startCluster } from './lib.mjs';

// s; the proxy's idle timeouts are four of them (REQUEST_TIMEOUT the same:
// the idle stream below outlives them; a creation on this busy machine
// may take seconds); slower under the sanitizers
const HEARTBEAT = 2 * Math.ceil(SLOW);
const ID = /^(n[123])-[0-9a-f]{12}$/;

const alive = (pid) => { try { process.kill(pid, 0); return true; } catch { return false; } };

let dir, cluster, env, base, restarted = null;
const started = []; // every pid this file may have to stop

// stopped from outside (a runner's timeout skips after()): stop the cluster too
const stopAll = () => {
  for (const pid of [...started, restarted?.pid]) if (pid && alive(pid)) process.kill(pid, 'SIGTERM');
};
process.on('exit', stopAll);
for (const sig of ['SIGTERM', 'SIGINT']) process.on(sig, () => { stopAll(); process.exit(1); });

before(async () => {
  dir = fs.mkdtempSync(path.join(os.tmpdir(), 'convsim-cluster-'));
  cluster = await startCluster(3, dir, {
    HEARTBEAT: String(HEARTBEAT),
    REQUEST_TIMEOUT: String(4 * HEARTBEAT),
    DAEMON_FLAGS: `--log-level warn --web-root ${WEB_ROOT} --checkpoint-interval 0.5`,
  });
  ({ base, env } = cluster);
  started.push(cluster.runner.pid, ...Object.values(cluster.pids));
});

after(async () => {
  if (restarted && alive(restarted.pid)) restarted.kill('SIGTERM');
  if (cluster) cluster.stop();
  await until(() => started.every((pid) => !alive(pid)) && (!restarted || restarted.exitCode !== null), 20000,
    'every process of the cluster to stop').catch(() => {
    for (const pid of started) if (alive(pid)) process.kill(pid, 'SIGKILL');
  });
  fs.rmSync(dir, { recursive: true, force: true });
});

const node = (id) => id.match(ID)[1];
// cheap sessions started at rest: the steady start's shooting would make
// each creation cost seconds under the sanitizers, and routing is the point
const ROUTED = { scene: { ...CHEAP.scene, start: 'rest' }, pace: 1, sample_rate: 50 };

test('three replicas behind HAProxy: routing, streams, a replica killed and restarted',
  { timeout: Math.min(90000 * SLOW, 280000) }, async () => {
    // 30 creations through the proxy land on all three replicas
    const ids = [];
    for (let i = 0; i < 30; i++) {
      const r = await req(base, 'POST', '/api/v1/sessions', ROUTED)
        .catch((e) => { throw new Error(`POST through ${base}: ${e.cause?.message || e.message}\n${cluster.output()}`); });
      assert.equal(r.status, 201, r.text);
      assert.match(r.body.id, ID);
      assert.equal(r.headers.get('location'), `/api/v1/sessions/${r.body.id}`);
      ids.push(r.body.id);
    }
    const per = { n1: [], n2: [], n3: [] };
    for (const id of ids) per[node(id)].push(id);
    for (const n of ['n1', 'n2', 'n3']) assert.ok(per[n].length >= 5, `${n} got ${per[n].length} of 30`);

    // every id reaches its own replica (another would answer 404)
    for (const id of ids) {
      const r = await req(base, 'GET', `/api/v1/sessions/${id}`);
      assert.equal(r.status, 200, `${id}: ${r.text}`);
      assert.equal(r.body.id, id);
    }
    // one list through the proxy holds every replica's sessions; scope=local one replica's
    const all = await req(base, 'GET', '/api/v1/sessions');
    assert.equal(all.status, 200);
    assert.deepEqual(all.body.sessions.map((s) => s.id).sort(), [...ids].sort());
    assert.equal(all.body.unreachable, undefined);
    const local = await req(base, 'GET', '/api/v1/sessions?scope=local');
    const localNodes = new Set(local.body.sessions.map((s) => node(s.id)));
    assert.equal(localNodes.size, 1);
    assert.equal(local.body.sessions.length, per[[...localNodes][0]].length);
    const csv = await req(base, 'GET', '/api/v1/sessions?format=csv');
    assert.equal(csv.text.trim().split('\n').length, 31, 'one header and 30 rows');

    // a stream and PATCH beta through the proxy
    const target = per.n2[0];
    const ac = new AbortController();
    const seen = (async () => {
      let samples = 0;
      for await (const rec of openStream(base, `/api/v1/sessions/${target}/stream?format=ndjson&fields=trough`, {}, ac.signal)) {
        if (rec.type === 'sample') samples++;
        if (rec.type === 'control') return { samples, control: rec };
      }
      return { samples };
    })();
    await until(async () => (await req(base, 'GET', `/api/v1/sessions/${target}`)).body.streams === 1, 5000, 'the stream');
    const patch = await req(base, 'PATCH', `/api/v1/sessions/${target}`, { beta: 128 });
    assert.equal(patch.status, 200, patch.text);
    assert.equal(patch.body.acknowledged, true);
    const { samples, control } = await seen;
    ac.abort();
    assert.ok(samples > 0, 'samples through the proxy');
    assert.equal(control.beta, 128);
    assert.equal(control.t_effective, patch.body.t_effective);

    // an idle stream (paused session) outlives the proxy's 4-heartbeat timeouts
    const paused = per.n1[0];
    assert.equal((await req(base, 'PATCH', `/api/v1/sessions/${paused}`, { running: false })).status, 200);
    const idle = new AbortController();
    const t0 = Date.now();
    let beats = 0, ended = null;
    const stop = setTimeout(() => idle.abort(), (4 * HEARTBEAT + 2) * 1000);
    try {
      for await (const rec of openStream(base, `/api/v1/sessions/${paused}/stream?format=ndjson`, {}, idle.signal)) {
        if (rec.type === 'heartbeat') beats++;
        if (rec.type === 'end') { ended = rec.reason; break; }
      }
    } catch (e) { if (e.name !== 'AbortError') throw e; }
    clearTimeout(stop);
    assert.equal(ended, null, 'the idle stream was not ended');
    assert.ok(Date.now() - t0 >= 4 * HEARTBEAT * 1000, 'the stream stayed open past the timeouts');
    assert.ok(beats >= 3, `${beats} heartbeats`);

    // kill -9 of n3: its ids get HAProxy's problem, the others answer
    const before3 = new Map();
    for (const id of per.n3) before3.set(id, (await req(base, 'GET', `/api/v1/sessions/${id}`)).body.status.t);
    await new Promise((r) => setTimeout(r, 1000)); // a checkpoint after these reads (0.5 s)
    const pid3 = cluster.pids.n3;
    process.kill(pid3, 'SIGKILL');
    await until(() => !alive(pid3), 5000, 'n3 to die');
    for (const id of per.n3) {
      const r = await req(base, 'GET', `/api/v1/sessions/${id}`);
      assert.equal(r.status, 503, r.text);
      assert.match(r.headers.get('content-type'), /^application\/problem\+json/);
      assert.equal(r.body.replica, 'n3');
      assert.equal(r.body.status, 503);
      assert.match(r.body.detail, /replica n3 .* is down/);
    }
    for (const id of [...per.n1, ...per.n2]) assert.equal((await req(base, 'GET', `/api/v1/sessions/${id}`)).status, 200);
    const partial = await req(base, 'GET', '/api/v1/sessions');
    assert.equal(partial.status, 200);
    assert.equal(partial.body.sessions.length, 20);
    assert.equal(partial.body.unreachable.length, 1);
    assert.equal(partial.body.unreachable[0].peer, `http://127.0.0.1:${cluster.ports[2]}`);
    assert.equal(partial.headers.get('convsim-unreachable'), partial.body.unreachable[0].peer);
    // once HAProxy's health check has marked n3 down, creations go to the others only
    await new Promise((r) => setTimeout(r, 2500)); // fall 2 x inter 1 s
    for (let i = 0; i < 6; i++) {
      const r = await req(base, 'POST', '/api/v1/sessions', ROUTED);
      assert.equal(r.status, 201, r.text);
      assert.notEqual(node(r.body.id), 'n3');
      assert.equal((await req(base, 'DELETE', `/api/v1/sessions/${r.body.id}`, '')).status, 204);
    }

    // restarted on its data directory, n3's sessions come back through the proxy
    restarted = spawn('bash', [CLUSTER_SCRIPT, 'replica', 'n3'], { env, stdio: 'ignore' });
    await until(async () => (await req(base, 'GET', `/api/v1/sessions/${per.n3[0]}`)).status === 200,
      15000, 'n3 back behind the proxy');
    for (const id of per.n3) {
      const r = await req(base, 'GET', `/api/v1/sessions/${id}`);
      assert.equal(r.status, 200, r.text);
      assert.equal(r.body.state, 'running');
      assert.ok(r.body.status.t >= before3.get(id), `${id} went back from t=${before3.get(id)} to ${r.body.status.t}`);
    }
    const whole = await req(base, 'GET', '/api/v1/sessions');
    assert.equal(whole.body.sessions.length, 30);
    assert.equal(whole.body.unreachable, undefined);
  });

test('cluster.sh stops every process it started', { timeout: 30000 * SLOW }, async () => {
  const pids = started.slice(1);
  assert.ok(pids.slice(0, 2).every(alive), 'n1 and n2 run');
  assert.equal(await cluster.stop(), 0);
  await until(() => pids.every((pid) => !alive(pid)), 20000, 'the cluster to stop');
  assert.equal(fs.existsSync(path.join(dir, 'n1.pid')), false, 'pid files removed');
});
