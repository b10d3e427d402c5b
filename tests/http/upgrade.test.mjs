// SPDX-License-Identifier: GPL-3.0-or-later
// An upgrade keeps what the data directory holds: each data directory under
// tests/fixtures/datadir/ (written by a release with
// tests/fixtures/datadir.mjs; expected.json is what that release answered
// before it stopped) is restored by this build and comes back whole:
// sessions running, paused or finished at their targets with their control
// logs, the experiment with its results, the sweep with its points, the fit
// with its result; 0 damaged, and the start-up line says so. Every record is
// then written again in this build's format (the frame's version, spec.json's
// "format"), and a second start reads them as they are.
import { test } from 'node:test';
import assert from 'node:assert/strict';
import { cpSync, mkdtempSync, readdirSync, readFileSync, rmSync, existsSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { startDaemon, req, until, getReady, SLOW } from './lib.mjs';

const FIXTURES = new URL('../fixtures/datadir/', import.meta.url).pathname;
const FORMAT = 3; // SRV_STORE_VERSION, API_SPEC_FILE_FORMAT
const JSON_CT = { 'Content-Type': 'application/json' };

// the frame's version (store.c: magic "CVSF", then a uint32 version)
const frameVersion = (file) => {
  const b = readFileSync(file);
  assert.equal(b.subarray(0, 4).toString(), 'CVSF', file);
  return b.readUInt32LE(4);
};

// the last beta a control log set (deg), or undefined
const lastBeta = (log) => log.split('\n').filter(Boolean).map((l) => JSON.parse(l))
  .filter((c) => c.beta !== undefined).map((c) => c.beta).pop();

const SEGMENT = ['beta', 'until', 'state', 't_command', 't_end', 'start_velocity', 'steady_velocity',
  'mean_velocity', 'uncertainty', 'steady', 'reversal_time'];
const POINT = ['beta', 'rotation', 'state', 'velocity', 'uncertainty', 'steady', 'mirrored'];
const pick = (o, keys) => Object.fromEntries(keys.map((k) => [k, o[k]]));
// times as today's API writes them (to the ns; c793934 wrote every digit)
const TIMES = ['t_command', 't_end', 'reversal_time'];
const segment = (s) => Object.fromEntries(SEGMENT.map((k) =>
  [k, TIMES.includes(k) && typeof s[k] === 'number' ? Math.round(s[k] * 1e9) / 1e9 : s[k]]));

// the CSV's columns of `names`, as text rows
const columns = (csv, names) => {
  const [head, ...rows] = csv.trim().split('\n').map((l) => l.split(','));
  const at = names.map((n) => head.indexOf(n));
  assert.ok(at.every((i) => i >= 0), `${head} lacks one of ${names}`);
  return rows.map((r) => at.map((i) => r[i]).join(','));
};

// the start-up line (stderr may arrive after the port line on stdout)
const restoredLine = (d) => until(async () => / fits in [\d.]+ s; /.test(d.stderr()), 10000, 'the restore\'s line');

async function checkWhole(d, dir, exp, first) {
  await restoredLine(d);
  const log = d.stderr();
  assert.match(log, /restored 3 sessions, 1 experiments \(0 interrupted\), 1 sweeps, \d fits in [\d.]+ s; damaged: 0 sessions, 0 experiments, 0 sweeps, 0 fits; (\d+) read from an earlier format/, log);
  const upgraded = Number(log.match(/; (\d+) read from an earlier format/)[1]);
  if (!first) assert.equal(upgraded, 0, 'a second start upgrades nothing');
  assert.doesNotMatch(log, /[0-9a-f]{16} damaged|not restored|not replayed/, log);

  const list = (await req(d.base, 'GET', '/api/v1/sessions')).body.sessions;
  assert.deepEqual(list.map((s) => s.id).sort(), Object.keys(exp.sessions).sort());
  for (const [id, want] of Object.entries(exp.sessions)) {
    const path = `/api/v1/sessions/${id}`;
    const logFile = join(dir, 'sessions', id, 'controls.ndjson');
    const controls = existsSync(logFile) ? readFileSync(logFile, 'utf8') : '';
    // the log as the release left it, line for line
    const fixtureLog = join(FIXTURES, exp.release, 'data', 'sessions', id, 'controls.ndjson');
    assert.equal(controls, existsSync(fixtureLog) ? readFileSync(fixtureLog, 'utf8') : '', `${id}'s log`);
    // (a session with controls to replay answers 503 until it is back where it was)
    const g = (await getReady(d.base, path, 20000 * SLOW)).body;
    assert.equal(g.state, want.state, `${want.role} ${id}: ${JSON.stringify(g)}`);
    assert.equal(g.preset, want.preset);
    assert.equal(g.pace, want.pace);
    assert.equal(g.columns, 1);
    assert.equal(g.layers, 2);
    // at the target its last control set (the log), else as it was
    const target = lastBeta(controls) ?? want.beta_target;
    assert.ok(Math.abs(g.status.beta_target - target) < 1e-9, `${want.role}: beta_target ${g.status.beta_target}, log ${target}`);
    // its CPU budget: no fixture's log grants one, so --max-cpu-seconds'
    // default; format 3's checkpoint (ac6018f on) kept the count, which
    // goes on from there; before, the count starts from 0
    assert.equal(g.cpu_limit, 1800, `${want.role}: cpu_limit`);
    assert.ok(g.cpu_seconds >= 0 && g.cpu_seconds < g.cpu_limit, `${want.role}: cpu_seconds ${g.cpu_seconds}`);
    if (want.cpu_seconds !== undefined)
      assert.ok(g.cpu_seconds >= want.cpu_seconds - 1e-9, `${want.role}: cpu_seconds ${g.cpu_seconds}, kept ${want.cpu_seconds}`);
    if (first && want.role !== 'running')
      assert.ok(g.cpu_seconds < (want.cpu_seconds ?? 0) + 1, `${want.role}: cpu_seconds ${g.cpu_seconds}, from ${want.cpu_seconds ?? 0}`);
    if (want.role === 'running') {
      // it runs on from at least where it was
      await until(async () => (await req(d.base, 'GET', path)).body.status.t > want.t, 20000 * SLOW, `${id} past t ${want.t}`);
      const p = await req(d.base, 'PATCH', path, { beta: 45 }, JSON_CT);
      assert.equal(p.status, 200, p.text);
    } else {
      assert.ok(g.status.t >= (want.role === 'finished' ? want.t : 0), `${want.role} t ${g.status.t}`);
    }
  }

  for (const [id, want] of Object.entries(exp.experiments)) {
    const g = (await req(d.base, 'GET', `/api/v1/experiments/${id}`)).body;
    assert.equal(g.state, 'done', JSON.stringify(g));
    assert.equal(g.segments.length, want.segments.length);
    g.segments.forEach((s, k) => assert.deepEqual(segment(s), segment(want.segments[k]), `segment ${k}`));
    const csv = (await req(d.base, 'GET', `/api/v1/experiments/${id}?format=csv`)).text;
    assert.equal(csv.trim().split('\n').length, 1 + want.segments.length, csv);
    const cols = ['segment', 'beta', 'until', 'state', 'steady', 'start_velocity', 'mean_velocity', 'steady_velocity', 'uncertainty'];
    assert.deepEqual(columns(csv, cols), columns(want.csv, cols));
  }

  for (const [id, want] of Object.entries(exp.sweeps)) {
    const g = (await req(d.base, 'GET', `/api/v1/sweeps/${id}`)).body;
    assert.equal(g.state, 'done', JSON.stringify(g));
    assert.equal(g.total, want.total);
    assert.equal(g.done, want.done);
    assert.equal(g.t_end, want.t_end);
    assert.deepEqual(g.points.map((p) => pick(p, POINT)), want.points.map((p) => pick(p, POINT)));
    const csv = (await req(d.base, 'GET', `/api/v1/sweeps/${id}?format=csv`)).text;
    const cols = ['beta', 'rotation', 'velocity', 'uncertainty', 'steady', 'state'];
    assert.deepEqual(columns(csv, cols), columns(want.csv, cols));
  }

  for (const [id, want] of Object.entries(exp.fits)) {
    const g = await req(d.base, 'GET', `/api/v1/fits/${id}`);
    const { csv, ...json } = want;
    assert.deepEqual(g.body, json);
    assert.equal((await req(d.base, 'GET', `/api/v1/fits/${id}?format=csv`)).text, csv);
  }
}

// every record in this build's format, once the daemon has stopped
function checkFormat(dir, exp) {
  for (const id of Object.keys(exp.sessions)) {
    const s = join(dir, 'sessions', id);
    assert.equal(frameVersion(join(s, 'spec.bin')), FORMAT, `${id} spec.bin`);
    assert.equal(JSON.parse(readFileSync(join(s, 'spec.json'), 'utf8')).format, FORMAT, `${id} spec.json`);
    assert.equal(frameVersion(join(s, 'checkpoint.bin')), FORMAT, `${id} checkpoint.bin`);
  }
  for (const kind of ['experiments', 'sweeps', 'fits'])
    for (const id of Object.keys(exp[kind]))
      assert.equal(frameVersion(join(dir, kind, `${id}.bin`)), FORMAT, `${kind}/${id}.bin`);
}

const releases = readdirSync(FIXTURES).filter((r) => existsSync(join(FIXTURES, r, 'expected.json'))).sort();

test('the fixtures: c793934\'s, c3bc9a1\'s, 7e56a85\'s, dbe9ffc\'s, 3005e12\'s, fefabe0\'s, 4a42636\'s, 4eff261\'s, 357b026\'s, 685132b\'s, b09537b\'s, ac6018f\'s, 21c112d\'s, 4611a1d\'s, 4163b0a\'s, f809dea\'s, 30ec102\'s, 629d0db\'s, f27d350\'s, 902f3ae\'s, 322ab1b\'s, 2c46d6e\'s, c0da41f\'s and a9a256a\'s data directories are kept', () => {
  assert.ok(['c793934', 'c3bc9a1', '7e56a85', 'dbe9ffc', '3005e12', 'fefabe0', '4a42636', '4eff261', '357b026', '685132b', 'b09537b', 'ac6018f', '21c112d', '4611a1d', '4163b0a', 'f809dea', '30ec102', '629d0db', 'f27d350', '902f3ae', '322ab1b', '2c46d6e', 'c0da41f', 'a9a256a'].every((r) => releases.includes(r)), releases.join(' '));
});

for (const release of releases) {
  test(`${release}'s data directory comes back whole, upgraded in place`, { timeout: 120000 * SLOW }, async () => {
    const exp = JSON.parse(readFileSync(join(FIXTURES, release, 'expected.json'), 'utf8'));
    const tmp = mkdtempSync(join(tmpdir(), `convsim-upgrade-${release}-`));
    const dir = join(tmp, 'data');
    cpSync(join(FIXTURES, release, 'data'), dir, { recursive: true });
    // a long checkpoint interval: what is written again is the restore's
    // upgrade and the stop's final checkpoints, nothing in between
    const args = ['--data-dir', dir, '--log-level', 'info', '--checkpoint-interval', '3600'];
    let d = await startDaemon(args);
    try {
      await checkWhole(d, dir, exp, true);
      assert.equal((await d.stop()).code, 0, d.stderr());
      checkFormat(dir, exp);
      // the running session was moved (beta 45) above: the log says so now
      const running = Object.entries(exp.sessions).find(([, s]) => s.role === 'running')[0];
      const lines = readFileSync(join(dir, 'sessions', running, 'controls.ndjson'), 'utf8').trim().split('\n');
      assert.equal(JSON.parse(lines.pop()).beta, 45);
      d = await startDaemon(args);
      const again = await req(d.base, 'GET', `/api/v1/sessions/${running}`);
      assert.equal(again.body.status.beta_target, 45);
      await restoredLine(d);
      assert.match(d.stderr(), /damaged: 0 sessions, 0 experiments, 0 sweeps, 0 fits; 0 read from an earlier format/);
      assert.equal((await d.stop()).code, 0, d.stderr());
    } finally {
      await d.stop();
      rmSync(tmp, { recursive: true, force: true });
    }
  });
}
