// SPDX-License-Identifier: GPL-3.0-or-later
// The data directory as an operator leaves it (docs/formats.md "The data directory"): junk
// beside the stored records is ignored with one log line each and never
// listed; a read-only or full data directory is reported, never taken for
// success.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { spawnSync } from 'node:child_process';
import { existsSync, mkdirSync, mkdtempSync, readFileSync, rmSync, symlinkSync, unlinkSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, CHEAP, NO_FEED, SLOW, BIN } from './lib.mjs';

test('junk in the data directory is ignored with one log line each, the real records restored', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-junk-'));
  const args = ['--data-dir', dir, '--log-level', 'warn'];
  let d = await startDaemon(args);
  let id;
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    id = s.body.id;
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  const junk = [
    ['sessions', 'garbagefile', () => writeFileSync(join(dir, 'sessions', 'garbagefile'), 'x')],
    ['sessions', 'zzzz-not-an-id', () => mkdirSync(join(dir, 'sessions', 'zzzz-not-an-id'))],
    ['sessions', '0123456789abcdeg', () => mkdirSync(join(dir, 'sessions', '0123456789abcdeg'))],
    ['sessions', 'fedcba9876543210', () => symlinkSync('/tmp', join(dir, 'sessions', 'fedcba9876543210'))],
    ['sweeps', 'notes.txt', () => writeFileSync(join(dir, 'sweeps', 'notes.txt'), 'x')],
    ['sweeps', '0123456789abcdef.bin', () => mkdirSync(join(dir, 'sweeps', '0123456789abcdef.bin'))],
    ['experiments', 'zzzz-not-an-id.bin', () => writeFileSync(join(dir, 'experiments', 'zzzz-not-an-id.bin'), 'x')],
  ];
  for (const [sub, , make] of junk) {
    mkdirSync(join(dir, sub), { recursive: true });
    make();
  }
  d = await startDaemon(args);
  try {
    const list = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
    assert.deepEqual(list.map((x) => x.id), [id], 'only the real session is listed');
    assert.equal(list[0].state, 'running');
    assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length, 0);
    assert.equal((await req(d.base, 'GET', '/api/v1/experiments')).body.experiments.length, 0);
    for (const [sub, name] of junk) {
      const lines = d.stderr().split('\n').filter((l) => l.includes(`ignored ${sub}/${name}:`));
      assert.equal(lines.length, 1, `one log line for ${sub}/${name}: ${d.stderr()}`);
    }
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});

test('a damaged sweep record is listed "damaged" with the reason, as a session is; its CSV result is still served', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-dsweep-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  let id, csv;
  try {
    const sw = await req(d.base, 'POST', '/api/v1/sweeps', { ...NO_FEED, beta: [20, 40], rotations: ['cw'], t_end: 0.2 });
    assert.equal(sw.status, 202, sw.text);
    id = sw.body.id;
    await until(async () => (await req(d.base, 'GET', `/api/v1/sweeps/${id}`)).body.state === 'done', 20000, 'the sweep done');
    csv = (await req(d.base, 'GET', `/api/v1/sweeps/${id}?format=csv`)).text;
    await until(() => existsSync(join(dir, `sweep-${id}.csv`)), 5000, 'the CSV result stored');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  const file = join(dir, 'sweeps', `${id}.bin`);
  const rec = readFileSync(file);
  rec[rec.length - 3] ^= 0x55; // the checksum no longer matches
  writeFileSync(file, rec);
  d = await startDaemon(args);
  try {
    const list = (await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps;
    assert.equal(list.length, 1, JSON.stringify(list));
    assert.equal(list[0].id, id);
    assert.equal(list[0].state, 'damaged');
    assert.match(list[0].error, new RegExp(`^damaged: sweeps/${id}\\.bin: .*checksum`));
    const g = await req(d.base, 'GET', `/api/v1/sweeps/${id}`);
    assert.equal(g.status, 200, g.text);
    assert.equal(g.body.state, 'damaged');
    const again = await req(d.base, 'GET', `/api/v1/sweeps/${id}?format=csv`);
    assert.equal(again.status, 200);
    assert.equal(again.text, csv, 'the stored CSV result, byte for byte');
    assert.equal((await req(d.base, 'DELETE', `/api/v1/sweeps/${id}`)).status, 204);
    assert.equal((await req(d.base, 'GET', '/api/v1/sweeps')).body.sweeps.length, 0);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});

test('a damaged experiment record is listed "damaged" with the reason', { timeout: 60000 * SLOW }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-dexp-'));
  const args = ['--data-dir', dir];
  let d = await startDaemon(args);
  let id;
  try {
    const ex = await req(d.base, 'POST', '/api/v1/experiments', { session: { ...NO_FEED, pace: 'max' }, schedule: [{ beta: 50, until: 0.2 }] });
    assert.equal(ex.status, 201, ex.text);
    id = ex.body.id;
    await until(async () => (await req(d.base, 'GET', `/api/v1/experiments/${id}`)).body.state === 'done', 20000, 'the experiment done');
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
  }
  const file = join(dir, 'experiments', `${id}.bin`);
  writeFileSync(file, readFileSync(file).subarray(0, 100)); // cut off
  d = await startDaemon(args);
  try {
    const list = (await req(d.base, 'GET', '/api/v1/experiments')).body.experiments;
    const mine = list.find((e) => e.id === id);
    assert.ok(mine, `listed: ${JSON.stringify(list)}`);
    assert.equal(mine.state, 'damaged');
    assert.match(mine.error, new RegExp(`^damaged: experiments/${id}\\.bin: `));
    const g = await req(d.base, 'GET', `/api/v1/experiments/${id}`);
    assert.equal(g.status, 200, g.text);
    assert.equal(g.body.state, 'damaged');
    assert.equal((await req(d.base, 'GET', `/api/v1/experiments/${id}?format=csv`)).status, 200);
  } finally {
    assert.equal((await d.stop()).code, 0, d.stderr());
    rmSync(dir, { recursive: true, force: true });
  }
});

// A private mount namespace with a tmpfs as the data directory (as
// persistence.test.mjs does); the test reaches into it through
// /proc/PID/root and nsenter.
function namespaces() {
  const probe = spawnSync('sh', ['-c', 'command -v nsenter >/dev/null && unshare -m sh -c \'d=$(mktemp -d) && ' +
    'mount -t tmpfs -o size=64k tmpfs "$d" && mount -o remount,ro "$d" && umount "$d"; rmdir "$d"\''], { encoding: 'utf8' });
  return probe.status === 0;
}
const NS_SKIP = !namespaces() && 'unshare -m with a tmpfs, or nsenter, is not possible here (needs root)';

test('a full disk: the session stays "error" until its spec is on disk; read-only: DELETE is 503 and deletes nothing', { timeout: 60000 * SLOW, skip: NS_SKIP }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-full-'));
  const script = `mount -t tmpfs -o size=64k tmpfs "${dir}" && mkdir "${dir}/sessions" "${dir}/experiments" "${dir}/sweeps" && ` +
    `(dd if=/dev/zero of="${dir}/filler" bs=4k 2>/dev/null; true) && exec "${BIN}" "$@"`;
  const d = await startDaemon([], { wrap: ['unshare', '-m', 'sh', '-c', script, 'sh'], tail: ['--data-dir', dir, '--checkpoint-interval', '0.2'] });
  const inside = (p) => `/proc/${d.proc.pid}/root${dir}/${p}`;
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const id = s.body.id;
    const path = `/api/v1/sessions/${id}`;
    const failed = await until(async () => {
      const g = (await req(d.base, 'GET', path)).body;
      return g.state === 'error' && g;
    }, 5000, 'the session in state error');
    assert.match(failed.error, /spec\.json: No space left on device/);
    assert.ok(!existsSync(inside(`sessions/${id}/spec.json`)), 'no spec.json on the full disk');
    // space comes back: healthy again only with its spec on disk
    unlinkSync(inside('filler'));
    const healed = await until(async () => {
      const g = (await req(d.base, 'GET', path)).body;
      return g.state !== 'error' && g;
    }, 10000, 'the session healthy again');
    assert.equal(healed.state, 'running');
    assert.ok(!healed.error, healed.error);
    assert.ok(existsSync(inside(`sessions/${id}/spec.json`)), 'a session reported healthy has its spec.json');
    // read-only: DELETE is refused with a problem the client can act on
    const ro = spawnSync('nsenter', ['-t', String(d.proc.pid), '-m', 'mount', '-o', 'remount,ro', dir], { encoding: 'utf8' });
    assert.equal(ro.status, 0, ro.stderr);
    const del = await req(d.base, 'DELETE', path);
    assert.equal(del.status, 503, del.text);
    assert.equal(del.body.type, '/api/v1/problems/unavailable');
    assert.match(del.body.detail, /Read-only file system.*nothing was deleted/);
    assert.equal(del.headers.get('retry-after'), '30');
    assert.equal((await req(d.base, 'GET', path)).status, 200, 'the session is still there');
    assert.ok(existsSync(inside(`sessions/${id}/spec.json`)), 'its files are still there');
    assert.doesNotMatch(d.stderr(), new RegExp(`session ${id} deleted`));
    // writable again: DELETE works
    spawnSync('nsenter', ['-t', String(d.proc.pid), '-m', 'mount', '-o', 'remount,rw', dir]);
    assert.equal((await req(d.base, 'DELETE', path)).status, 204);
    await until(async () => !existsSync(inside(`sessions/${id}`)), 5000, 'the files removed');
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
});

// SIGTERM writes every session's final checkpoint: when the data
// directory went read-only, that is no clean stop.
test('a read-only data directory: a fit is "error", and SIGTERM exits 1 naming the final writes that failed', { timeout: 60000 * SLOW, skip: NS_SKIP }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-rostop-'));
  const script = `mount -t tmpfs -o size=1m tmpfs "${dir}" && exec "${BIN}" "$@"`;
  const d = await startDaemon([], { wrap: ['unshare', '-m', 'sh', '-c', script, 'sh'], tail: ['--data-dir', dir, '--checkpoint-interval', '3600', '--log-level', 'info'] });
  try {
    const s = await req(d.base, 'POST', '/api/v1/sessions', { ...CHEAP, pace: 1 });
    assert.equal(s.status, 201, s.text);
    const id = s.body.id;
    // (no control first: a session's control log stays open for writing,
    // and a file system with a file open for writing cannot be remounted
    // read-only by hand: "mount point is busy")
    await until(async () => existsSync(`/proc/${d.proc.pid}/root${dir}/sessions/${id}/spec.json`), 5000, 'the spec on disk');
    const ro = spawnSync('nsenter', ['-t', String(d.proc.pid), '-m', 'mount', '-o', 'remount,ro', dir], { encoding: 'utf8' });
    assert.equal(ro.status, 0, ro.stderr);
    // a fit posted now cannot be kept: state "error", never "done"
    const fit = await req(d.base, 'POST', '/api/v1/fits', { ...CHEAP, t_end: 0.5, free: ['e'], curve_step: 90,
      points: [{ beta: 20, rotation: 'cw', v: 0.07 }, { beta: 60, rotation: 'cw', v: 0.06 }] });
    assert.equal(fit.status, 202, fit.text);
    const fe = await until(async () => {
      const g = (await req(d.base, 'GET', `/api/v1/fits/${fit.body.id}`)).body;
      return g.state === 'error' && g;
    }, 10000, 'the fit in state error');
    assert.match(fe.error, new RegExp(`fits/${fit.body.id}\\.bin: Read-only file system`));
    const r = await d.stop();
    assert.equal(r.code, 1, d.stderr());
    assert.match(d.stderr(), new RegExp(`stopped, but 1 final write failed, their state is not on disk: cannot create sessions/${id}/checkpoint\\.bin: Read-only file system`));
    assert.doesNotMatch(d.stderr(), /stopped cleanly/);
  } finally {
    await d.stop('SIGKILL');
    rmSync(dir, { recursive: true, force: true });
  }
});

test('starting on a read-only data directory exits 2 with a message', { timeout: 30000 * SLOW, skip: NS_SKIP }, async () => {
  const dir = mkdtempSync(join(tmpdir(), 'convsimd-ro-'));
  try {
    const r = spawnSync('unshare', ['-m', 'sh', '-c', `mount -t tmpfs -o size=64k,ro tmpfs "${dir}" && exec "${BIN}" --port 0 --data-dir "${dir}"`],
      { encoding: 'utf8', timeout: 20000 * SLOW });
    assert.equal(r.status, 2, r.stderr);
    assert.equal(r.stderr, `convsimd: --data-dir ${dir} is not a writable directory\n`);
  } finally {
    rmSync(dir, { recursive: true, force: true });
  }
});
